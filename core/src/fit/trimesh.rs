//! A small editable triangle mesh with directed-edge → face lookup and vertex → face lists: what
//! the flip subdivision, the segment walk and the re-triangulation need (faces are removed and
//! added one at a time). Requires an oriented edge-manifold input, which it checks.

use crate::error::{Error, Result};
use crate::geometry::{add, normalize, sub, triangle_cross};
use crate::mesh::Point3;

pub use crate::hash::{IntHasher, IntMap};

/// Undirected edges (smaller index first) that must stay: curve edges, locked edges.
pub type EdgeSet = crate::hash::IntSet<(u32, u32)>;

/// The check [`TriMesh::new`] makes, without building the mesh: no face repeats a vertex and no
/// directed edge is used twice (a sort, not a hash map: this runs on every template).
pub fn check_oriented_manifold(tris: &[[u32; 3]]) -> Result<()> {
    check_oriented_manifold_faces(tris, None)
}

/// [`check_oriented_manifold`] naming the input face of each triangle (`face_of[t]`, for a
/// template of quads and n-gons triangulated by fans) instead of the triangle.
pub fn check_oriented_manifold_faces(tris: &[[u32; 3]], face_of: Option<&[usize]>) -> Result<()> {
    let name = |t: u32| face_of.and_then(|f| f.get(t as usize).copied()).unwrap_or(t as usize);
    let mut keys: Vec<(u64, u32)> = Vec::with_capacity(tris.len() * 3);
    for (fi, t) in tris.iter().enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(Error::Topology(format!("template face {} repeats a vertex {t:?}", name(fi as u32))));
        }
        for k in 0..3 {
            keys.push((((t[k] as u64) << 32) | t[(k + 1) % 3] as u64, fi as u32));
        }
    }
    keys.sort_unstable();
    for w in keys.windows(2) {
        if w[0].0 == w[1].0 {
            let (a, b) = ((w[0].0 >> 32) as u32, w[0].0 as u32);
            return Err(Error::Topology(format!(
                "template edge ({a}, {b}) is used in the same direction by faces {} and {}: \
                 the template is not an oriented manifold (run the repair job first)",
                name(w[0].1),
                name(w[1].1)
            )));
        }
    }
    Ok(())
}

/// Vertices on a boundary edge (a directed edge whose reverse no face uses), of `nv` vertices.
/// Each directed edge a → b looks for a face with b → a among the faces at one of its ends (a
/// vertex → faces table, ~6 faces a row), the faces in parallel: on the headline's 194k faces a
/// sort of the 580k directed edges took ~35 ms of serial CPU (it runs twice per fit), a hash set
/// ~60 ms (session 16).
pub fn boundary_vertices(nv: usize, tris: &[[u32; 3]]) -> Vec<bool> {
    use rayon::prelude::*;
    let vf = crate::topology::Csr::vertex_triangles(nv, tris);
    // A face with b → a has both ends, so it is in the row of either (a vertex past nv has none).
    let has_reverse = |a: u32, b: u32| {
        let end = if (a as usize) < nv { a } else { b } as usize;
        end < nv
            && vf.row(end).iter().any(|&g| {
                let u = tris[g as usize];
                (0..3).any(|j| u[j] == b && u[(j + 1) % 3] == a)
            })
    };
    // Per face, its edges on the boundary (an edge from a vertex to itself has no other side).
    let one_sided: Vec<[bool; 3]> = tris
        .par_iter()
        .with_min_len(4096)
        .map(|t| {
            std::array::from_fn(|k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                a == b || !has_reverse(a, b)
            })
        })
        .collect();
    let mut on_rim = vec![false; nv];
    for (t, sides) in tris.iter().zip(&one_sided) {
        for k in (0..3).filter(|&k| sides[k]) {
            for v in [t[k], t[(k + 1) % 3]] {
                if let Some(r) = on_rim.get_mut(v as usize) {
                    *r = true;
                }
            }
        }
    }
    on_rim
}

#[derive(Clone)]
pub struct TriMesh {
    pub pos: Vec<Point3>,
    pub tris: Vec<[u32; 3]>,
    pub alive: Vec<bool>,
    /// Live faces at each vertex. The face with a directed edge a → b is found in `vfaces[a]`
    /// (~6 faces): no directed-edge hash map, whose 600k entries on the headline cost more to
    /// build, clone and update than these short scans (docs/benchmarks.md, session 11).
    vfaces: Vec<Vec<u32>>,
    /// Live faces (what `alive` counts), and the most the fit lets its stages make
    /// ([`TriMesh::check_growth`]).
    live: usize,
    peak: usize,
    face_limit: usize,
}

impl TriMesh {
    /// Builds the adjacency; fails naming the face when an edge is used twice in one direction
    /// (non-manifold or inconsistently oriented input).
    pub fn new(pos: Vec<Point3>, tris: Vec<[u32; 3]>) -> Result<Self> {
        // Each vertex's list sized for its faces and a few edits (one allocation each).
        let mut valence = vec![0u32; pos.len()];
        for &v in tris.iter().flatten() {
            if let Some(c) = valence.get_mut(v as usize) {
                *c += 1;
            }
        }
        let mut m = TriMesh {
            vfaces: valence.iter().map(|&c| Vec::with_capacity(c as usize + 2)).collect(),
            pos,
            alive: vec![true; tris.len()],
            tris: Vec::with_capacity(tris.len()),
            live: tris.len(),
            peak: tris.len(),
            face_limit: usize::MAX,
        };
        for (fi, t) in tris.iter().enumerate() {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return Err(Error::Topology(format!("template face {fi} repeats a vertex {t:?}")));
            }
            for k in 0..3 {
                if let Some(other) = m.face_with_edge(t[k], t[(k + 1) % 3]) {
                    return Err(Error::Topology(format!(
                        "template edge ({}, {}) is used in the same direction by faces {other} and {fi}: \
                         the template is not an oriented manifold (run the repair job first)",
                        t[k],
                        t[(k + 1) % 3]
                    )));
                }
            }
            let fi = m.tris.len() as u32;
            for &v in t {
                m.vfaces[v as usize].push(fi);
            }
            m.tris.push(*t);
        }
        Ok(m)
    }

    pub fn add_vertex(&mut self, p: Point3) -> u32 {
        self.pos.push(p);
        self.vfaces.push(Vec::new());
        (self.pos.len() - 1) as u32
    }

    /// Removes the last vertex when no face uses it (a vertex added to judge an edit that was not
    /// made); false otherwise.
    pub fn pop_vertex(&mut self) -> bool {
        if !self.vfaces.last().is_some_and(|f| f.is_empty()) {
            return false;
        }
        self.vfaces.pop();
        self.pos.pop();
        true
    }

    /// Adds a face; Err(()) if one of its directed edges is already taken.
    pub fn add_face(&mut self, t: [u32; 3]) -> std::result::Result<u32, ()> {
        for k in 0..3 {
            if self.face_with_edge(t[k], t[(k + 1) % 3]).is_some() {
                return Err(());
            }
        }
        let fi = self.tris.len() as u32;
        for &v in &t {
            self.vfaces[v as usize].push(fi);
        }
        self.tris.push(t);
        self.alive.push(true);
        self.live += 1;
        self.peak = self.peak.max(self.live);
        Ok(fi)
    }

    pub fn remove_face(&mut self, f: u32) {
        if !self.alive[f as usize] {
            return;
        }
        let t = self.tris[f as usize];
        self.alive[f as usize] = false;
        self.live -= 1;
        for v in t {
            let list = &mut self.vfaces[v as usize];
            if let Some(i) = list.iter().position(|&g| g == f) {
                list.swap_remove(i);
            }
        }
    }

    /// Splits edge (a, b) at `x` and the one or two faces on it (each into two with the same
    /// orientation); the new vertex's id, or None when no face has the edge.
    pub fn split_edge(&mut self, a: u32, b: u32, x: Point3) -> Option<u32> {
        let faces: Vec<u32> =
            [self.face_with_edge(a, b), self.face_with_edge(b, a)].into_iter().flatten().collect();
        if faces.is_empty() {
            return None;
        }
        let m = self.add_vertex(x);
        for f in faces {
            let t = self.tris[f as usize];
            let k =
                (0..3).find(|&k| (t[k] == a && t[(k + 1) % 3] == b) || (t[k] == b && t[(k + 1) % 3] == a))?;
            let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            self.remove_face(f);
            // The removed face freed its directed edges; p→m, m→q and the edges at m are new.
            self.add_face([p, m, r]).ok()?;
            self.add_face([m, q, r]).ok()?;
        }
        Some(m)
    }

    pub fn faces_of(&self, v: u32) -> &[u32] {
        &self.vfaces[v as usize]
    }

    pub fn has_edge(&self, a: u32, b: u32) -> bool {
        self.face_with_edge(a, b).is_some() || self.face_with_edge(b, a).is_some()
    }

    /// The face that has the directed edge a → b (at most one: [`TriMesh::add_face`] refuses a
    /// second).
    pub fn face_with_edge(&self, a: u32, b: u32) -> Option<u32> {
        let faces = self.vfaces.get(a as usize)?;
        faces.iter().copied().find(|&f| {
            let t = self.tris[f as usize];
            (t[0] == a && t[1] == b) || (t[1] == a && t[2] == b) || (t[2] == a && t[0] == b)
        })
    }

    /// The face on the other side of edge (a, b) from face `f`.
    pub fn across(&self, f: u32, a: u32, b: u32) -> Option<u32> {
        [self.face_with_edge(a, b), self.face_with_edge(b, a)].into_iter().flatten().find(|&g| g != f)
    }

    /// True when some edge at `v` has a face on one side only.
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.vfaces[v as usize].iter().any(|&f| {
            let t = self.tris[f as usize];
            (0..3).any(|k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                (a == v || b == v) && self.face_with_edge(b, a).is_none()
            })
        })
    }

    pub fn face_normal(&self, f: u32) -> Point3 {
        let t = self.tris[f as usize];
        triangle_cross(self.pos[t[0] as usize], self.pos[t[1] as usize], self.pos[t[2] as usize])
    }

    /// Area-weighted unit vertex normal.
    pub fn vertex_normal(&self, v: u32) -> Point3 {
        let mut n = [0.0; 3];
        for &f in &self.vfaces[v as usize] {
            n = add(n, self.face_normal(f));
        }
        normalize(n)
    }

    /// Number of live faces.
    pub fn live_faces(&self) -> usize {
        self.live
    }

    /// The most live faces the mesh had at once.
    pub fn peak_faces(&self) -> usize {
        self.peak
    }

    /// The face count above which [`TriMesh::check_growth`] fails (the fit's `max_face_growth`).
    pub fn set_face_limit(&mut self, limit: usize) {
        self.face_limit = limit;
    }

    /// Fails when the mesh has grown past its face limit, naming the stage: a stage that keeps
    /// splitting (curves the template cannot follow, e.g. a round template on a thin target:
    /// 1,280 → 600k faces and minutes of work before the guard) stops at its next poll instead.
    pub fn check_growth(&self, stage: &str) -> Result<()> {
        if self.live <= self.face_limit {
            return Ok(());
        }
        Err(Error::TooLarge {
            what: format!(
                "faces of the fitted mesh in stage `{stage}` (limit: max_face_growth × (template \
                 triangles + 8 × curve vertices)): the template cannot follow the curves there (a \
                 template far from the curves' shape, e.g. round against a thin target?); give pairs, \
                 a template closer to the target, or raise max_face_growth"
            ),
            limit: self.face_limit as u64,
            actual: self.live as u64,
        })
    }

    pub fn alive_faces(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.tris.len() as u32).filter(move |&f| self.alive[f as usize])
    }

    /// The live triangles in order (what the output mesh gets).
    pub fn live_triangles(&self) -> Vec<[u32; 3]> {
        self.alive_faces().map(|f| self.tris[f as usize]).collect()
    }

    /// Edge length helper.
    pub fn len(&self, a: u32, b: u32) -> f64 {
        crate::geometry::norm(sub(self.pos[a as usize], self.pos[b as usize]))
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_vertices_are_those_on_one_sided_edges() {
        // A closed tetrahedron: no boundary. Without its face [1, 2, 3]: vertices 1, 2, 3 are on
        // the rim, apex 0 is not; vertex 4 is in no face.
        let tet = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        assert_eq!(boundary_vertices(4, &tet), vec![false; 4]);
        assert_eq!(boundary_vertices(5, &tet[..3]), vec![false, true, true, true, false]);
        // The same answer as the editable mesh's per-vertex test.
        let pos = vec![[0.0; 3]; 5];
        let mesh = TriMesh::new(pos, tet[..3].to_vec()).unwrap();
        let each: Vec<bool> = (0..5).map(|v| mesh.is_boundary_vertex(v)).collect();
        assert_eq!(boundary_vertices(5, &tet[..3]), each);
    }

    /// The cases off a clean surface, each with its hand answer: an edge used twice in one
    /// direction and once in the other is interior (both directions are used); an edge used twice
    /// in one direction only is on the boundary; a face repeating a vertex has an edge from that
    /// vertex to itself, a boundary edge; a corner past `nv` is skipped, its edges still count.
    #[test]
    fn boundary_vertices_off_a_clean_surface() {
        // Edge 0–1: 0 → 1 in faces 0 and 2, 1 → 0 in face 1; so only the other edges of the
        // three faces (0–2, 2–1, 1–3, 3–0, 1–4, 4–0) are one-sided, and all of 0..4 are on them.
        let fin = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        assert_eq!(boundary_vertices(6, &fin), vec![true, true, true, true, true, false]);
        // A closed tetrahedron plus a copy of one face: that face's edges are used twice in its
        // direction and once in the other: interior, no boundary anywhere.
        let tet = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [1, 2, 3]];
        assert_eq!(boundary_vertices(4, &tet), vec![false; 4]);
        // Two faces on 0 → 1 only (no reverse): 0 and 1 on the boundary, and the other edges.
        assert_eq!(boundary_vertices(4, &[[0, 1, 2], [0, 1, 3]]), vec![true; 4]);
        // A closed tetrahedron whose face [1, 2, 3] became [1, 1, 3] (vertex 2 repeated away):
        // the self-edge 1 → 1 is one-sided; 1 → 3 / 3 → 1 (faces 1 and 3), 0–1, 0–2, 0–3 keep
        // both directions; 2 → 1 and 3 → 2 lost their reverses. So 1, 2, 3 on the rim, not 0.
        let pinched = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 1, 3]];
        assert_eq!(boundary_vertices(4, &pinched), vec![false, true, true, true]);
        // A face with a corner past nv = 3: its edges are one-sided, 0 and 1 marked, 7 skipped.
        assert_eq!(boundary_vertices(3, &[[0, 1, 7]]), vec![true, true, false]);
    }

    #[test]
    fn a_split_interior_edge_makes_four_faces_around_the_new_vertex() {
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        let mut mesh = TriMesh::new(pos, vec![[0, 1, 2], [1, 3, 2]]).unwrap();
        let m = mesh.split_edge(1, 2, [0.5, 0.5, 0.0]).unwrap();
        assert_eq!(m, 4);
        assert_eq!(mesh.faces_of(m).len(), 4);
        assert_eq!(mesh.alive_faces().count(), 4);
        assert!(!mesh.has_edge(1, 2));
        // Same orientation: every live face is counter-clockwise in the plane.
        for f in mesh.alive_faces() {
            let t = mesh.tris[f as usize];
            let c = crate::geometry::triangle_cross(
                mesh.pos[t[0] as usize],
                mesh.pos[t[1] as usize],
                mesh.pos[t[2] as usize],
            );
            assert!(c[2] > 0.0, "{t:?}");
        }
    }
}
