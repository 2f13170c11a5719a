//! The mesh data every job works on.
//!
//! Positions are f64. Faces keep the arity they were given (triangles, quads, n-gons) in one compact
//! offsets + indices store, each face carrying the id of the group it belongs to (OBJ `g`/`o`, glTF
//! primitive), so partitions survive a round trip. Vertex indices are those of the input file, so a
//! user's "template vertex 12" means the same vertex everywhere.
//!
//! Topology (adjacency, boundaries, …) is *not* stored here: it is derived on demand by
//! [`crate::topology`] so that it can never drift from the face list.

use crate::error::{Error, Location, Result};

pub type Point3 = [f64; 3];

/// Faces of any arity, stored as offsets into one index array, with a group id per face.
///
/// Invariants (kept by the only mutating method, [`Faces::push`]): `offsets[0] == 0`,
/// `offsets` is non-decreasing, `offsets.len() == groups.len() + 1`, every face has ≥ 1 index
/// (the reader rejects or reports faces with < 3; repair may produce none).
#[derive(Clone, Debug, PartialEq)]
pub struct Faces {
    offsets: Vec<u32>,
    indices: Vec<u32>,
    groups: Vec<u32>,
}

impl Default for Faces {
    fn default() -> Self {
        Self::new()
    }
}

impl Faces {
    pub fn new() -> Self {
        Faces { offsets: vec![0], indices: Vec::new(), groups: Vec::new() }
    }

    pub fn with_capacity(faces: usize, indices: usize) -> Self {
        let mut offsets = Vec::with_capacity(faces + 1);
        offsets.push(0);
        Faces { offsets, indices: Vec::with_capacity(indices), groups: Vec::with_capacity(faces) }
    }

    /// Triangles from a flat index list (length a multiple of 3), all in group 0.
    pub fn from_triangles(tris: &[[u32; 3]]) -> Self {
        let mut f = Faces::with_capacity(tris.len(), tris.len() * 3);
        for t in tris {
            f.push(t, 0);
        }
        f
    }

    /// Appends one face. Panics only if the total index count passes u32::MAX, which the readers
    /// prevent by their size limits.
    pub fn push(&mut self, face: &[u32], group: u32) {
        self.indices.extend_from_slice(face);
        let end = u32::try_from(self.indices.len()).unwrap_or(u32::MAX);
        self.offsets.push(end);
        self.groups.push(group);
    }

    pub fn len(&self) -> usize {
        self.groups.len()
    }

    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// The vertex indices of face `i`.
    #[inline]
    pub fn get(&self, i: usize) -> &[u32] {
        &self.indices[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    #[inline]
    pub fn arity(&self, i: usize) -> usize {
        (self.offsets[i + 1] - self.offsets[i]) as usize
    }

    #[inline]
    pub fn group(&self, i: usize) -> u32 {
        self.groups[i]
    }

    pub fn groups(&self) -> &[u32] {
        &self.groups
    }

    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// All face indices back to back.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// Mutable access to the indices (for reindexing after a weld); arities cannot change.
    pub fn indices_mut(&mut self) -> &mut [u32] {
        &mut self.indices
    }

    pub fn iter(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.offsets.windows(2).map(move |w| &self.indices[w[0] as usize..w[1] as usize])
    }

    /// True when every face is a triangle (the fast paths of the solvers use this).
    pub fn all_triangles(&self) -> bool {
        self.indices.len() == 3 * self.len()
    }

    /// The flat index list viewed as triangles, when every face is one.
    pub fn as_triangles(&self) -> Option<&[u32]> {
        self.all_triangles().then_some(&self.indices[..])
    }

    /// The corner each face is fan-triangulated from (0 for triangles). Usually the first corner;
    /// but when a diagonal of that fan is already an edge of the mesh (or a diagonal chosen for an
    /// earlier polygon), the fan would put a third face on that edge and make a manifold polygon
    /// mesh non-manifold once triangulated (Suzanne has such a quad). Then the first corner whose
    /// diagonals are all new is the apex; when there is none, corner 0 stays (the input then
    /// has that edge three times whichever way it is cut).
    pub fn fan_apexes(&self) -> Vec<u32> {
        let mut apex = vec![0u32; self.len()];
        if self.all_triangles() {
            return apex;
        }
        let key = |a: u32, b: u32| ((a.min(b) as u64) << 32) | a.max(b) as u64;
        let mut edges: Vec<u64> = Vec::with_capacity(self.indices.len());
        for f in self.iter() {
            for k in 0..f.len() {
                edges.push(key(f[k], f[(k + 1) % f.len()]));
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let mut chosen: std::collections::HashSet<u64> = std::collections::HashSet::new();
        let taken = |e: u64, chosen: &std::collections::HashSet<u64>| {
            edges.binary_search(&e).is_ok() || chosen.contains(&e)
        };
        for (fi, f) in self.iter().enumerate() {
            let n = f.len();
            if n < 4 {
                continue;
            }
            let free = |a: usize| (2..n - 1).all(|j| !taken(key(f[a], f[(a + j) % n]), &chosen));
            let a = (0..n).find(|&a| free(a)).unwrap_or(0);
            apex[fi] = a as u32;
            for j in 2..n - 1 {
                chosen.insert(key(f[a], f[(a + j) % n]));
            }
        }
        apex
    }

    /// Every face as triangles, fanned from its [`Faces::fan_apexes`] corner, in face order;
    /// faces with fewer than 3 corners give none.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let apex = self.fan_apexes();
        let mut tris = Vec::with_capacity(self.indices.len().saturating_sub(2 * self.len()));
        for (f, &a) in self.iter().zip(&apex) {
            fan_of(f, a as usize, |t| tris.push(t));
        }
        tris
    }

    /// Keeps the faces for which `keep(face_index)` is true, in order.
    pub fn retain(&mut self, mut keep: impl FnMut(usize) -> bool) {
        let mut out = Faces::with_capacity(self.len(), self.indices.len());
        for i in 0..self.len() {
            if keep(i) {
                out.push(self.get(i), self.groups[i]);
            }
        }
        *self = out;
    }
}

/// Calls `emit` with the fan triangles of polygon `f` from corner `apex` (none below 3 corners).
#[inline]
pub fn fan_of(f: &[u32], apex: usize, mut emit: impl FnMut([u32; 3])) {
    let n = f.len();
    for j in 1..n.saturating_sub(1) {
        emit([f[apex], f[(apex + j) % n], f[(apex + j + 1) % n]]);
    }
}

/// The largest coordinate magnitude a job accepts (`convert` excepted). Jobs square lengths (areas, distances in the
/// spatial index, normal equations); past ~1e154 a square overflows to infinity and a valid mesh
/// would come out as degenerate faces or empty. 1e150 leaves room for sums of squares.
pub const MAX_COORDINATE: f64 = 1e150;

/// The smallest extent (longest side of the bounding box) a job accepts when it is not 0
/// (`convert` excepted). Areas are squared in their norms, so they go as the fourth power of the
/// edge lengths: below ~1e-77 they underflow to 0 and a valid mesh comes out as degenerate faces
/// (`repair` emptied a model at 1e-100) or smooths to garbage. 1e-50 leaves room for edges a
/// million times shorter than the mesh.
pub const MIN_EXTENT: f64 = 1e-50;

/// A polygon mesh with optional per-vertex attributes, named face groups and polylines.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Point3>,
    pub faces: Faces,
    /// Per-vertex normals, same length as `positions` when present.
    pub normals: Option<Vec<Point3>>,
    /// Per-vertex texture coordinates, same length as `positions` when present.
    pub uvs: Option<Vec<[f64; 2]>>,
    /// Group names; a face's group id indexes this list. Empty means one unnamed group 0.
    pub groups: Vec<String>,
    /// Polylines (OBJ `l`, glTF LINES/LINE_STRIP) as vertex index lists into `positions`.
    pub curves: Vec<Vec<u32>>,
}

impl Mesh {
    pub fn new(positions: Vec<Point3>, faces: Faces) -> Self {
        Mesh { positions, faces, ..Default::default() }
    }

    /// A triangle mesh in one unnamed group.
    pub fn from_triangles(positions: Vec<Point3>, tris: &[[u32; 3]]) -> Self {
        Mesh::new(positions, Faces::from_triangles(tris))
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// Name of a group id ("" when the mesh has no names).
    pub fn group_name(&self, id: u32) -> &str {
        self.groups.get(id as usize).map(String::as_str).unwrap_or("")
    }

    /// The longest side of the bounding box (0 for no or one distinct position), and the vertex
    /// holding its maximum.
    pub fn longest_side(&self) -> (f64, usize) {
        let mut side = (0.0f64, 0usize);
        for k in 0..3 {
            let (mut lo, mut hi) = (f64::INFINITY, (f64::NEG_INFINITY, 0usize));
            for (i, p) in self.positions.iter().enumerate() {
                lo = lo.min(p[k]);
                if p[k] > hi.0 {
                    hi = (p[k], i);
                }
            }
            if hi.0 - lo > side.0 {
                side = (hi.0 - lo, hi.1);
            }
        }
        side
    }

    /// Refuses coordinates beyond ±[`MAX_COORDINATE`] (finite, but their squares overflow), naming
    /// the first vertex, and a mesh whose extent is not 0 but below [`MIN_EXTENT`] (its areas
    /// underflow), naming the vertex at the far end of its longest side. A policy on job inputs,
    /// not a structural invariant: `job::run` calls it for every job but `convert`; readers and
    /// [`Mesh::check`] do not.
    pub fn check_coordinate_range(&self) -> Result<()> {
        if let Some(i) = self.positions.iter().position(|p| p.iter().any(|c| c.abs() > MAX_COORDINATE)) {
            let c = self.positions[i].iter().fold(0.0f64, |m, c| m.max(c.abs()));
            return Err(Error::InvalidMesh {
                location: Location::Vertex(i),
                message: format!(
                    "coordinate {c:e} is beyond ±{MAX_COORDINATE:e}: squared lengths and areas would \
                     overflow; rescale the mesh"
                ),
            });
        }
        let side = self.longest_side();
        if side.0 > 0.0 && side.0 < MIN_EXTENT {
            return Err(Error::InvalidMesh {
                location: Location::Vertex(side.1),
                message: format!(
                    "the mesh spans only {:e} (the longest side of its bounding box, up to this vertex), \
                     below {MIN_EXTENT:e}: areas and squared distances would underflow to 0 (faces \
                     would count as degenerate); rescale the mesh",
                    side.0
                ),
            });
        }
        Ok(())
    }

    /// Checks the structural invariants a reader must establish: indices in range, attribute
    /// lengths, finite coordinates, group ids named. Readers call this before handing a mesh out,
    /// so jobs may index without bounds worries.
    pub fn check(&self) -> Result<()> {
        let n = self.positions.len();
        if let Some(i) = self.positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(Error::InvalidMesh {
                location: Location::Vertex(i),
                message: "coordinate is NaN or infinite".into(),
            });
        }
        for (fi, f) in self.faces.iter().enumerate() {
            if let Some(&bad) = f.iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidMesh {
                    location: Location::Face(fi),
                    message: format!("vertex index {bad} out of range (mesh has {n} vertices)"),
                });
            }
        }
        for (ci, c) in self.curves.iter().enumerate() {
            if let Some(&bad) = c.iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidMesh {
                    location: Location::Vertex(bad as usize),
                    message: format!("curve {ci} refers to vertex {bad}, mesh has {n} vertices"),
                });
            }
        }
        if let Some(nr) = &self.normals {
            if nr.len() != n {
                return Err(Error::Internal(format!("{} normals for {n} vertices", nr.len())));
            }
        }
        if let Some(uv) = &self.uvs {
            if uv.len() != n {
                return Err(Error::Internal(format!("{} uvs for {n} vertices", uv.len())));
            }
        }
        if !self.groups.is_empty() {
            if let Some(fi) = self.faces.groups().iter().position(|&g| g as usize >= self.groups.len()) {
                return Err(Error::Internal(format!("face {fi} has an unnamed group id")));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_keep_arity_and_groups() {
        let mut f = Faces::new();
        f.push(&[0, 1, 2], 0);
        f.push(&[0, 2, 3, 4], 1);
        assert_eq!(f.len(), 2);
        assert_eq!(f.get(1), &[0, 2, 3, 4]);
        assert_eq!(f.arity(0), 3);
        assert_eq!(f.group(1), 1);
        assert!(!f.all_triangles());
        f.retain(|i| i == 1);
        assert_eq!(f.len(), 1);
        assert_eq!(f.get(0), &[0, 2, 3, 4]);
    }

    /// Uses per undirected edge, counted by hand from the triangle list.
    fn max_edge_uses(tris: &[[u32; 3]]) -> usize {
        let mut uses = std::collections::HashMap::new();
        for t in tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
            }
        }
        uses.into_values().max().unwrap_or(0)
    }

    #[test]
    fn quads_fan_from_the_first_corner_when_nothing_is_in_the_way() {
        let mut f = Faces::new();
        f.push(&[0, 1, 2, 3], 0);
        f.push(&[1, 4, 5, 2], 0);
        assert_eq!(f.triangles(), vec![[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]]);
        assert_eq!(f.fan_apexes(), vec![0, 0]);
    }

    #[test]
    fn a_diagonal_that_is_already_an_edge_is_not_used() {
        // Quad 0-1-2-3 whose diagonal 0–2 is also the edge shared by two triangles on the other
        // side (the Suzanne case): the fan from 0 would put four faces on 0–2.
        let mut f = Faces::new();
        f.push(&[0, 1, 2, 3], 0);
        f.push(&[0, 4, 2], 0);
        f.push(&[2, 5, 0], 0);
        assert_eq!(f.fan_apexes(), vec![1, 0, 0]);
        let tris = f.triangles();
        assert_eq!(&tris[..2], &[[1, 2, 3], [1, 3, 0]]);
        assert_eq!(max_edge_uses(&tris), 2);

        // A pentagon with existing edges 0–2 and 1–4: the fans from 0 (0–2), 1 (1–4) and 2 (2–0)
        // each hit one; the fan from 3 (3–0, 3–1) is the first free one.
        let mut p = Faces::new();
        p.push(&[0, 1, 2, 3, 4], 0);
        p.push(&[0, 2, 9], 0);
        p.push(&[1, 4, 9], 0);
        assert_eq!(p.fan_apexes()[0], 3);
        assert_eq!(p.triangles().len(), 3 + 2);
    }

    #[test]
    fn two_polygons_do_not_pick_the_same_new_diagonal() {
        // Quads 0-1-2-3 and 2-5-0-6 both have the diagonal 0–2; the second must take the other.
        let mut f = Faces::new();
        f.push(&[0, 1, 2, 3], 0);
        f.push(&[2, 5, 0, 6], 0);
        let tris = f.triangles();
        assert_eq!(f.fan_apexes(), vec![0, 1]);
        assert_eq!(max_edge_uses(&tris), 2);
    }

    #[test]
    fn check_rejects_out_of_range_and_nan() {
        let mut m = Mesh::from_triangles(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 3]]);
        assert!(matches!(m.check(), Err(Error::InvalidMesh { location: Location::Face(0), .. })));
        m.faces = Faces::from_triangles(&[[0, 1, 2]]);
        m.positions[1][2] = f64::NAN;
        assert!(matches!(m.check(), Err(Error::InvalidMesh { location: Location::Vertex(1), .. })));
    }
}
