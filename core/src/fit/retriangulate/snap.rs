//! Moving a vertex onto a segment only where that turns no face of its star over.

use crate::geometry::{cross, dot, norm, sub};
use crate::mesh::Point3;

use super::super::trimesh::TriMesh;

/// A vertex put onto a segment may turn each face of its star by at most this (cosine: about
/// 26°). Why: a route's split points sit on the surface; pulled onto the straight segment across a
/// curved or folded patch they stood faces on edge that only had to stay "not turned over", and
/// the later stages counted them (session 21: without the bound, 528 / 699 flipped faces on the
/// two deformed sweep sets; with it 474 / 604, folded edges 495 → 383, 591 → 503).
pub(super) const SNAP_MAX_TURN_COS: f64 = 0.9;

/// Would moving `z` to `target` keep every face of its star turned the way `reference` says
/// (the face's current normal when `reference` has none), of non-negligible area, and turned by
/// less than `arccos(min_cos)` from that reference?
pub(super) fn keeps_orientation(
    mesh: &TriMesh,
    z: u32,
    target: Point3,
    reference: impl Fn(u32) -> Option<Point3>,
    min_cos: f64,
) -> bool {
    mesh.faces_of(z).iter().all(|&f| {
        let t = mesh.tris[f as usize];
        let p = |v: u32| if v == z { target } else { mesh.pos[v as usize] };
        let n0 = mesh.face_normal(f);
        let r = reference(f).unwrap_or(n0);
        let n1 = cross(sub(p(t[1]), p(t[0])), sub(p(t[2]), p(t[0])));
        dot(r, n1) > min_cos * norm(r) * norm(n1) && dot(n0, n1) > 0.0 && norm(n1) > 1e-12 * norm(n0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat square fan around vertex 0 at the origin (corners at distance 1 on the axes).
    fn fan() -> TriMesh {
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]];
        TriMesh::new(pos, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]]).unwrap()
    }

    #[test]
    fn a_move_may_tilt_the_star_only_within_the_bound() {
        // Lifting the centre by h tilts each face by atan(h / (1/√2)) (its far edge is 1/√2 away):
        // h = 0.2 → 15.8°, h = 0.5 → 35.3° (hand-computed); the bound is arccos 0.9 = 25.8°.
        let m = fan();
        assert!(keeps_orientation(&m, 0, [0.0, 0.0, 0.2], |_| None, SNAP_MAX_TURN_COS));
        assert!(!keeps_orientation(&m, 0, [0.0, 0.0, 0.5], |_| None, SNAP_MAX_TURN_COS));
        // Without the bound only turning over counts: the lifted centre is accepted.
        assert!(keeps_orientation(&m, 0, [0.0, 0.0, 0.5], |_| None, 0.0));
        // Sliding within the plane past an edge turns a face over: refused either way.
        assert!(!keeps_orientation(&m, 0, [0.8, 0.8, 0.0], |_| None, 0.0));
    }
}
