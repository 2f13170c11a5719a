//! Where the new vertex of a split edge goes: the point of its quadrilateral ring, seen along the
//! count's reference, whose four faces have the largest smallest angle.
//!
//! Why not the kernel's Chebyshev centre alone ([`super::super::untangle::kernel_centre`]): it is
//! the point farthest from the ring's edges, which in a thin quad sits near its far corner, and
//! its faces' smallest angle is often below the fold repair's floor where a better point is not
//! (by hand in `tests.rs`: 1.2° there, above 2° at the point found here). A pattern search over
//! the plane (halving its step) from the best of a few starting points, keeping every face of the
//! star turning the right way round.

use crate::fit::untangle::RingFrame;
use crate::geometry::corner_angle;
use crate::mesh::Point3;

/// Halvings of the search's step.
const HALVINGS: usize = 24;

/// Steps of the search at most (moves and halvings).
const MAX_STEPS: usize = 200;

/// The ring's faces' smallest corner angle (degrees) with the centre at `m` (2D), or None when a
/// face is degenerate or turned (the ring's edges (x, y) counter-clockwise, each face (m, x, y)).
fn min_angle_2d(ring: &[([f64; 2], [f64; 2])], m: [f64; 2]) -> Option<f64> {
    let mut worst = f64::INFINITY;
    for &(x, y) in ring {
        let c = (x[0] - m[0]) * (y[1] - m[1]) - (x[1] - m[1]) * (y[0] - m[0]);
        if c.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let p = |q: [f64; 2]| [q[0], q[1], 0.0];
        let (m3, x3, y3) = (p(m), p(x), p(y));
        let a = corner_angle(m3, x3, y3).min(corner_angle(x3, y3, m3)).min(corner_angle(y3, m3, x3));
        worst = worst.min(a.to_degrees());
    }
    Some(worst)
}

/// The best centre of the star with ring edges `ring` (each (x, y) in its face's order after the
/// centre) seen along `n`, lifted to the ring's mean height, from starting points `starts`; None
/// when no start has every face turning the right way round.
pub(super) fn best_centre(ring: &[(Point3, Point3)], n: Point3, starts: &[Point3]) -> Option<Point3> {
    let frame = RingFrame::new(ring, n)?;
    let flat = |p: Point3| frame.flat(p);
    let ring2: Vec<([f64; 2], [f64; 2])> = ring.iter().map(|&(x, y)| (flat(x), flat(y))).collect();
    let mut best: Option<([f64; 2], f64)> = None;
    for &s in starts {
        let s = flat(s);
        if let Some(a) = min_angle_2d(&ring2, s) {
            if best.is_none_or(|b| a > b.1) {
                best = Some((s, a));
            }
        }
    }
    let (mut p, mut a) = best?;
    let size = ring.iter().map(|&(x, y)| crate::geometry::dist(x, y)).fold(0.0, f64::max);
    let mut h = 0.25 * size;
    const D: f64 = std::f64::consts::FRAC_1_SQRT_2;
    const DIRS: [[f64; 2]; 8] =
        [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0], [D, D], [-D, D], [D, -D], [-D, -D]];
    let (mut halvings, mut steps) = (0, 0);
    while halvings < HALVINGS && steps < MAX_STEPS {
        steps += 1;
        let mut moved = false;
        for d in DIRS {
            let q = [p[0] + h * d[0], p[1] + h * d[1]];
            if let Some(b) = min_angle_2d(&ring2, q) {
                if b > a {
                    (p, a, moved) = (q, b, true);
                }
            }
        }
        if !moved {
            h *= 0.5;
            halvings += 1;
        }
    }
    Some(frame.lift(p))
}
