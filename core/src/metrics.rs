//! Quality measures reported by the jobs: triangle angles, flipped faces, displacement, relative
//! volume/area change, mean curvature.

use rayon::prelude::*;
use serde::Serialize;

use crate::geometry::{add, corner_angle, cross, dist, dot, norm, sub};
use crate::laplacian::Operator;
use crate::mesh::{Faces, Point3};

/// Angle statistics over the (fan-triangulated) faces, in degrees.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq)]
pub struct AngleStats {
    /// Smallest angle of any triangle.
    pub min: f64,
    /// Mean over triangles of each triangle's smallest angle (the mean of *all* angles of a
    /// triangle is always 60°, so this is the informative mean).
    pub mean_min: f64,
    /// Largest angle of any triangle.
    pub max: f64,
}

pub fn angle_stats(positions: &[Point3], faces: &Faces) -> AngleStats {
    let tris = crate::shapes::fan_triangles(faces);
    if tris.is_empty() {
        return AngleStats::default();
    }
    let (mn, sum, mx) = tris
        .par_iter()
        .with_min_len(4096)
        .map(|t| {
            let p = [positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]];
            let a = [
                corner_angle(p[0], p[1], p[2]),
                corner_angle(p[1], p[2], p[0]),
                corner_angle(p[2], p[0], p[1]),
            ];
            let lo = a[0].min(a[1]).min(a[2]);
            let hi = a[0].max(a[1]).max(a[2]);
            (lo, lo, hi)
        })
        .reduce(|| (f64::INFINITY, 0.0, 0.0), |x, y| (x.0.min(y.0), x.1 + y.1, x.2.max(y.2)));
    AngleStats {
        min: mn.to_degrees(),
        mean_min: (sum / tris.len() as f64).to_degrees(),
        max: mx.to_degrees(),
    }
}

/// Newell normal of a polygon (twice its vector area).
pub fn face_normal(positions: &[Point3], face: &[u32]) -> Point3 {
    let mut n = [0.0; 3];
    for k in 0..face.len() {
        let a = positions[face[k] as usize];
        let b = positions[face[(k + 1) % face.len()] as usize];
        n = add(n, cross(a, b));
    }
    n
}

/// Faces whose normal turned by more than 90° between `before` and `after`.
pub fn flipped_faces(before: &[Point3], after: &[Point3], faces: &Faces) -> usize {
    (0..faces.len())
        .into_par_iter()
        .with_min_len(4096)
        .filter(|&f| dot(face_normal(before, faces.get(f)), face_normal(after, faces.get(f))) < 0.0)
        .count()
}

/// (max, mean) vertex displacement.
pub fn displacement(before: &[Point3], after: &[Point3]) -> (f64, f64) {
    if before.is_empty() {
        return (0.0, 0.0);
    }
    let (mx, sum) = before
        .par_iter()
        .zip(after)
        .with_min_len(8192)
        .map(|(a, b)| {
            let d = dist(*a, *b);
            (d, d)
        })
        .reduce(|| (0.0, 0.0), |x, y| (x.0.max(y.0), x.1 + y.1));
    (mx, sum / before.len() as f64)
}

/// Signed volume of the cone from `apex` over the faces (for a closed mesh: the enclosed volume,
/// independent of the apex; for an open one, the apex makes it translation-invariant).
pub fn volume_about(positions: &[Point3], faces: &Faces, apex: Point3) -> f64 {
    let v: f64 = (0..faces.len())
        .into_par_iter()
        .with_min_len(8192)
        .map(|fi| {
            let f = faces.get(fi);
            let a = sub(positions[f[0] as usize], apex);
            let mut s = 0.0;
            for k in 1..f.len().saturating_sub(1) {
                let b = sub(positions[f[k] as usize], apex);
                let c = sub(positions[f[k + 1] as usize], apex);
                s += dot(a, cross(b, c));
            }
            s
        })
        .sum();
    v / 6.0
}

pub fn area(positions: &[Point3], faces: &Faces) -> f64 {
    (0..faces.len())
        .into_par_iter()
        .with_min_len(8192)
        .map(|f| 0.5 * norm(face_normal(positions, faces.get(f))))
        .sum()
}

/// Relative signed change (after − before) / |before|, 0 when before is 0.
pub fn relative_change(before: f64, after: f64) -> f64 {
    if before == 0.0 {
        0.0
    } else {
        (after - before) / before.abs()
    }
}

/// Mass-weighted mean of |H| over the vertices not in `skip` (boundary vertices have no
/// meaningful curvature normal), with `|H| = |(M⁻¹ S x)_i| / 2` from a cotangent operator with
/// an area scale (`Operator::scale` = mass).
pub fn mean_curvature(op: &Operator, positions: &[Point3], skip: &[bool]) -> f64 {
    let x = positions.as_flattened();
    let mut y = vec![0.0; x.len()];
    op.stiffness.mul_vec(x, &mut y, 3);
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..positions.len() {
        if skip[i] || op.locked[i] {
            continue;
        }
        let m = op.scale[i];
        let h = norm([y[3 * i], y[3 * i + 1], y[3 * i + 2]]) / (2.0 * m);
        num += m * h;
        den += m;
    }
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laplacian::{operator, MassKind, OperatorKind};
    use crate::shapes::{grid, icosphere};

    #[test]
    fn equilateral_angles_and_no_flips() {
        let m = crate::shapes::triangle_grid(4, 4, 1.0);
        let a = angle_stats(&m.positions, &m.faces);
        assert!(
            (a.min - 60.0).abs() < 1e-9 && (a.mean_min - 60.0).abs() < 1e-9 && (a.max - 60.0).abs() < 1e-9
        );
        assert_eq!(flipped_faces(&m.positions, &m.positions, &m.faces), 0);
        let mut q = m.positions.clone();
        for p in &mut q {
            p[0] = -p[0]; // mirror: every face flips
        }
        assert_eq!(flipped_faces(&m.positions, &q, &m.faces), m.face_count());
    }

    #[test]
    fn sphere_mean_curvature_is_one_over_r() {
        let r = 2.0;
        let m = icosphere(4, r);
        let op = operator(&m.positions, &m.faces, OperatorKind::Cotan, MassKind::Voronoi).unwrap();
        let h = mean_curvature(&op, &m.positions, &vec![false; m.vertex_count()]);
        assert!((h - 1.0 / r).abs() < 0.01 / r, "{h}");
        let v = volume_about(&m.positions, &m.faces, [5.0, 1.0, 0.0]);
        let v0 = crate::geometry::signed_volume(&m.positions, &m.faces);
        assert!((v - v0).abs() < 1e-12 * v0);
        let g = grid(2, 2, 1.0, true);
        assert!((area(&g.positions, &g.faces) - 4.0).abs() < 1e-15);
        assert_eq!(displacement(&g.positions, &g.positions), (0.0, 0.0));
    }
}
