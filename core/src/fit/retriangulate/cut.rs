//! The cutting plane of a segment: the plane through its two ends that contains the mean surface
//! normal there. The walk decides the side of every vertex once from its signed distance `s`, so
//! it stays consistent across faces and cannot lose its way when the path runs through a vertex.

use crate::geometry::{add, dot, scale, sub};
use crate::mesh::Point3;

use super::super::trimesh::TriMesh;

/// The plane through the segment that contains the mean surface normal.
pub(super) struct Cut {
    pub a: Point3,
    pub dir: Point3,
    pub side: Point3,
    pub len: f64,
}

impl Cut {
    pub(super) fn s(&self, p: Point3) -> f64 {
        dot(sub(p, self.a), self.side)
    }
    pub(super) fn t(&self, p: Point3) -> f64 {
        dot(sub(p, self.a), self.dir)
    }
    pub(super) fn on_line(&self, p: Point3) -> Point3 {
        add(self.a, scale(self.dir, self.t(p).clamp(0.0, self.len)))
    }
}

/// Where the cut plane crosses edge (l, r) (s(l) ≥ 0 > s(r)): the point and its parameter from l.
pub(super) fn crossing(mesh: &TriMesh, cut: &Cut, l: u32, r: u32) -> (Point3, f64) {
    let (pl, pr) = (mesh.pos[l as usize], mesh.pos[r as usize]);
    let (sl, sr) = (cut.s(pl), cut.s(pr));
    let lam = if sl - sr > 0.0 { (sl / (sl - sr)).clamp(0.0, 1.0) } else { 0.5 };
    (add(pl, scale(sub(pr, pl), lam)), lam)
}
