//! A held-out family for the deformed sweep: other smooth maps and other (oblique) section planes
//! than the ones the fit's repairs were tuned on (`bend`, `twist`, `sweep_planes`). A change chosen
//! because it helps the first family should be judged here too, so a gain that only fits those
//! particular deformations shows up as a loss (or no gain) on this one.
//!
//! Every map is smooth and orientation-preserving on the unit box (the tests check the Jacobian's
//! determinant on a grid), so the deformed template is a valid truth surface.

use crate::geometry::{dot, normalize, Aabb};
use crate::mesh::Point3;

/// A taper along x with a shear: the y–z cross-section grows from 0.825× to 1.175× across the box,
/// x bends with y², z waves with x. Jacobian determinant s·(s − 0.084·(y−½)²) > 0 with s ≥ 0.825.
pub fn taper(p: Point3) -> Point3 {
    let (x, y, z) = (p[0] - 0.5, p[1] - 0.5, p[2] - 0.5);
    let s = 1.0 + 0.35 * x;
    [0.5 + x + 0.12 * y * y, 0.5 + s * y, 0.5 + s * z + 0.08 * (3.0 * x).sin()]
}

/// A wave: every coordinate displaced by 0.025·sin of the sum of the other two (wavelength ≈ 0.47
/// along the diagonals). The Jacobian is I plus a zero-diagonal matrix with entries ≤ 0.236, so it
/// is diagonally dominant and its determinant stays positive.
pub fn wave(p: Point3) -> Point3 {
    let a = 0.025;
    let k = std::f64::consts::TAU * 1.5;
    [
        p[0] + a * (k * (p[1] + p[2])).sin(),
        p[1] + a * (k * (p[2] + p[0])).sin(),
        p[2] + a * (k * (p[0] + p[1])).sin(),
    ]
}

/// A bulge: points pushed away from an off-centre point c = (0.6, 0.45, 0.5) by the factor
/// 1 + 0.25·exp(−|p − c|²/0.1). The radial stretch 1 + 0.25·e^(−u)(1 − 2u), u = |p − c|²/0.1, is at
/// least 1 − 0.5·e^(−1.5) ≈ 0.89 and the tangential one at least 1, so the map is a diffeomorphism.
pub fn bulge(p: Point3) -> Point3 {
    let c = [0.6, 0.45, 0.5];
    let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
    let g = 1.0 + 0.25 * (-dot(d, d) / 0.1).exp();
    [c[0] + g * d[0], c[1] + g * d[1], c[2] + g * d[2]]
}

/// Oblique section planes for `positions` (the held-out counterpart of `sweep_planes`): four planes
/// across a direction tilted off the longest axis, and one tilted plane across each other axis, at
/// offsets off round fractions of the extent along each normal. Empty for no positions.
pub fn oblique_planes(positions: &[Point3]) -> Vec<(Point3, f64)> {
    let Some(bb) = Aabb::of(positions) else { return Vec::new() };
    let ext: Vec<f64> = (0..3).map(|k| bb.max[k] - bb.min[k]).collect();
    let long = (0..3).max_by(|&a, &b| ext[a].total_cmp(&ext[b])).unwrap_or(0);
    let (second, third) = ((long + 1) % 3, (long + 2) % 3);
    let dir = |w: [(usize, f64); 3]| {
        let mut n = [0.0; 3];
        for (k, c) in w {
            n[k] += c;
        }
        normalize(n)
    };
    // The extent along a normal: where the planes at fractions of it fall.
    let span = |n: Point3| {
        let (lo, hi) = positions.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &p| {
            let t = dot(n, p);
            (lo.min(t), hi.max(t))
        });
        move |f: f64| lo + f * (hi - lo)
    };
    let across = dir([(long, 1.0), (second, 0.3), (third, 0.2)]);
    let at = span(across);
    let mut planes: Vec<(Point3, f64)> =
        [0.2237, 0.3871, 0.5413, 0.6957].iter().map(|&f| (across, at(f))).collect();
    for n in
        [dir([(second, 1.0), (long, 0.25), (third, 0.0)]), dir([(third, 1.0), (second, 0.3), (long, -0.15)])]
    {
        planes.push((n, span(n)(0.4613)));
    }
    planes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{cross, sub};

    /// det of the Jacobian by central differences.
    fn jacobian_det(f: fn(Point3) -> Point3, p: Point3) -> f64 {
        let h = 1e-5;
        let col = |k: usize| {
            let (mut a, mut b) = (p, p);
            a[k] += h;
            b[k] -= h;
            let d = sub(f(a), f(b));
            [d[0] / (2.0 * h), d[1] / (2.0 * h), d[2] / (2.0 * h)]
        };
        dot(col(0), cross(col(1), col(2)))
    }

    #[test]
    fn held_out_maps_preserve_orientation_on_the_unit_box() {
        // On a grid 0.1 beyond the box: taper's s·(s − 0.084·y²) ≥ 0.79·(0.79 − 0.03) ≈ 0.6 there,
        // wave's diagonally dominant I + E (a floor well above 0), bulge's radial stretch ≥ 0.89.
        for (name, f, floor) in
            [("taper", taper as fn(Point3) -> Point3, 0.55), ("wave", wave, 0.3), ("bulge", bulge, 0.85)]
        {
            let mut lowest = f64::INFINITY;
            for i in 0..=20 {
                for j in 0..=20 {
                    for k in 0..=20 {
                        let p = [i as f64 * 0.06 - 0.1, j as f64 * 0.06 - 0.1, k as f64 * 0.06 - 0.1];
                        lowest = lowest.min(jacobian_det(f, p));
                    }
                }
            }
            assert!(lowest > floor, "{name}: det J down to {lowest}");
        }
    }

    #[test]
    fn held_out_maps_are_not_affine() {
        // A map that is affine would be absorbed by the fit's affine part and test nothing new:
        // the midpoint of two points must not map to the midpoint of their images.
        for f in [taper as fn(Point3) -> Point3, wave, bulge] {
            let (a, b) = ([0.1, 0.2, 0.3], [0.9, 0.7, 0.6]);
            let m = f([0.5, 0.45, 0.45]);
            let (fa, fb) = (f(a), f(b));
            let gap = sub(m, [(fa[0] + fb[0]) / 2.0, (fa[1] + fb[1]) / 2.0, (fa[2] + fb[2]) / 2.0]);
            assert!(dot(gap, gap).sqrt() > 1e-3);
        }
    }

    #[test]
    fn oblique_planes_cut_a_sphere_and_are_not_axis_aligned() {
        // A sphere of radius 0.5 about (0.5, 0.5, 0.5), sampled on a coarse lattice of its surface.
        let mut pts = Vec::new();
        for i in 0..40 {
            for j in 0..20 {
                let (t, u) =
                    (i as f64 * std::f64::consts::TAU / 40.0, (j as f64 + 0.5) * std::f64::consts::PI / 20.0);
                pts.push([0.5 + 0.5 * u.sin() * t.cos(), 0.5 + 0.5 * u.sin() * t.sin(), 0.5 + 0.5 * u.cos()]);
            }
        }
        let planes = oblique_planes(&pts);
        assert_eq!(planes.len(), 6);
        for (n, o) in &planes {
            assert!((dot(*n, *n) - 1.0).abs() < 1e-12);
            // Tilted: no component is the whole normal.
            assert!(n.iter().all(|c| c.abs() < 0.99), "{n:?}");
            // Every plane passes within the sphere (distance of the centre below the radius).
            assert!((dot(*n, [0.5, 0.5, 0.5]) - o).abs() < 0.5, "plane {n:?} {o} misses");
        }
        assert!(oblique_planes(&[]).is_empty());
    }
}
