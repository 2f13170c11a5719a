//! Small vector helpers on `[f64; 3]`, shared by every module (no external linear-algebra type in
//! the hot loops: plain arrays vectorise well and keep `Mesh` free of a math crate).

use crate::mesh::Point3;

#[inline]
pub fn add(a: Point3, b: Point3) -> Point3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub fn scale(a: Point3, s: f64) -> Point3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline]
pub fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub fn cross(a: Point3, b: Point3) -> Point3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[inline]
pub fn norm(a: Point3) -> f64 {
    dot(a, a).sqrt()
}

#[inline]
pub fn norm2(a: Point3) -> f64 {
    dot(a, a)
}

#[inline]
pub fn dist(a: Point3, b: Point3) -> f64 {
    norm(sub(a, b))
}

/// The point of segment a–b closest to `p` (`a` for a zero-length segment).
#[inline]
pub fn closest_on_segment(p: Point3, a: Point3, b: Point3) -> Point3 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 { (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    add(a, scale(ab, t))
}

/// `a` scaled to unit length, or zero when `a` is (numerically) zero.
#[inline]
pub fn normalize(a: Point3) -> Point3 {
    let n = norm(a);
    if n > 0.0 {
        scale(a, 1.0 / n)
    } else {
        [0.0; 3]
    }
}

/// Twice-area vector of triangle (a, b, c): its direction is the normal, its length 2·area.
#[inline]
pub fn triangle_cross(a: Point3, b: Point3, c: Point3) -> Point3 {
    cross(sub(b, a), sub(c, a))
}

/// The centroid of triangle (a, b, c).
#[inline]
pub fn triangle_centroid(a: Point3, b: Point3, c: Point3) -> Point3 {
    scale(add(add(a, b), c), 1.0 / 3.0)
}

#[inline]
pub fn triangle_area(a: Point3, b: Point3, c: Point3) -> f64 {
    0.5 * norm(triangle_cross(a, b, c))
}

/// Interior angle at `a` of triangle (a, b, c), in radians; 0 for a degenerate corner.
#[inline]
pub fn corner_angle(a: Point3, b: Point3, c: Point3) -> f64 {
    let u = sub(b, a);
    let v = sub(c, a);
    // atan2 of |u×v| and u·v is accurate for small and near-π angles, unlike acos.
    norm(cross(u, v)).atan2(dot(u, v))
}

/// The smallest corner angle of triangle (a, b, c), in degrees.
pub fn min_angle_deg(a: Point3, b: Point3, c: Point3) -> f64 {
    corner_angle(a, b, c).min(corner_angle(b, c, a)).min(corner_angle(c, a, b)).to_degrees()
}

/// Axis-aligned bounding box; `None` for an empty point set.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, utoipa::ToSchema)]
pub struct Aabb {
    #[schema(value_type = Vec<f64>)]
    pub min: Point3,
    #[schema(value_type = Vec<f64>)]
    pub max: Point3,
}

impl Aabb {
    pub fn of(points: &[Point3]) -> Option<Aabb> {
        let first = *points.first()?;
        let mut b = Aabb { min: first, max: first };
        for p in points {
            for k in 0..3 {
                b.min[k] = b.min[k].min(p[k]);
                b.max[k] = b.max[k].max(p[k]);
            }
        }
        Some(b)
    }

    pub fn diagonal(&self) -> f64 {
        dist(self.min, self.max)
    }

    pub fn center(&self) -> Point3 {
        scale(add(self.min, self.max), 0.5)
    }
}

/// Signed volume enclosed by a closed, consistently oriented polygon mesh (fan-triangulated faces);
/// positive when faces are oriented outward.
pub fn signed_volume(positions: &[Point3], faces: &crate::mesh::Faces) -> f64 {
    let mut v = 0.0;
    for f in faces.iter() {
        let a = positions[f[0] as usize];
        for k in 1..f.len().saturating_sub(1) {
            let b = positions[f[k] as usize];
            let c = positions[f[k + 1] as usize];
            v += dot(a, cross(b, c));
        }
    }
    v / 6.0
}

/// Total area of the faces (fan-triangulated).
pub fn surface_area(positions: &[Point3], faces: &crate::mesh::Faces) -> f64 {
    let mut s = 0.0;
    for f in faces.iter() {
        let a = positions[f[0] as usize];
        for k in 1..f.len().saturating_sub(1) {
            s += triangle_area(a, positions[f[k] as usize], positions[f[k + 1] as usize]);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Faces;

    #[test]
    fn unit_cube_volume_and_area() {
        let p = vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.],
            [1., 1., 1.],
            [0., 1., 1.],
        ];
        let mut f = Faces::new();
        for q in [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]] {
            f.push(&q, 0);
        }
        assert!((signed_volume(&p, &f) - 1.0).abs() < 1e-15);
        assert!((surface_area(&p, &f) - 6.0).abs() < 1e-15);
    }

    #[test]
    fn corner_angle_right_and_degenerate() {
        let a = corner_angle([0.; 3], [1., 0., 0.], [0., 1., 0.]);
        assert!((a - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(corner_angle([0.; 3], [0.; 3], [0., 1., 0.]), 0.0);
    }
}
