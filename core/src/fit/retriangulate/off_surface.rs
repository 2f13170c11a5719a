//! Segments with no surface under them: a curve that crosses a hole of the template (a scan with
//! a gap under a curve) or runs past its outer boundary.
//!
//! The fine stage drags the hole's rim onto the curve points over it, so both ends of such a
//! segment are mesh vertices, but the straight way between them crosses the gap. No chain of
//! edges can follow it: the walk stops at the rim or at another chain, and the route fallback
//! finds a way *around* the hole, which is no realisation of the segment and cuts the faces
//! between the route and the rim off as a spurious region (measured: 9 regions instead of the
//! octants' 8, detours 3.5–4.9× the segment). Such a segment is left unrealised and counted
//! apart (`off_surface_segments`): the regions on either side of the curve stay apart anyway,
//! since the chains on both sides of the gap end on the rim.
//!
//! The test (the caller, `fallback.rs`, also asks for both ends on the rim and no route across
//! faces within `LONG_DETOUR` × the ends' distance): points along the segment whose nearest point on the surface around it lies on a
//! boundary edge, farther than [`OFF_FRACTION`] of the segment's length. A segment over the surface
//! (ends on it after the fine stage) is within its sagitta of it, with the nearest point inside a
//! face; only a segment whose chord leaves the surface over its rim has a far nearest point on
//! the rim.

use crate::geometry::dist;
use crate::hash::IntSet;
use crate::mesh::Point3;
use crate::spatial::closest_on_triangle;

use super::super::trimesh::TriMesh;

/// A sample farther from the surface than this fraction of the segment's length, with its nearest
/// surface point on the rim, is over a gap. (A chord of a rim circle is this far from it at its
/// middle only when it spans more than ~106° of the circle: chords near the rim stay routable.)
pub(super) const OFF_FRACTION: f64 = 0.25;

/// Faces searched around a segment at most (the test is then inconclusive: not off the surface).
const FACE_BUDGET: usize = 20_000;

/// Whether the straight segment between mesh vertices `u` and `w` leaves the surface over its
/// boundary (a hole or the outer rim). Searches the faces connected to the ends' stars within
/// 1.5 × the segment's length of its middle.
pub(super) fn is_off_surface(mesh: &TriMesh, u: u32, w: u32) -> bool {
    let (a, b) = (mesh.pos[u as usize], mesh.pos[w as usize]);
    let len = dist(a, b);
    if len <= 0.0 {
        return false;
    }
    let at =
        |t: f64| -> Point3 { [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])] };
    let mid = at(0.5);
    let samples = [at(0.25), mid, at(0.75)];
    // Per sample: nearest distance to any face, and to any boundary edge.
    let mut surf = [f64::INFINITY; 3];
    let mut rim = [f64::INFINITY; 3];
    let mut seen: IntSet<u32> = IntSet::default();
    let mut stack: Vec<u32> = Vec::new();
    for &v in &[u, w] {
        for &f in mesh.faces_of(v) {
            if seen.insert(f) {
                stack.push(f);
            }
        }
    }
    while let Some(f) = stack.pop() {
        if seen.len() > FACE_BUDGET {
            return false;
        }
        let t = mesh.tris[f as usize];
        let corners = t.map(|v| mesh.pos[v as usize]);
        for (k, s) in samples.iter().enumerate() {
            surf[k] = surf[k].min(dist(*s, closest_on_triangle(*s, &corners)));
        }
        for e in 0..3 {
            let (l, r) = (t[e], t[(e + 1) % 3]);
            match mesh.across(f, l, r) {
                None => {
                    let (p, q) = (mesh.pos[l as usize], mesh.pos[r as usize]);
                    for (k, s) in samples.iter().enumerate() {
                        rim[k] = rim[k].min(super::super::point_segment_distance(*s, p, q));
                    }
                }
                Some(g) => {
                    if seen.contains(&g) {
                        continue;
                    }
                    let tg = mesh.tris[g as usize].map(|v| mesh.pos[v as usize]);
                    if dist(mid, closest_on_triangle(mid, &tg)) <= 1.5 * len {
                        seen.insert(g);
                        stack.push(g);
                    }
                }
            }
        }
    }
    (0..3).any(|k| surf[k] > OFF_FRACTION * len && rim[k] <= surf[k] * (1.0 + 1e-9) + 1e-12 * len)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat 6 × 6 grid of unit squares (z = 0) with the 2 × 2 squares around (3, 3) removed.
    fn grid_with_gap() -> TriMesh {
        let n = 6usize;
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let pos: Vec<Point3> =
            (0..=n).flat_map(|j| (0..=n).map(move |i| [i as f64, j as f64, 0.0])).collect();
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if (2..4).contains(&i) && (2..4).contains(&j) {
                    continue;
                }
                tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        TriMesh::new(pos, tris).unwrap()
    }

    #[test]
    fn a_segment_across_the_gap_is_off_the_surface_one_beside_it_is_not() {
        let m = grid_with_gap();
        let id = |i: u32, j: u32| j * 7 + i;
        // (2, 3) → (4, 3) crosses the 2 × 2 gap through its middle: the middle sample (3, 3) is 1
        // from the rim (0.5 of the length 2). Hand truth: off.
        assert!(is_off_surface(&m, id(2, 3), id(4, 3)));
        // (2, 2) → (4, 2) runs along the gap's rim edges: on the surface.
        assert!(!is_off_surface(&m, id(2, 2), id(4, 2)));
        // (1, 1) → (5, 1) runs over faces below the gap: on the surface.
        assert!(!is_off_surface(&m, id(1, 1), id(5, 1)));
        // (2, 2) → (3, 4) cuts across the gap's corner: its samples (2.25, 2.5), (2.5, 3),
        // (2.75, 3.5) are 0.25, 0.5, 0.5 from the rim, at most 0.5 / √5 = 0.22 of the length
        // (below 0.25): a chord near the rim stays routable.
        assert!(!is_off_surface(&m, id(2, 2), id(3, 4)));
        // (2, 4) → (4, 2), the gap's diagonal: the middle (3, 3) is 1 from the rim, 0.35 of the
        // length 2√2: off.
        assert!(is_off_surface(&m, id(2, 4), id(4, 2)));
    }
}
