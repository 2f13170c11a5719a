//! The guaranteed fallback: a route across faces from one end of a segment to the other that
//! never crosses a realised curve edge and never passes through a vertex, made a chain by
//! splitting every edge it crosses.
//!
//! Why it always works when any chain can: the route is a path in the dual graph (faces joined
//! across edges that are not curve edges), from a face of the start vertex's star to a face of
//! the end vertex's star, each face at most once. Splitting its crossed edges in order joins the
//! new vertices one to the next (two crossed edges of one face become two edges of one child
//! face), the first to the start and the last to the end. A split point strictly inside an edge
//! gives children inside the parent face, so no face turns over. If no such route exists, the
//! curve edges already realised separate the two ends on the surface: the network's embedding
//! is tangled (two segments would have to cross) and no chain without crossing exists.
//!
//! The route is the shortest one (Dijkstra over faces, each face entered once) when every crossed
//! edge is crossed at its point nearest the straight segment, kept away from the edge's ends.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::geometry::{add, dist, dot, norm2, scale, sub};
use crate::mesh::Point3;

use super::super::trimesh::{IntMap, TriMesh};
use super::EdgeSet;

/// Split points stay this far (edge fraction) from an edge's ends: no sliver children.
const END_MARGIN: f64 = 0.1;

/// One crossed edge (l, r) and where it is crossed (fraction from l).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Crossing {
    pub l: u32,
    pub r: u32,
    pub lam: f64,
}

/// Why no route was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum NoRoute {
    /// Every face reachable from the start without crossing a curve edge was searched: the ends
    /// are separated by realised curves (crossing input or a tangled embedding).
    Separated,
    /// The search budget ran out before reaching the end.
    Budget,
}

/// The fraction along edge p→q of its point nearest the segment a–b, clamped off the ends.
fn nearest_fraction(p: Point3, q: Point3, a: Point3, b: Point3) -> f64 {
    // Closest points of two segments: minimise |p + s(q-p) - a - t(b-a)|² over s, t in [0, 1],
    // by alternating the two clamped one-dimensional minimisations (converges in a few steps
    // for segments; exactness is not needed, only a point near the segment).
    let (d1, d2) = (sub(q, p), sub(b, a));
    let (l1, l2) = (norm2(d1), norm2(d2));
    if l1 <= 0.0 {
        return 0.5;
    }
    let mut s = 0.5;
    for _ in 0..4 {
        let x = add(p, scale(d1, s));
        let t = if l2 > 0.0 { (dot(sub(x, a), d2) / l2).clamp(0.0, 1.0) } else { 0.0 };
        let y = add(a, scale(d2, t));
        s = (dot(sub(y, p), d1) / l1).clamp(0.0, 1.0);
    }
    s.clamp(END_MARGIN, 1.0 - END_MARGIN)
}

/// Per face reached: best distance, where it was entered, and the (previous face, crossing) it
/// was entered by (none for the start's star).
type Reached = (f64, Point3, Option<(u32, Crossing)>);

/// The shortest route of crossings from `from` to `to` (neither on the other's star), avoiding
/// `locked` edges; `a`–`b` is the straight segment the crossings stay near. At most `budget`
/// faces are settled.
pub(super) fn find(
    mesh: &TriMesh,
    from: u32,
    to: u32,
    (a, b): (Point3, Point3),
    locked: &EdgeSet,
    budget: usize,
) -> Result<Vec<Crossing>, NoRoute> {
    let is_locked = |x: u32, y: u32| locked.contains(&(x.min(y), x.max(y)));
    let mut best: IntMap<u32, Reached> = IntMap::default();
    let mut heap = BinaryHeap::new();
    let start = mesh.pos[from as usize];
    for &f in mesh.faces_of(from) {
        best.insert(f, (0.0, start, None));
        heap.push(Reverse((0u64, f)));
    }
    let mut settled = 0usize;
    while let Some(Reverse((dbits, f))) = heap.pop() {
        let (df, entry, _) = best[&f];
        if f64::from_bits(dbits) > df {
            continue;
        }
        let t = mesh.tris[f as usize];
        if t.contains(&to) {
            // Walk the entry crossings back to a face of the start's star.
            let mut out = Vec::new();
            let mut g = f;
            while let Some((prev, c)) = best[&g].2 {
                out.push(c);
                g = prev;
            }
            out.reverse();
            return Ok(out);
        }
        settled += 1;
        if settled > budget {
            return Err(NoRoute::Budget);
        }
        for k in 0..3 {
            let (l, r) = (t[k], t[(k + 1) % 3]);
            if l == from || r == from || is_locked(l, r) {
                continue;
            }
            let Some(g) = mesh.across(f, l, r) else { continue };
            let (pl, pr) = (mesh.pos[l as usize], mesh.pos[r as usize]);
            let lam = nearest_fraction(pl, pr, a, b);
            let x = add(pl, scale(sub(pr, pl), lam));
            let nd = df + dist(entry, x);
            if best.get(&g).is_none_or(|e| nd < e.0) {
                best.insert(g, (nd, x, Some((f, Crossing { l, r, lam }))));
                // Non-negative f64 bit patterns order like the values.
                heap.push(Reverse((nd.to_bits(), g)));
            }
        }
    }
    Err(NoRoute::Separated)
}

/// Whether `from` and `to` lie on one piece of the mesh: a face of `to`'s star is reachable from
/// a face of `from`'s across edges (curve edges included). When not, no chain of edges can join
/// them: they are on different components of the template, or on the two sides of an unwelded
/// seam (a crack whose coincident boundary edges are not shared). Visits each face at most once.
pub(super) fn on_one_piece(mesh: &TriMesh, from: u32, to: u32) -> bool {
    let mut seen: crate::hash::IntSet<u32> = Default::default();
    let mut stack: Vec<u32> = mesh.faces_of(from).to_vec();
    seen.extend(stack.iter().copied());
    while let Some(f) = stack.pop() {
        let t = mesh.tris[f as usize];
        if t.contains(&to) {
            return true;
        }
        for k in 0..3 {
            if let Some(g) = mesh.across(f, t[k], t[(k + 1) % 3]) {
                if seen.insert(g) {
                    stack.push(g);
                }
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_fraction_finds_the_crossing_and_keeps_off_the_ends() {
        // Edge from (1, -1) to (1, 1) and segment from (0, 0) to (2, 0) (hand truth: cross at the
        // middle); an edge that passes the segment's end is clamped to the margin.
        let f = nearest_fraction([1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [0.0; 3], [2.0, 0.0, 0.0]);
        assert!((f - 0.5).abs() < 1e-12);
        let f = nearest_fraction([3.0, 0.0, 0.0], [3.0, 2.0, 0.0], [0.0; 3], [2.0, 0.0, 0.0]);
        assert_eq!(f, END_MARGIN);
    }
}
