//! What the fit's repair stages test a face against: the direction it should face.
//!
//! Why one trait: the report's `flipped_faces` counts faces against the template's normal carried
//! by the fit's maps ([`super::orientation`]), and every stage that repairs folds (the untangling
//! after the fine stage, after re-triangulation and after smoothing, the clean-up's guard, the
//! smoothing's undo) should decide "folded" against that same reference, or it "fixes" faces
//! toward another one. They use the area-weighted vertex normals of the fine-deformed surface: at
//! a 135° crease of small template faces next to large ones those normals follow the large faces,
//! and the untangling turns the small ones over (the headline's 3 flipped faces). Through
//! [`Reference::face`] the repair and the count can share one definition of a face's reference
//! ([`super::orientation::Orientation`] implements it with the count's own function).
//!
//! **Not switched on (session 15):** the pipeline still passes the plain per-vertex normals
//! ([`Vec<Point3>`]: a face's reference is the sum of its corners' normals). Passing the
//! `Orientation` halved the report's count on `sweep_deformed` but raised the faces against the
//! independent truth surface (19,372 → 19,642–19,678) and failed a CAD test
//! (docs/benchmarks.md, session 15).

use crate::geometry::{add, normalize};
use crate::mesh::Point3;

use super::trimesh::TriMesh;

/// The direction each face of a working mesh should face.
pub trait Reference: Sync {
    /// Face `t`'s reference direction (any length; zero when there is none, and then nothing
    /// can be decided against it). A face is turned over when its normal opposes it.
    fn face(&self, t: [u32; 3]) -> Point3;

    /// [`Reference::face`] of live face id `f` of `mesh` (an implementation may have it cached:
    /// a face id's corners never change, `TriMesh` never reuses an id).
    fn face_of(&self, mesh: &TriMesh, f: u32) -> Point3 {
        self.face(mesh.tris[f as usize])
    }

    /// A unit normal at vertex `v` of `mesh`, for the algorithms that need one per vertex (the
    /// view direction of a ring's kernel, tangential moves, a patch's plane): the normalised sum
    /// of the references of the faces around it (zero when they cancel).
    fn vertex(&self, mesh: &TriMesh, v: u32) -> Point3 {
        let sum = mesh
            .faces_of(v)
            .iter()
            .fold([0.0; 3], |s, &g| add(s, normalize(self.face(mesh.tris[g as usize]))));
        normalize(sum)
    }
}

/// A [`Reference`] that grows with the vertices the untangling adds on split edges.
pub trait SplitReference: Reference {
    /// How many vertices it covers.
    fn vertex_count(&self) -> usize;
    /// Covers one more vertex: the midpoint of edge `a`–`b`.
    fn push_midpoint(&mut self, a: u32, b: u32);
    /// Forgets the vertices from `n` on (a rolled-back round of splits).
    fn truncate_vertices(&mut self, n: usize);
}

/// Unit vertex normals (zero for none): a face's reference is the sum of its corners'.
impl Reference for Vec<Point3> {
    fn face(&self, t: [u32; 3]) -> Point3 {
        add(add(self[t[0] as usize], self[t[1] as usize]), self[t[2] as usize])
    }

    fn vertex(&self, _mesh: &TriMesh, v: u32) -> Point3 {
        self[v as usize]
    }
}

impl SplitReference for Vec<Point3> {
    fn vertex_count(&self) -> usize {
        self.len()
    }

    fn push_midpoint(&mut self, a: u32, b: u32) {
        let n = normalize(add(self[a as usize], self[b as usize]));
        self.push(n);
    }

    fn truncate_vertices(&mut self, n: usize) {
        self.truncate(n);
    }
}

#[cfg(test)]
mod tests;
