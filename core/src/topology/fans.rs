//! Fans around a vertex (see the module docs of [`super`]): the per-vertex count used by repair and
//! the all-vertex [`VertexKind`] classification used by validation.

use super::{find, union, Topology, NONE, POLL_ITEMS};
use crate::error::Result;
use crate::job::Progress;

/// What the faces around a vertex look like (see the module docs for fans and pinches).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VertexKind {
    /// No face uses the vertex.
    Unreferenced,
    /// One closed fan: an interior manifold vertex.
    Interior,
    /// One open fan: a manifold boundary vertex.
    Boundary,
    /// Several fans, all open, no non-manifold edge: boundary loops touching (seed 003 Fig. 4.6).
    /// Not a non-manifold vertex; filling either hole makes it a regular vertex.
    Pinch,
    /// Several fans, at least one closed, no non-manifold edge at the vertex.
    NonManifold,
    /// The vertex is an end of a non-manifold edge (reported through the edge, not as a vertex).
    OnNonManifoldEdge,
}

impl Topology {
    /// Fans around vertex `v`: returns (number of fans, number of closed fans, whether a
    /// non-manifold edge touches `v`). Fans are the classes of corners at `v` joined through
    /// manifold edges incident to `v`; a fan is closed when none of its corners touches a
    /// boundary, non-manifold or degenerate edge.
    pub fn fans(&self, v: u32) -> (usize, usize, bool) {
        let mut scratch = FanScratch::default();
        self.fans_with(v, &mut scratch)
    }

    pub(super) fn fans_with(&self, v: u32, s: &mut FanScratch) -> (usize, usize, bool) {
        let corners = self.vertex_corners(v);
        let m = corners.len();
        s.parent.clear();
        s.parent.extend(0..m as u32);
        s.open.clear();
        s.open.resize(m, false);
        let mut nm_edge = false;
        for i in 0..m {
            let c = corners[i] as usize;
            // The two half-edges at this corner: leaving (c) and arriving (prev(c)).
            for h in [c, self.prev_corner(c)] {
                let e = self.corner_edge[h];
                if e == NONE {
                    s.open[i] = true;
                    continue;
                }
                let val = self.edge_valence(e);
                if val != 2 {
                    s.open[i] = true;
                    nm_edge |= val > 2;
                    continue;
                }
                let Some(o) = self.other_use(e, h) else {
                    s.open[i] = true;
                    continue;
                };
                let oc = self.corner_at(self.use_corner(&o), v);
                if let Ok(j) = corners.binary_search(&(oc as u32)) {
                    union(&mut s.parent, i as u32, j as u32);
                } else {
                    s.open[i] = true;
                }
            }
        }
        // Count roots, and roots whose class has no open corner.
        s.class_open.clear();
        s.class_open.resize(m, false);
        let mut fans = 0;
        for i in 0..m {
            let r = find(&mut s.parent, i as u32) as usize;
            if r == i {
                fans += 1;
            }
            if s.open[i] {
                s.class_open[r] = true;
            }
        }
        let closed = (0..m).filter(|&i| s.parent[i] == i as u32 && !s.class_open[i]).count();
        (fans, closed, nm_edge)
    }

    /// Kind of every vertex (see [`VertexKind`]).
    pub fn vertex_kinds(&self) -> Vec<VertexKind> {
        self.vertex_kinds_polled(&Progress::new())
            .expect("vertex_kinds_polled fails only through progress.check(), and a fresh Progress is never cancelled")
    }

    /// [`Topology::vertex_kinds`], polling `progress` every [`POLL_ITEMS`] edges and vertices.
    pub fn vertex_kinds_polled(&self, progress: &Progress) -> Result<Vec<VertexKind>> {
        // One global union-find over corners: the two corners at each end of a manifold edge are
        // in the same fan. Unions only join corners of the same vertex, and the smaller index wins,
        // so every class's root is one of that vertex's corners. (Same result as [`Topology::fans`]
        // per vertex, without a binary search per corner.)
        let nc = self.corner_vertex.len();
        let mut parent: Vec<u32> = (0..nc as u32).collect();
        for e in 0..self.edges.len() {
            progress.check_every(e, POLL_ITEMS)?;
            let (lo, hi) = (self.edge_offsets[e] as usize, self.edge_offsets[e + 1] as usize);
            if hi - lo != 2 {
                continue;
            }
            let (c0, c1) = (self.use_corner(&self.uses[lo]), self.use_corner(&self.uses[lo + 1]));
            let n0 = self.next_corner(c0);
            let (a, b) = (self.corner_vertex[c0], self.corner_vertex[n0]);
            union(&mut parent, c0 as u32, self.corner_at(c1, a) as u32);
            union(&mut parent, n0 as u32, self.corner_at(c1, b) as u32);
        }
        // A corner is open when one of its two sides is not a manifold edge.
        let side = |h: usize| -> (bool, bool) {
            let e = self.corner_edge[h];
            if e == NONE {
                return (true, false);
            }
            let v = self.edge_valence(e);
            (v != 2, v > 2)
        };
        let mut class_open = vec![false; nc];
        let mut kinds = Vec::with_capacity(self.n_vertices);
        for v in 0..self.n_vertices {
            progress.check_every(v, POLL_ITEMS)?;
            let corners = self.vertex_corners.row(v);
            if corners.is_empty() {
                kinds.push(VertexKind::Unreferenced);
                continue;
            }
            let mut nm_edge = false;
            for &c in corners {
                let c = c as usize;
                let (o1, n1) = side(c);
                let (o2, n2) = side(self.prev_corner(c));
                nm_edge |= n1 | n2;
                if o1 | o2 {
                    let r = find(&mut parent, c as u32) as usize;
                    class_open[r] = true;
                }
            }
            let (mut fans, mut closed) = (0, 0);
            for &c in corners {
                if find(&mut parent, c) == c {
                    fans += 1;
                    closed += usize::from(!class_open[c as usize]);
                }
            }
            kinds.push(if nm_edge {
                VertexKind::OnNonManifoldEdge
            } else if fans == 1 {
                if closed == 1 {
                    VertexKind::Interior
                } else {
                    VertexKind::Boundary
                }
            } else if closed == 0 {
                VertexKind::Pinch
            } else {
                VertexKind::NonManifold
            });
        }
        Ok(kinds)
    }
}

/// Reusable buffers for the per-vertex fan union-find.
#[derive(Default)]
pub(super) struct FanScratch {
    pub(super) parent: Vec<u32>,
    pub(super) open: Vec<bool>,
    pub(super) class_open: Vec<bool>,
}
