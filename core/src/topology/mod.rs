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

use crate::error::Result;
use crate::job::Progress;
use crate::mesh::{Faces, Mesh};
mod components;
mod fans;
mod loops;

pub use components::{Components, Connectivity};
use fans::FanScratch;
pub use fans::VertexKind;
pub use loops::BoundaryLoop;

/// "No such index" marker (degenerate half-edges have no edge id).
/// Vertices, edges or corners visited between two polls of the `_polled` passes (a few ms).
pub(crate) const POLL_ITEMS: usize = 32_768;

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
    /// Topology of a mesh's faces.
    pub fn new(mesh: &Mesh) -> Topology {
        Topology::from_faces(&mesh.faces, mesh.positions.len())
    }

    /// [`Topology::new`], polling `progress` between its passes and every [`POLL_ITEMS`]
    /// vertices of the edge pass (~50 ms of work on 280k faces otherwise out of reach of a cancel).
    pub fn new_polled(mesh: &Mesh, progress: &Progress) -> Result<Topology> {
        Topology::from_faces_polled(&mesh.faces, mesh.positions.len(), progress)
    }

    /// Topology of a face list over `n_vertices` vertices. Indices ≥ `n_vertices` (which
    /// [`Mesh::check`] rejects) do not panic: the vertex count grows to cover them.
    pub fn from_faces(faces: &Faces, n_vertices: usize) -> Topology {
        Topology::from_faces_polled(faces, n_vertices, &Progress::new()).expect(
            "from_faces_polled fails only through progress.check(), and a fresh Progress is never cancelled",
        )
    }

    /// [`Topology::from_faces`], polling `progress` (see [`Topology::new_polled`]).
    pub fn from_faces_polled(faces: &Faces, n_vertices: usize, progress: &Progress) -> Result<Topology> {
        let idx = faces.indices();
        let offsets = faces.offsets();
        let n = idx.iter().map(|&v| v as usize + 1).max().unwrap_or(0).max(n_vertices);
        let nc = idx.len();

        let mut corner_face = vec![0u32; nc];
        for f in 0..faces.len() {
            corner_face[offsets[f] as usize..offsets[f + 1] as usize].fill(f as u32);
        }
        // Half-edge c runs from corner c to the next corner of its face (computed per face, which
        // avoids a corner → face lookup per half-edge).
        let half_edges = || {
            (0..faces.len()).flat_map(move |f| {
                let (s, e) = (offsets[f] as usize, offsets[f + 1] as usize);
                (s..e).map(move |c| (c, idx[c], idx[if c + 1 == e { s } else { c + 1 }]))
            })
        };

        // Bucket the half-edges by their smaller vertex (counting sort), each entry packed as
        // (larger vertex << 32 | corner) so that sorting a bucket orders it by edge, then corner.
        let mut start = vec![0u32; n + 1];
        let mut degenerate = 0usize;
        for (_, a, b) in half_edges() {
            if a == b {
                degenerate += 1;
            } else {
                start[a.min(b) as usize + 1] += 1;
            }
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        progress.check()?;
        let mut fill = start.clone();
        let mut packed = vec![0u64; nc - degenerate];
        for (c, a, b) in half_edges() {
            if a != b {
                let lo = a.min(b) as usize;
                packed[fill[lo] as usize] = ((a.max(b) as u64) << 32) | c as u64;
                fill[lo] += 1;
            }
        }
        drop(fill);
        progress.check()?;

        let mut corner_edge = vec![NONE; nc];
        let mut edges: Vec<[u32; 2]> = Vec::with_capacity(packed.len() / 2 + 1);
        let mut edge_offsets: Vec<u32> = Vec::with_capacity(packed.len() / 2 + 2);
        let mut uses: Vec<EdgeUse> = Vec::with_capacity(packed.len());
        let mut lo_start = vec![0u32; n + 1];
        for lo in 0..n {
            progress.check_every(lo, POLL_ITEMS)?;
            lo_start[lo] = edges.len() as u32;
            let bucket = &mut packed[start[lo] as usize..start[lo + 1] as usize];
            if bucket.len() > 1 {
                bucket.sort_unstable();
            }
            let mut prev_hi = NONE;
            for &p in bucket.iter() {
                let hi = (p >> 32) as u32;
                let c = (p & 0xffff_ffff) as usize;
                if hi != prev_hi {
                    edge_offsets.push(uses.len() as u32);
                    edges.push([lo as u32, hi]);
                    prev_hi = hi;
                }
                let f = corner_face[c];
                uses.push(EdgeUse {
                    face: f,
                    corner: c as u32 - offsets[f as usize],
                    forward: idx[c] as usize == lo,
                });
                corner_edge[c] = edges.len() as u32 - 1;
            }
        }
        lo_start[n] = edges.len() as u32;
        edge_offsets.push(uses.len() as u32);

        progress.check()?;
        // Vertex → corners, by counting sort (rows come out ascending).
        let mut vc_off = vec![0u32; n + 1];
        for &v in idx {
            vc_off[v as usize + 1] += 1;
        }
        for v in 0..n {
            vc_off[v + 1] += vc_off[v];
        }
        let mut fill = vc_off.clone();
        let mut vc = vec![0u32; nc];
        for (c, &v) in idx.iter().enumerate() {
            vc[fill[v as usize] as usize] = c as u32;
            fill[v as usize] += 1;
        }

        Ok(Topology {
            n_vertices: n,
            face_offsets: offsets.to_vec(),
            corner_vertex: idx.to_vec(),
            corner_face,
            corner_edge,
            edges,
            edge_offsets,
            uses,
            lo_start,
            vertex_corners: Csr { offsets: vc_off, items: vc },
            degenerate_half_edges: degenerate,
        })
    }

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

/// Union-find root with path halving.
pub(crate) fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let g = parent[parent[x as usize] as usize];
        parent[x as usize] = g;
        x = g;
    }
    x
}

/// Union-find merge (the smaller root wins, which keeps labels deterministic).
pub(crate) fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        parent[hi as usize] = lo;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Faces;
    use crate::shapes;

    fn topo(n: usize, faces: &[&[u32]]) -> Topology {
        let mut f = Faces::new();
        for face in faces {
            f.push(face, 0);
        }
        Topology::from_faces(&f, n)
    }

    #[test]
    fn single_triangle() {
        let t = topo(3, &[&[0, 1, 2]]);
        assert_eq!(t.edges(), &[[0, 1], [0, 2], [1, 2]]);
        assert_eq!(t.boundary_edges().len(), 3);
        let loops = t.boundary_loops();
        assert_eq!(loops.len(), 1);
        assert!(loops[0].closed);
        assert_eq!(loops[0].vertices, vec![0, 1, 2]);
        assert_eq!(t.vertex_kinds(), vec![VertexKind::Boundary; 3]);
        assert_eq!(t.find_edge(2, 0), Some(1));
        assert_eq!(t.find_edge(0, 0), None);
    }

    #[test]
    fn icosphere_is_closed_manifold_consistent() {
        let m = shapes::icosphere(2, 1.0);
        let t = Topology::new(&m);
        // V − E + F = 2 with E = 3F/2.
        assert_eq!(t.edge_count(), m.face_count() * 3 / 2);
        assert!(t.boundary_edges().is_empty());
        assert!(t.non_manifold_edges().is_empty());
        assert!(t.inconsistent_edges().is_empty());
        assert!(t.vertex_kinds().iter().all(|&k| k == VertexKind::Interior));
        assert_eq!(t.components(Connectivity::SharedEdge).count(), 1);
        // Every vertex of an icosphere has valence 5 or 6.
        let ring = t.vertex_neighbors();
        assert!((0..ring.rows()).all(|v| matches!(ring.row(v).len(), 5 | 6)));
    }

    #[test]
    fn quad_grid_has_one_loop_of_perimeter_length() {
        let m = shapes::grid(4, 3, 1.0, true);
        let t = Topology::new(&m);
        let loops = t.boundary_loops();
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0].vertices.len(), 2 * (4 + 3));
        assert!(loops[0].closed);
        // A loop is a closed walk: consecutive vertices are joined by the listed edge.
        let l = &loops[0];
        for i in 0..l.vertices.len() {
            let (a, b) = (l.vertices[i], l.vertices[(i + 1) % l.vertices.len()]);
            assert_eq!(t.find_edge(a, b), Some(l.edges[i]));
        }
    }

    /// 5×5-vertex grid, each quad split along its (i,j)–(i+1,j+1) diagonal; `skip` removes faces.
    fn grid5(skip: &[[u32; 3]]) -> Vec<[u32; 3]> {
        let mut tris = Vec::new();
        for j in 0..4u32 {
            for i in 0..4u32 {
                let (a, b, c, d) = (j * 5 + i, j * 5 + i + 1, (j + 1) * 5 + i, (j + 1) * 5 + i + 1);
                for t in [[a, b, d], [a, d, c]] {
                    if !skip.contains(&t) {
                        tris.push(t);
                    }
                }
            }
        }
        tris
    }

    /// Seed 003 Fig. 4.6: two holes sharing a vertex. Removing two triangles of a grid that touch
    /// only at the centre vertex 12 leaves two open fans there: a pinch, not a non-manifold vertex,
    /// and each hole is a loop of its own (3 edges each) besides the 16-edge rim.
    #[test]
    fn two_holes_sharing_a_vertex_is_a_pinch() {
        let tris = grid5(&[[6, 7, 12], [12, 13, 18]]);
        assert_eq!(tris.len(), 30);
        let f: Vec<&[u32]> = tris.iter().map(|t| &t[..]).collect();
        let t = topo(25, &f);
        let kinds = t.vertex_kinds();
        assert_eq!(kinds[12], VertexKind::Pinch);
        assert_eq!(t.fans(12), (2, 0, false));
        assert!(!kinds.contains(&VertexKind::NonManifold));
        let mut lens: Vec<usize> = t.boundary_loops().iter().map(|l| l.edges.len()).collect();
        lens.sort();
        assert_eq!(lens, vec![3, 3, 16]);
        let loops = t.boundary_loops();
        assert!(loops.iter().all(|l| l.closed));
        for l in loops.iter().filter(|l| l.edges.len() == 3) {
            let mut v = l.vertices.clone();
            v.sort();
            assert!(v == vec![6, 7, 12] || v == vec![12, 13, 18], "{v:?}");
        }
    }

    /// `vertex_kinds` (global union-find) agrees with the per-vertex `fans` on every case here.
    #[test]
    fn vertex_kinds_agree_with_per_vertex_fans() {
        let cases: Vec<Vec<[u32; 3]>> = vec![
            grid5(&[[6, 7, 12], [12, 13, 18]]),
            grid5(&[[6, 7, 12]]),
            grid5(&[]),
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [0, 5, 6], [0, 6, 7], [0, 7, 5]],
        ];
        for tris in cases {
            let f: Vec<&[u32]> = tris.iter().map(|t| &t[..]).collect();
            let t = topo(25, &f);
            let kinds = t.vertex_kinds();
            for v in 0..25u32 {
                let (fans, closed, nm) = t.fans(v);
                let expect = match (fans, closed, nm) {
                    (0, _, _) => VertexKind::Unreferenced,
                    (_, _, true) => VertexKind::OnNonManifoldEdge,
                    (1, 1, _) => VertexKind::Interior,
                    (1, _, _) => VertexKind::Boundary,
                    (_, 0, _) => VertexKind::Pinch,
                    _ => VertexKind::NonManifold,
                };
                assert_eq!(kinds[v as usize], expect, "vertex {v}");
            }
        }
    }

    #[test]
    fn figure_eight_walk_splits_into_two_cycles() {
        let l = BoundaryLoop {
            vertices: vec![0, 1, 2, 0, 3, 4],
            edges: vec![10, 11, 12, 13, 14, 15],
            closed: true,
        };
        let c = l.simple_cycles();
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].vertices, vec![0, 1, 2]);
        assert_eq!(c[0].edges, vec![10, 11, 12]);
        assert_eq!(c[1].vertices, vec![0, 3, 4]);
        assert_eq!(c[1].edges, vec![13, 14, 15]);
    }

    /// The bow-tie: two triangles sharing only a vertex. Both fans are open: a pinch too.
    #[test]
    fn bowtie_is_a_pinch() {
        let t = topo(5, &[&[0, 1, 2], &[0, 3, 4]]);
        assert_eq!(t.vertex_kinds()[0], VertexKind::Pinch);
        assert_eq!(t.boundary_loops().iter().map(|l| l.edges.len()).sum::<usize>(), 6);
    }

    /// Two tetrahedra glued at one vertex: two closed fans there = a real non-manifold vertex.
    #[test]
    fn two_closed_fans_is_non_manifold() {
        let tet = |o: u32| [[o, o + 2, o + 1], [o, o + 1, o + 3], [o + 1, o + 2, o + 3], [o + 2, o, o + 3]];
        let mut faces: Vec<[u32; 3]> = tet(0).to_vec();
        // Second tetrahedron: vertices 3 (shared), 4, 5, 6.
        for f in tet(3).iter() {
            faces.push(*f);
        }
        let f: Vec<&[u32]> = faces.iter().map(|f| &f[..]).collect();
        // tet(3) uses 3,4,5,6 with 3 as its apex "o".
        let t = topo(7, &f);
        let kinds = t.vertex_kinds();
        assert_eq!(kinds[3], VertexKind::NonManifold);
        assert_eq!(kinds.iter().filter(|&&k| k == VertexKind::NonManifold).count(), 1);
        assert!(t.boundary_edges().is_empty());
        assert_eq!(t.components(Connectivity::SharedVertex).count(), 1);
        assert_eq!(t.components(Connectivity::SharedEdge).count(), 2);
    }

    #[test]
    fn three_faces_on_one_edge() {
        let t = topo(5, &[&[0, 1, 2], &[1, 0, 3], &[0, 1, 4]]);
        let nm = t.non_manifold_edges();
        assert_eq!(nm.len(), 1);
        assert_eq!(t.edge(nm[0]), [0, 1]);
        assert_eq!(t.edge_valence(nm[0]), 3);
        let k = t.vertex_kinds();
        assert_eq!(k[0], VertexKind::OnNonManifoldEdge);
        assert_eq!(k[2], VertexKind::Boundary);
        // No panic walking loops around a non-manifold edge; each boundary edge in one loop.
        let loops = t.boundary_loops();
        assert_eq!(loops.iter().map(|l| l.edges.len()).sum::<usize>(), 6);
    }

    #[test]
    fn flipped_face_gives_inconsistent_edges() {
        let m = shapes::icosphere(1, 1.0);
        let mut faces = Faces::new();
        for (i, f) in m.faces.iter().enumerate() {
            if i == 7 {
                faces.push(&[f[0], f[2], f[1]], 0);
            } else {
                faces.push(f, 0);
            }
        }
        let t = Topology::from_faces(&faces, m.vertex_count());
        assert_eq!(t.inconsistent_edges().len(), 3);
    }

    #[test]
    fn degenerate_and_out_of_range_do_not_panic() {
        let t = topo(2, &[&[0, 0, 1], &[5], &[1, 2]]);
        assert_eq!(t.vertex_count(), 6);
        assert_eq!(t.degenerate_half_edges(), 2);
        let _ = t.boundary_loops();
        let _ = t.vertex_kinds();
        let _ = t.components(Connectivity::SharedVertex);
    }

    #[test]
    fn vertex_faces_dedup_and_neighbors() {
        let t = topo(4, &[&[0, 1, 2], &[0, 2, 3]]);
        let vf = t.vertex_faces();
        assert_eq!(vf.row(0), &[0, 1]);
        assert_eq!(vf.row(1), &[0]);
        let nb = t.vertex_neighbors();
        assert_eq!(nb.row(0), &[1, 2, 3]);
        assert_eq!(nb.row(1), &[0, 2]);
    }
}
