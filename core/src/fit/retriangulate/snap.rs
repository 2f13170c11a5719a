//! Moving a vertex onto a segment only where that turns no face of its star over.

use crate::geometry::{cross, dot, norm, sub};
use crate::mesh::Point3;

use super::super::trimesh::TriMesh;

/// Would moving `z` to `target` keep every face of its star turned the way `reference` says
/// (the face's current normal when `reference` has none) and of non-negligible area?
pub(super) fn keeps_orientation(
    mesh: &TriMesh,
    z: u32,
    target: Point3,
    reference: impl Fn(u32) -> Option<Point3>,
) -> bool {
    mesh.faces_of(z).iter().all(|&f| {
        let t = mesh.tris[f as usize];
        let p = |v: u32| if v == z { target } else { mesh.pos[v as usize] };
        let n0 = mesh.face_normal(f);
        let r = reference(f).unwrap_or(n0);
        let n1 = cross(sub(p(t[1]), p(t[0])), sub(p(t[2]), p(t[0])));
        dot(r, n1) > 0.0 && dot(n0, n1) > 0.0 && norm(n1) > 1e-12 * norm(n0)
    })
}
