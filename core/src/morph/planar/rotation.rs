//! Boundary correspondence between disks: the rotation of each disk that best matches its 3D
//! boundary curve (or its feature points) to input 0's, and applying it to a disk map.

use std::f64::consts::TAU;

use super::{lift, DiskMap};
use crate::geometry::{add, sub};
use crate::mesh::Point3;

/// The 3D boundary point at angle `t` (radians, any value) of a disk whose boundary vertices
/// `lp` sit at increasing `angles` in [0, 2π).
fn boundary_point(pos: &[Point3], lp: &[u32], angles: &[f64], t: f64) -> Point3 {
    let n = lp.len();
    let t = t.rem_euclid(TAU);
    // First index with angle > t, cyclically.
    let i1 = angles.partition_point(|&a| a <= t);
    let i0 = (i1 + n - 1) % n;
    let i1 = i1 % n;
    let (a0, mut a1) = (angles[i0], angles[i1]);
    let mut tt = t;
    if a1 <= a0 {
        a1 += TAU;
        if tt < a0 {
            tt += TAU;
        }
    }
    let f = if a1 > a0 { ((tt - a0) / (a1 - a0)).clamp(0.0, 1.0) } else { 0.0 };
    let (p, q) = (pos[lp[i0] as usize], pos[lp[i1] as usize]);
    add(p, crate::geometry::scale(sub(q, p), f))
}

/// The rotation φ of disk B (its angle θ_B ↦ θ_B − φ) that best matches B's normalised 3D boundary
/// to A's at equal angles: least squares over 256 samples, 720 trial angles, then refined.
#[allow(clippy::too_many_arguments)]
pub fn boundary_rotation(
    pos_a: &[Point3],
    lp_a: &[u32],
    ang_a: &[f64],
    pos_b: &[Point3],
    lp_b: &[u32],
    ang_b: &[f64],
) -> f64 {
    const S: usize = 256;
    let pa: Vec<Point3> =
        (0..S).map(|s| boundary_point(pos_a, lp_a, ang_a, TAU * s as f64 / S as f64)).collect();
    let cost = |phi: f64| -> f64 {
        pa.iter()
            .enumerate()
            .map(|(s, &p)| {
                let q = boundary_point(pos_b, lp_b, ang_b, TAU * s as f64 / S as f64 + phi);
                crate::geometry::norm2(sub(p, q))
            })
            .sum()
    };
    let mut best = (f64::INFINITY, 0.0);
    for k in 0..720 {
        let phi = TAU * k as f64 / 720.0;
        let c = cost(phi);
        if c < best.0 {
            best = (c, phi);
        }
    }
    // Refine around the best coarse angle (golden-section-free: two finer scans).
    let mut step = TAU / 720.0;
    for _ in 0..2 {
        let centre = best.1;
        for k in -10..=10 {
            let phi = centre + step * k as f64 / 10.0;
            let c = cost(phi);
            if c < best.0 {
                best = (c, phi);
            }
        }
        step /= 10.0;
    }
    best.1.rem_euclid(TAU)
}

/// The mean angular offset of B's feature points from A's (weighted by their radii).
pub fn feature_rotation(plane_a: &[Point3], fa: &[u32], plane_b: &[Point3], fb: &[u32]) -> Option<f64> {
    let (mut s, mut c) = (0.0, 0.0);
    for (&va, &vb) in fa.iter().zip(fb) {
        let (p, q) = (plane_a[va as usize], plane_b[vb as usize]);
        // Angle of q relative to p, times |p||q|: Im and Re of conj(p)·q.
        c += p[0] * q[0] + p[1] * q[1];
        s += p[0] * q[1] - p[1] * q[0];
    }
    (s.hypot(c) > 1e-12).then(|| s.atan2(c).rem_euclid(TAU))
}

/// Rotates a disk map by −φ (so B's angle θ + φ lands on θ); boundary angles stay in [0, 2π) and
/// the loop is re-started at its smallest angle so the angles increase along it.
pub fn rotate(map: &mut DiskMap, phi: f64) {
    let (s, c) = (-phi).sin_cos();
    for p in &mut map.plane {
        *p = lift(c * p[0] - s * p[1], s * p[0] + c * p[1]);
    }
    for a in &mut map.angles {
        *a = (*a - phi).rem_euclid(TAU);
    }
    restart_at_min(map);
}

pub(super) fn restart_at_min(map: &mut DiskMap) {
    let k = (0..map.angles.len()).min_by(|&i, &j| map.angles[i].total_cmp(&map.angles[j])).unwrap_or(0);
    map.angles.rotate_left(k);
    map.boundary.rotate_left(k);
}
