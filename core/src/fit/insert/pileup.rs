//! Feet that pile up at one point of the template are spread over the faces around it.
//!
//! Why: the closest point of every curve vertex that passes beyond a convex vertex of the
//! template (inside its normal cone) is that vertex itself, and beyond a convex edge, crossing it,
//! one point of that edge. Where the approach leaves the surface far from the curves (measured:
//! a level-3 icosphere onto homer's sections, auto alignment, six curve vertices of two curves
//! 0.04–0.055 from the template whose feet were all template vertex 217), several curve vertices
//! share one foot. The insertion gives the first one the vertex and nudges every later one 20 %
//! towards the centre of the (ever smaller) face it lands in, so the later ones end
//! 1e-12 apart: the fine RBF then has coincident centres with different targets (the "duplicate
//! RBF centres" error, which blamed the curves for the pipeline's own pile-up) or, just above the
//! duplicate tolerance, a field that folds everything around them.
//!
//! The spread foot of a piled-up point is the foot moved along the point's offset from it,
//! projected on the faces around the foot (the surface there unfolded, as the normal projection
//! of the vertex's tangent plane would): curve vertices at different places above the pile get
//! different feet, in the same arrangement as the curve vertices themselves. The move is
//! compressed (`d / (1 + d / exit)`, `exit` the distance to the face's far side along the
//! direction) so it never leaves the face and stays monotone in the offset. A point straight above
//! the pile keeps it (the insertion's nudge still separates it).

use crate::geometry::{add, dist, dot, norm, scale, sub, triangle_cross};
use crate::mesh::Point3;
use crate::spatial::closest_on_triangle;

use super::super::kdtree::KdTree;
use super::{barycentric, Foot};

/// Feet closer than this × the template's bounding-box diagonal are one pile.
const PILE_TOLERANCE: f64 = 1e-9;
/// A face is around a pile when the pile point is within this × the face's longest edge of it.
const ON_FACE: f64 = 1e-9;

/// Spreads every pile of feet (see the module doc), except the feet of `keep` points. Returns how
/// many feet moved.
pub fn spread_piled_feet(
    pos: &[Point3],
    tris: &[[u32; 3]],
    vf: &[Vec<u32>],
    points: &[Point3],
    feet: &mut [Foot],
    keep: &[bool],
) -> usize {
    let foot_points: Vec<Point3> = feet.iter().map(|f| f.1).collect();
    let Some(bb) = crate::geometry::Aabb::of(pos) else { return 0 };
    let tol = PILE_TOLERANCE * bb.diagonal();
    let tree = KdTree::new(&foot_points);
    let piled: Vec<usize> = (0..feet.len())
        .filter(|&p| !keep[p])
        .filter(|&p| {
            tree.nearest_filtered(foot_points[p], |q| q as usize != p).is_some_and(|(_, d2)| d2.sqrt() <= tol)
        })
        .collect();
    let mut moved = 0;
    for p in piled {
        if let Some(f) = spread_foot(pos, tris, vf, points[p], feet[p]) {
            feet[p] = f;
            moved += 1;
        }
    }
    moved
}

/// The foot of `x` moved from `foot` along `x`'s offset projected on the face around `foot` that
/// the offset points into; `None` when the offset is along the normal or no face takes it.
fn spread_foot(pos: &[Point3], tris: &[[u32; 3]], vf: &[Vec<u32>], x: Point3, foot: Foot) -> Option<Foot> {
    let (f0, at, _) = foot;
    let corners = |f: u32| tris[f as usize].map(|v| pos[v as usize]);
    let mut around: Vec<u32> =
        tris[f0 as usize].iter().flat_map(|&v| vf[v as usize].iter().copied()).collect();
    around.sort_unstable();
    around.dedup();
    // The faces the pile point lies on (its star when it is a vertex, two faces on an edge).
    around.retain(|&f| {
        let t = corners(f);
        let longest = (0..3).map(|k| dist(t[k], t[(k + 1) % 3])).fold(0.0, f64::max);
        let n = triangle_cross(t[0], t[1], t[2]);
        longest > 0.0 && dot(n, n) > 0.0 && dist(closest_on_triangle(at, &t), at) <= ON_FACE * longest
    });
    // The offset in the tangent plane there (the area-weighted normal of those faces): projected
    // on each face's own plane instead, the offset of a point above a convex corner points out of
    // every face.
    let normal = around.iter().fold([0.0; 3], |acc, &f| {
        let t = corners(f);
        add(acc, triangle_cross(t[0], t[1], t[2]))
    });
    let nn = dot(normal, normal);
    if nn <= 0.0 {
        return None;
    }
    let offset = sub(x, at);
    let tangent = sub(offset, scale(normal, dot(offset, normal) / nn));
    let mut best: Option<(f64, u32, Point3)> = None;
    for f in around {
        let t = corners(f);
        let n = triangle_cross(t[0], t[1], t[2]);
        let d = sub(tangent, scale(n, dot(tangent, n) / dot(n, n)));
        let longest = (0..3).map(|k| dist(t[k], t[(k + 1) % 3])).fold(0.0, f64::max);
        if norm(d) <= 1e-12 * longest {
            continue;
        }
        // Barycentric coordinates are affine: l(at + α d) = l0 + α (l1 − l0).
        let l0 = barycentric(at, &t);
        let l1 = barycentric(add(at, d), &t);
        let eps = 1e-9;
        let mut exit = f64::INFINITY;
        let mut inward = true;
        for k in 0..3 {
            let dl = l1[k] - l0[k];
            if l0[k] <= eps && dl < -eps {
                inward = false; // the offset leaves this face straight away
            }
            if dl < 0.0 {
                exit = exit.min(l0[k].max(0.0) / -dl);
            }
        }
        if !inward || !exit.is_finite() || exit <= 0.0 {
            continue;
        }
        // The offset fits `exit` times before the far side: compress so it stays inside.
        let step = 1.0 / (1.0 + 1.0 / exit);
        let q = add(at, scale(d, step));
        if best.as_ref().is_none_or(|b| exit > b.0) {
            best = Some((exit, f, q));
        }
    }
    let (_, f, q) = best?;
    Some((f, q, dist(x, q)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square pyramid's apex (0, 0, 1) over the base corners (±1, ±1, 0), its four side faces.
    fn pyramid() -> (Vec<Point3>, Vec<[u32; 3]>, Vec<Vec<u32>>) {
        let pos =
            vec![[0.0, 0.0, 1.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [-1.0, -1.0, 0.0], [1.0, -1.0, 0.0]];
        let tris = vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]];
        let vf = super::super::vertex_faces(pos.len(), &tris);
        (pos, tris, vf)
    }

    #[test]
    fn feet_piled_at_an_apex_are_spread_in_the_curve_points_own_order() {
        let (pos, tris, vf) = pyramid();
        // Points high above the apex, inside its normal cone: every closest point is the apex.
        let points: Vec<Point3> = (0..5).map(|k| [0.1 * k as f64 - 0.2, 0.05, 2.0]).collect();
        let mut feet: Vec<Foot> = super::super::feet(&pos, &tris, &points, &[0, 1, 2, 3, 4]).unwrap();
        assert!(feet.iter().all(|f| dist(f.1, pos[0]) < 1e-15), "the case: all feet at the apex");
        let moved = spread_piled_feet(&pos, &tris, &vf, &points, &mut feet, &[false; 5]);
        assert_eq!(moved, 5);
        for (k, f) in feet.iter().enumerate() {
            // On the pyramid: in the plane of its face.
            let t = tris[f.0 as usize].map(|v| pos[v as usize]);
            assert!(dist(closest_on_triangle(f.1, &t), f.1) < 1e-12, "foot {k} off its face");
            assert!((f.2 - dist(points[k], f.1)).abs() < 1e-12);
        }
        // The points' x order survives (they differ along x only), all 1e-3 or more apart.
        for w in feet.windows(2) {
            assert!(w[1].1[0] - w[0].1[0] > 1e-3, "{:?} then {:?}", w[0].1, w[1].1);
        }
    }

    #[test]
    fn a_point_straight_above_the_pile_keeps_it_and_kept_points_do_not_move() {
        let (pos, tris, vf) = pyramid();
        let points = vec![[0.0, 0.0, 2.0], [0.1, 0.0, 2.0], [0.2, 0.0, 2.0]];
        let mut feet: Vec<Foot> = super::super::feet(&pos, &tris, &points, &[0, 1, 2]).unwrap();
        let before = feet.clone();
        let moved = spread_piled_feet(&pos, &tris, &vf, &points, &mut feet, &[false, false, true]);
        assert_eq!(moved, 1);
        assert_eq!(feet[0].1, before[0].1);
        assert_eq!(feet[2].1, before[2].1);
        assert!(feet[1].1[0] > 0.01 && feet[1].1[0] < 0.1);
    }
}
