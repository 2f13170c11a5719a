//! The carried orientation as the repair stages' reference ([`super::super::reference`]): what
//! the untanglings, the clean-up's guard and the smoothing's undo would test faces against once the
//! pipeline passes it (docs/benchmarks.md, fit-carried and lead, session 15: not switched on, because
//! the independent truth got worse). Kept apart from the count so the count's module stays one
//! responsibility; a child module, so it reads the `Orientation`'s fields directly.

use rayon::prelude::*;

use crate::error::Result;
use crate::job::Progress;
use crate::mesh::Point3;

use super::super::reference::{Reference, SplitReference};
use super::super::trimesh::TriMesh;
use super::{cofactor, Jacobian, Orientation, Side, REPAIR_SIDE};

impl Orientation {
    /// Caches the repair reference ([`Reference::face`]) of the face ids of `tris` past the
    /// cached ones, in parallel, polling between chunks. Why: the repair stages' scans ask for
    /// every face many times (the untanglings' reference cost ~80 ms of CPU each on the headline
    /// uncached), and a face id's corners never change (`TriMesh` never reuses an id), nor do
    /// the Jacobians of existing vertices. For the fit's one working mesh, from the fine stage
    /// on; only ever called between stages (an untangling that rolls back splits reuses ids past
    /// its start, which are never cached).
    pub fn cache_faces(&mut self, tris: &[[u32; 3]], progress: &Progress) -> Result<()> {
        const CHUNK: usize = 16384;
        // cof(J) of every vertex first (faces not cached, e.g. the clean-up's candidates, use it).
        progress.check()?;
        let from = self.cofactors.len().min(self.jacobians.len());
        let more: Vec<Jacobian> = self.jacobians[from..].par_iter().map(cofactor).collect();
        self.cofactors.extend(more);
        while self.face_cache.len() < tris.len() {
            progress.check()?;
            let from = self.face_cache.len();
            let to = (from + CHUNK).min(tris.len());
            let this = &*self;
            let chunk: Vec<Point3> = tris[from..to].par_iter().map(|&t| this.face(t)).collect();
            self.face_cache.extend(chunk);
        }
        Ok(())
    }
}

/// The repair stages' reference ([`super::super::reference`]): the count's function with the stored
/// Jacobians, without the error bounds (the count decides again exactly only the faces the bounds
/// leave open: 5 of 193,548 on the headline), on the maps' image side ([`Side::Image`]: the same
/// as the count's wherever no corner of a face was inverted by the maps). Valid for the working
/// numbering, before [`Orientation::renumbered`].
impl Reference for Orientation {
    fn face(&self, t: [u32; 3]) -> Point3 {
        self.reference_with(&t, REPAIR_SIDE, |v| (self.jacobians[v as usize], 0.0)).0
    }

    fn face_of(&self, mesh: &TriMesh, f: u32) -> Point3 {
        match self.face_cache.get(f as usize) {
            Some(&r) => r,
            None => self.face(mesh.tris[f as usize]),
        }
    }
}

/// The repair reference of the untangling right after the fine stage ([`Side::LastMap`]).
pub struct AfterLastMap<'a>(pub &'a Orientation);

impl Reference for AfterLastMap<'_> {
    fn face(&self, t: [u32; 3]) -> Point3 {
        let o = self.0;
        o.reference_with(&t, Side::LastMap, |v| (o.jacobians[v as usize], 0.0)).0
    }

    fn face_of(&self, mesh: &TriMesh, f: u32) -> Point3 {
        let t = mesh.tris[f as usize];
        if REPAIR_SIDE == Side::Image && !t.iter().any(|&v| self.0.last_inverted[v as usize]) {
            // The same as the cached repair reference where the last map inverts no corner.
            self.0.face_of(mesh, f)
        } else {
            self.face(t)
        }
    }
}

/// Vertices the untangling adds on split edges take the blend of the edge's ends, as
/// [`Orientation::sync`] gives them from the parents the fit records for them.
impl SplitReference for Orientation {
    fn vertex_count(&self) -> usize {
        self.jacobians.len()
    }

    fn push_midpoint(&mut self, a: u32, b: u32) {
        self.push_vertex(&[(a, 0.5), (b, 0.5), (a, 0.0)]);
    }

    fn truncate_vertices(&mut self, n: usize) {
        self.truncate_to(n);
    }
}
