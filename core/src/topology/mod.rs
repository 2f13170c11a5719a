//! Adjacency derived on demand from a face list: undirected edges with their incident faces,
//! vertex → corners/faces, vertex neighbour rings, fans, boundary loops, connected components and
//! manifold checks.
//!
//! Nothing here assumes a manifold, consistently oriented or even non-degenerate input: this is
//! the module validation and repair stand on, and their input is by definition broken. Faces may
//! have any arity (each face contributes one half-edge per corner, from corner `k` to corner
//! `k + 1`, cyclically). A half-edge whose two ends are the same vertex (a face repeating an index)
//! is *degenerate*: it gets no edge id ([`NONE`]) and is counted by [`Topology::degenerate_half_edges`].
//!
//! # Vocabulary
//! - *corner*: one entry of the face index array, addressed globally by its position in
//!   [`crate::mesh::Faces::indices`]; corner `c` also names the half-edge from `c` to the next
//!   corner of the same face.
//! - *edge*: an unordered vertex pair `[lo, hi]`, `lo < hi`, with the list of its *uses*
//!   ([`EdgeUse`]): each half-edge lying on it. 1 use = boundary, 2 = manifold, > 2 = non-manifold.
//! - *fan*: the faces around a vertex that are connected through manifold edges incident to that
//!   vertex. A manifold vertex has one fan (closed for an interior vertex, open for a boundary one).
//!   A vertex with several fans that are *all open* is where boundary loops touch (a "pinch", seed 003
//!   Fig. 4.6: two holes sharing a vertex) and is **not** counted as non-manifold; a vertex with
//!   several fans of which one is closed is a real non-manifold vertex (e.g. two cones touching at
//!   their tips).
//!
//! # Cost
//! [`Topology::new`] is O(corners) plus a sort of each vertex's (short) edge bucket: the half-edges
//! are bucketed by their smaller vertex with a counting sort, so there is no hash map per edge.
//! Everything else (rings, fans, loops, components) is computed by a method when asked for.
//!
//! Files: `build` (the tables from a face list), this file (the tables and what they answer
//! directly), `fans` (fans and vertex kinds), `loops` (boundary loops), `components`, `union_find`.

mod build;
mod components;
mod fans;
mod loops;
#[cfg(test)]
mod tests;
mod union_find;

pub use components::{Components, Connectivity};
use fans::FanScratch;
pub use fans::VertexKind;
pub use loops::BoundaryLoop;
pub(crate) use union_find::{find, union};

/// Vertices, edges or corners visited between two polls of the `_polled` passes (a few ms).
pub(crate) const POLL_ITEMS: usize = 32_768;

/// "No such index" marker (degenerate half-edges have no edge id).
pub const NONE: u32 = u32::MAX;

/// One half-edge lying on an undirected edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeUse {
    /// The face the half-edge belongs to.
    pub face: u32,
    /// Local corner index in that face: the half-edge runs from `face[corner]` to `face[corner + 1]`.
    pub corner: u32,
    /// True when the half-edge runs from the edge's `lo` vertex to its `hi` vertex.
    pub forward: bool,
}

/// Compressed sparse rows: row `i` is `items[offsets[i]..offsets[i + 1]]`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Csr {
    pub offsets: Vec<u32>,
    pub items: Vec<u32>,
}

impl Csr {
    /// Row `i`.
    #[inline]
    pub fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Vertex → triangles of `tris` over `nv` vertices, each row in increasing face order (a
    /// counting sort: two passes over the corners, no hash map). A face repeating a vertex is
    /// listed once in that vertex's row; indices `>= nv` are skipped.
    pub fn vertex_triangles(nv: usize, tris: &[[u32; 3]]) -> Csr {
        let distinct = |t: &[u32; 3]| {
            let t = *t;
            (0..3).filter(move |&k| !t[..k].contains(&t[k])).map(move |k| t[k] as usize)
        };
        let mut offsets = vec![0u32; nv + 1];
        for t in tris {
            for v in distinct(t).filter(|&v| v < nv) {
                offsets[v + 1] += 1;
            }
        }
        for i in 0..nv {
            offsets[i + 1] += offsets[i];
        }
        let mut next = offsets.clone();
        let mut items = vec![0u32; offsets[nv] as usize];
        for (f, t) in tris.iter().enumerate() {
            for v in distinct(t).filter(|&v| v < nv) {
                items[next[v] as usize] = f as u32;
                next[v] += 1;
            }
        }
        Csr { offsets, items }
    }

    /// The triangles of `tris` with edge `(a, b)` (either direction), in increasing order, from
    /// the row of `a` of a [`Csr::vertex_triangles`] table.
    pub fn triangles_on_edge<'a>(
        &'a self,
        tris: &'a [[u32; 3]],
        a: u32,
        b: u32,
    ) -> impl Iterator<Item = u32> + 'a {
        let row = if (a as usize) < self.rows() { self.row(a as usize) } else { &[] };
        row.iter().copied().filter(move |&f| tris[f as usize].contains(&b))
    }
}

/// Edge and incidence tables of a face list. Build with [`Topology::new`]; it does not borrow the
/// mesh (it keeps a copy of the face index arrays), so the mesh may be changed afterwards — the
/// topology then describes the old faces.
#[derive(Clone, Debug)]
pub struct Topology {
    n_vertices: usize,
    face_offsets: Vec<u32>,
    corner_vertex: Vec<u32>,
    corner_face: Vec<u32>,
    /// Edge id of the half-edge starting at each corner, [`NONE`] when degenerate.
    corner_edge: Vec<u32>,
    edges: Vec<[u32; 2]>,
    edge_offsets: Vec<u32>,
    uses: Vec<EdgeUse>,
    /// Edges are sorted by `lo`; `lo_start[v]..lo_start[v+1]` are the edges whose smaller end is `v`.
    lo_start: Vec<u32>,
    /// Vertex → global corners at that vertex (ascending).
    vertex_corners: Csr,
    degenerate_half_edges: usize,
}

impl Topology {
    // ---- sizes and raw access -------------------------------------------------------------

    /// Number of vertices covered (the mesh's vertex count, referenced or not).
    pub fn vertex_count(&self) -> usize {
        self.n_vertices
    }

    pub fn face_count(&self) -> usize {
        self.face_offsets.len() - 1
    }

    /// Number of distinct undirected edges (degenerate half-edges excluded).
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Half-edges whose two ends are the same vertex (faces repeating an index consecutively).
    pub fn degenerate_half_edges(&self) -> usize {
        self.degenerate_half_edges
    }

    /// All edges as `[lo, hi]`, sorted lexicographically; an edge's id is its position here.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    #[inline]
    pub fn edge(&self, e: u32) -> [u32; 2] {
        self.edges[e as usize]
    }

    /// The half-edges lying on edge `e`, ordered by face then corner.
    #[inline]
    pub fn edge_uses(&self, e: u32) -> &[EdgeUse] {
        &self.uses[self.edge_offsets[e as usize] as usize..self.edge_offsets[e as usize + 1] as usize]
    }

    /// Number of half-edges on edge `e` (1 boundary, 2 manifold, > 2 non-manifold).
    #[inline]
    pub fn edge_valence(&self, e: u32) -> usize {
        (self.edge_offsets[e as usize + 1] - self.edge_offsets[e as usize]) as usize
    }

    /// The edge joining `a` and `b`, if any (binary search in `min(a, b)`'s bucket).
    pub fn find_edge(&self, a: u32, b: u32) -> Option<u32> {
        let (lo, hi) = (a.min(b) as usize, a.max(b));
        if lo >= self.n_vertices || a == b {
            return None;
        }
        let range = self.lo_start[lo] as usize..self.lo_start[lo + 1] as usize;
        let base = range.start;
        self.edges[range].binary_search_by_key(&hi, |e| e[1]).ok().map(|i| (base + i) as u32)
    }

    /// Face `f`'s corners as global corner ids.
    #[inline]
    pub fn face_corners(&self, f: u32) -> std::ops::Range<usize> {
        self.face_offsets[f as usize] as usize..self.face_offsets[f as usize + 1] as usize
    }

    /// Face `f`'s vertex indices.
    #[inline]
    pub fn face_vertices(&self, f: u32) -> &[u32] {
        &self.corner_vertex[self.face_corners(f)]
    }

    /// Edge ids of face `f`'s half-edges (corner k → k+1), [`NONE`] for degenerate ones.
    #[inline]
    pub fn face_edges(&self, f: u32) -> &[u32] {
        &self.corner_edge[self.face_corners(f)]
    }

    /// The face a global corner belongs to.
    #[inline]
    pub fn corner_face(&self, c: usize) -> u32 {
        self.corner_face[c]
    }

    /// The vertex at a global corner.
    #[inline]
    pub fn corner_vertex(&self, c: usize) -> u32 {
        self.corner_vertex[c]
    }

    /// Edge id of the half-edge leaving global corner `c`, [`NONE`] if degenerate.
    #[inline]
    pub fn corner_edge(&self, c: usize) -> u32 {
        self.corner_edge[c]
    }

    /// The next corner of the same face (cyclically).
    #[inline]
    pub fn next_corner(&self, c: usize) -> usize {
        let f = self.corner_face[c] as usize;
        if c + 1 == self.face_offsets[f + 1] as usize {
            self.face_offsets[f] as usize
        } else {
            c + 1
        }
    }

    /// The previous corner of the same face (cyclically).
    #[inline]
    pub fn prev_corner(&self, c: usize) -> usize {
        let f = self.corner_face[c] as usize;
        if c == self.face_offsets[f] as usize {
            self.face_offsets[f + 1] as usize - 1
        } else {
            c - 1
        }
    }

    /// Global corner id of an edge use.
    #[inline]
    pub fn use_corner(&self, u: &EdgeUse) -> usize {
        self.face_offsets[u.face as usize] as usize + u.corner as usize
    }

    /// Global corners at vertex `v`, ascending (a face repeating `v` contributes several).
    #[inline]
    pub fn vertex_corners(&self, v: u32) -> &[u32] {
        self.vertex_corners.row(v as usize)
    }

    /// Faces using vertex `v`, possibly repeated when a face repeats `v`. See
    /// [`Topology::vertex_faces`] for a deduplicated table.
    pub fn vertex_faces_iter(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.vertex_corners(v).iter().map(move |&c| self.corner_face[c as usize])
    }

    /// Whether any face uses vertex `v`.
    pub fn is_referenced(&self, v: u32) -> bool {
        !self.vertex_corners(v).is_empty()
    }

    // ---- derived tables -------------------------------------------------------------------

    /// Vertex → faces (CSR), each face listed once per vertex, ascending.
    pub fn vertex_faces(&self) -> Csr {
        let mut offsets = Vec::with_capacity(self.n_vertices + 1);
        let mut items = Vec::with_capacity(self.corner_vertex.len());
        offsets.push(0);
        for v in 0..self.n_vertices as u32 {
            // Corners ascend, so faces ascend and repeats are adjacent.
            let mut last = NONE;
            for f in self.vertex_faces_iter(v) {
                if f != last {
                    items.push(f);
                    last = f;
                }
            }
            offsets.push(items.len() as u32);
        }
        Csr { offsets, items }
    }

    /// Vertex neighbour rings (CSR): the vertices sharing an edge with each vertex, ascending,
    /// without repeats. Not cyclically ordered (fans may be broken on bad input).
    pub fn vertex_neighbors(&self) -> Csr {
        let n = self.n_vertices;
        let mut offsets = vec![0u32; n + 1];
        for &[a, b] in &self.edges {
            offsets[a as usize + 1] += 1;
            offsets[b as usize + 1] += 1;
        }
        for v in 0..n {
            offsets[v + 1] += offsets[v];
        }
        let mut fill = offsets.clone();
        let mut items = vec![0u32; 2 * self.edges.len()];
        // Edges are sorted by (lo, hi): visiting them in order appends each row's entries in
        // ascending order for the "hi" side; the "lo" side needs a final sort of each row.
        for &[a, b] in &self.edges {
            items[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
            items[fill[b as usize] as usize] = a;
            fill[b as usize] += 1;
        }
        for v in 0..n {
            items[offsets[v] as usize..offsets[v + 1] as usize].sort_unstable();
        }
        Csr { offsets, items }
    }

    /// Edge ids with exactly one use.
    pub fn boundary_edges(&self) -> Vec<u32> {
        (0..self.edges.len() as u32).filter(|&e| self.edge_valence(e) == 1).collect()
    }

    /// Edge ids with more than two uses.
    pub fn non_manifold_edges(&self) -> Vec<u32> {
        (0..self.edges.len() as u32).filter(|&e| self.edge_valence(e) > 2).collect()
    }

    /// Manifold edges whose two faces traverse them in the same direction (orientation clash).
    pub fn inconsistent_edges(&self) -> Vec<u32> {
        (0..self.edges.len() as u32)
            .filter(|&e| {
                let u = self.edge_uses(e);
                u.len() == 2 && u[0].forward == u[1].forward
            })
            .collect()
    }

    /// For an edge with exactly two uses, the use other than the half-edge at global corner
    /// `corner` (None on boundary and non-manifold edges).
    pub fn other_use(&self, e: u32, corner: usize) -> Option<EdgeUse> {
        let u = self.edge_uses(e);
        if u.len() != 2 {
            return None;
        }
        if self.use_corner(&u[0]) == corner {
            Some(u[1])
        } else if self.use_corner(&u[1]) == corner {
            Some(u[0])
        } else {
            None
        }
    }

    /// The corner at vertex `v` of the half-edge starting at global corner `c` (`c` itself or
    /// the next corner).
    #[inline]
    pub fn corner_at(&self, c: usize, v: u32) -> usize {
        if self.corner_vertex[c] == v {
            c
        } else {
            self.next_corner(c)
        }
    }
}
