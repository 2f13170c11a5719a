//! Curve order on the template: does the step between two curve vertices' feet follow the curve?
//!
//! Independent closest points keep a curve's order only while the curve is nearer to the template
//! than the template's local feature size (the gap to another sheet, the half-thickness of a thin
//! part). Where it is not, the feet of consecutive curve vertices jump to the other sheet, pile
//! onto one spot or turn back (see [`super::walk`], which prevents the jumps). The fine RBF then
//! carries vertices inserted in the wrong order onto the curve, the surface folds there and the
//! curve's own chains can enclose the ends of its next segment. The report counts the segments
//! whose feet step at more than [`MAX_TURN_DEG`] from the curve's step (or not at all), before
//! and after the walk.

use crate::geometry::{dot, sub};
use crate::mesh::Point3;

use super::super::curves::CurveNetwork;

/// Largest angle between a curve segment and the step of its two feet that counts as in order.
pub const MAX_TURN_DEG: f64 = 60.0;

/// Does the step between the feet `fp` → `fq` follow the curve step `cp` → `cq`?
pub fn in_order(cp: Point3, cq: Point3, fp: Point3, fq: Point3) -> bool {
    let (c, f) = (sub(cq, cp), sub(fq, fp));
    let cos_min = MAX_TURN_DEG.to_radians().cos();
    dot(c, f) > cos_min * (dot(c, c) * dot(f, f)).sqrt()
}

/// Segments of the network whose feet (`foot` per curve point) are out of order.
pub fn out_of_order_segments(net: &CurveNetwork, foot: &[Point3]) -> usize {
    net.segments
        .iter()
        .filter(|s| {
            let (p, q) = (s[0] as usize, s[1] as usize);
            !in_order(net.points[p], net.points[q], foot[p], foot[q])
        })
        .count()
}

/// Feet more than this many times farther apart than their curve points count as stretched.
pub const MAX_STRETCH: f64 = 2.0;

/// Segments of the network whose feet are more than [`MAX_STRETCH`] × the segment apart: on the
/// concave side of a surface of curvature radius R, a curve d off has its feet spread by
/// R / (R − d) (over 2 once d > R / 2); feet that jump across a crease or to another sheet spread
/// too. The fine RBF squeezes the faces between such feet onto the segment. A sign measured in
/// session 18 (docs/benchmarks.md, seps18): rows that end at the bar have 1–2 such segments,
/// the others 9 on average.
pub fn stretched_segments(net: &CurveNetwork, foot: &[Point3]) -> usize {
    net.segments
        .iter()
        .filter(|s| {
            let (p, q) = (s[0] as usize, s[1] as usize);
            crate::geometry::dist(foot[p], foot[q])
                > MAX_STRETCH * crate::geometry::dist(net.points[p], net.points[q])
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    fn net(points: Vec<Point3>) -> CurveNetwork {
        let n = points.len() as u32;
        let m = Mesh { positions: points, curves: vec![(0..n).collect()], ..Default::default() };
        CurveNetwork::from_mesh(&m, 1e-9).unwrap()
    }

    #[test]
    fn turned_back_and_piled_feet_are_out_of_order_squeezed_ones_are_not() {
        let pts: Vec<Point3> = (0..8).map(|i| [i as f64, 0.0, 0.0]).collect();
        let n = net(pts.clone());
        assert_eq!(out_of_order_segments(&n, &pts), 0);
        // Point 4's foot put back at x = 2.5, behind point 3's: step 3→4 goes −0.5 along a +1
        // step (out of order), 4→5 goes +2.5 (in order). Hand count: 1.
        let mut foot = pts.clone();
        foot[4] = [2.5, 0.1, 0.0];
        assert_eq!(out_of_order_segments(&n, &foot), 1);
        // Squeezed to half the spacing and turned 45°: still in order (limit 60°).
        let foot: Vec<Point3> = (0..8).map(|i| [0.5 * i as f64, 0.5 * i as f64, 0.0]).collect();
        assert_eq!(out_of_order_segments(&n, &foot), 0);
        // Two feet on one spot: the step has no direction, out of order.
        let mut foot = pts.clone();
        foot[3] = foot[2];
        assert!(!in_order(pts[2], pts[3], foot[2], foot[3]));
        assert_eq!(out_of_order_segments(&n, &foot), 1);
    }

    #[test]
    fn feet_spread_by_a_concave_arc_are_stretched_at_more_than_half_the_radius() {
        // Curve points on an arc of radius 1, inside a concentric tube of radius r: their closest
        // points are on the tube's arc of radius r, straight out, so the feet are r × the points'
        // spacing apart (d = r − 1 off a surface of radius R = r: spread R / (R − d) = r, over 2
        // once d > R / 2). Hand count: r = 1.9 → none stretched, r = 2.1 → all 7 segments.
        let arc = |r: f64| -> Vec<Point3> {
            (0..8)
                .map(|i| {
                    let a = 0.1 * i as f64;
                    [r * a.cos(), r * a.sin(), 0.0]
                })
                .collect()
        };
        let n = net(arc(1.0));
        assert_eq!(stretched_segments(&n, &arc(1.9)), 0);
        assert_eq!(stretched_segments(&n, &arc(2.1)), 7);
        // One foot jumped away (to another sheet 0.5 below): its two segments, and only they.
        let mut foot = arc(1.0);
        foot[3][2] -= 0.5;
        assert_eq!(stretched_segments(&n, &foot), 2);
    }
}
