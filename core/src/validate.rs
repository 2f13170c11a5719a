//! The validation report (seed 003 §4.2): counts of everything that can be wrong with a mesh, so a
//! user can decide whether to repair it and a job can refuse input it cannot handle.
//!
//! Definitions (all computed on the faces as given, without welding):
//! - *edges* are unordered vertex pairs; a face repeating an index has a degenerate side that is
//!   not an edge ([`crate::topology`]).
//! - `components`: faces connected through shared edges; `components_by_vertex`: through shared
//!   vertices (a bow-tie is 2 of the first kind, 1 of the second).
//! - `non_manifold_vertices`: vertices with several fans of which one is closed, not on a
//!   non-manifold edge (those are counted by `non_manifold_edges`). Vertices where holes touch
//!   (several fans, all open) are `pinch_vertices`, not non-manifold (seed 003 Fig. 4.6).
//! - `degenerate_faces`: fewer than 3 distinct vertices, or (vector) area ≤ 1e-12 · diagonal²
//!   of the bounding box.
//! - `duplicate_faces`: faces with the same vertex *set* as an earlier face (winding ignored); the
//!   first of each set is not counted.
//! - `euler_characteristic` = V − E + F over referenced vertices, edges and all faces.
//! - `genus` = (2·components − χ) / 2, summed over components, given only when the mesh is
//!   closed, manifold (no non-manifold edge or vertex, no pinch) and the division is exact.

use serde::Serialize;

use crate::error::Result;
use crate::geometry::{self, Aabb};
use crate::hash::IntSet;
use crate::job::{Output, Progress, Stages};
use crate::mesh::{Mesh, Point3};
use crate::topology::{Connectivity, Topology, VertexKind};

/// Parameters of the `validate` job.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ValidateParams {
    /// How many examples (face ids, vertex ids, vertex pairs) to list for each kind of problem.
    pub max_examples: usize,
}

impl Default for ValidateParams {
    fn default() -> Self {
        ValidateParams { max_examples: 10 }
    }
}

/// Relative area below which a face counts as zero-area: area ≤ `ZERO_AREA_REL` · diagonal².
pub const ZERO_AREA_REL: f64 = 1e-12;

/// The report of [`analyze`] (and of the `validate` job, plus timings).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Report {
    pub vertices: usize,
    pub faces: usize,
    pub edges: usize,
    /// Face count by number of corners, e.g. `{"3": 468, "4": 32}`.
    pub face_arity: std::collections::BTreeMap<String, usize>,
    pub components: usize,
    pub components_by_vertex: usize,
    pub boundary_edges: usize,
    /// Closed boundary loops (holes and rims), each a simple cycle.
    pub boundary_loops: usize,
    /// Edge counts of the boundary loops, longest first.
    pub boundary_loop_lengths: Vec<usize>,
    /// Boundary walks that could not be closed (they end at non-manifold edges).
    pub boundary_chains: usize,
    pub non_manifold_edges: usize,
    pub non_manifold_vertices: usize,
    pub pinch_vertices: usize,
    pub degenerate_faces: usize,
    pub duplicate_faces: usize,
    pub unreferenced_vertices: usize,
    /// Manifold edges whose two faces traverse them in the same direction.
    pub inconsistent_orientation: usize,
    /// Face indices ≥ vertex count (a well-read mesh has none; such faces are ignored by geometry).
    pub out_of_range_indices: usize,
    pub non_finite_coordinates: usize,
    pub euler_characteristic: i64,
    pub genus: Option<i64>,
    /// No boundary edges (and at least one face).
    pub closed: bool,
    /// No non-manifold edges or vertices (pinches allowed).
    pub manifold: bool,
    /// Every manifold edge consistently oriented.
    pub consistently_oriented: bool,
    pub bbox: Option<Aabb>,
    pub bbox_diagonal: f64,
    pub area: f64,
    /// Signed volume, given when closed, manifold and consistently oriented (positive = outward).
    pub volume: Option<f64>,
    pub examples: Examples,
}

/// A few instances of each problem, to find them in a viewer.
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct Examples {
    pub non_manifold_edges: Vec<[u32; 2]>,
    pub non_manifold_vertices: Vec<u32>,
    pub pinch_vertices: Vec<u32>,
    pub degenerate_faces: Vec<usize>,
    pub duplicate_faces: Vec<usize>,
    pub inconsistent_edges: Vec<[u32; 2]>,
    pub unreferenced_vertices: Vec<u32>,
}

/// The `validate` job: the report as JSON with `stages` timings and `total_ms`.
pub fn run(mesh: &Mesh, params: &ValidateParams, progress: &Progress) -> Result<Output> {
    let mut stages = Stages::new();
    let report = analyze_staged(mesh, params.max_examples, &mut stages, progress)?;
    let mut json = serde_json::to_value(&report).map_err(|e| crate::Error::Internal(e.to_string()))?;
    json["stages"] = stages.to_json();
    json["total_ms"] = serde_json::json!(stages.total_ms());
    Ok(Output { report: json, ..Default::default() })
}

/// The report without timings (for tests and benchmarks; jobs use [`analyze_polled`]).
pub fn analyze(mesh: &Mesh) -> Report {
    analyze_polled(mesh, &Progress::new())
        .expect("analyze_polled fails only through progress.check(), and a fresh Progress is never cancelled")
}

/// The report without timings, polling `progress` between its passes but leaving its stage
/// alone (repair analyses its input and output inside its own stages).
pub fn analyze_polled(mesh: &Mesh, progress: &Progress) -> Result<Report> {
    analyze_with(mesh, 10, &mut Timing::Quiet, progress)
}

/// The report, timing each stage into `stages` (and announcing it on `progress`).
pub fn analyze_staged(
    mesh: &Mesh,
    max_examples: usize,
    stages: &mut Stages,
    progress: &Progress,
) -> Result<Report> {
    analyze_with(mesh, max_examples, &mut Timing::Stages(stages), progress)
}

/// Whether the passes of [`analyze_with`] are job stages of their own.
enum Timing<'a> {
    Stages(&'a mut Stages),
    /// Part of a caller's stage: only poll for cancellation between passes.
    Quiet,
}

impl Timing<'_> {
    fn run<T>(&mut self, progress: &Progress, name: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        match self {
            Timing::Stages(s) => s.run(progress, name, f),
            Timing::Quiet => {
                progress.check()?;
                f()
            }
        }
    }
}

fn analyze_with(
    mesh: &Mesh,
    max_examples: usize,
    stages: &mut Timing,
    progress: &Progress,
) -> Result<Report> {
    let n = mesh.positions.len();
    let faces = &mesh.faces;
    let mut ex = Examples::default();

    let (bbox, non_finite) = stages.run(progress, "geometry", || {
        let finite: Vec<Point3> =
            mesh.positions.iter().copied().filter(|p| p.iter().all(|c| c.is_finite())).collect();
        Ok((Aabb::of(&finite), n - finite.len()))
    })?;
    let diag = bbox.map(|b| b.diagonal()).unwrap_or(0.0);

    let topo = stages.run(progress, "topology", || Topology::new_polled(mesh, progress))?;

    let FaceScan { arity: face_arity, out_of_range, degenerate, area, duplicates } =
        stages.run(progress, "faces", || scan_faces(mesh, diag, progress))?;
    ex.degenerate_faces = degenerate.iter().take(max_examples).copied().collect();
    ex.duplicate_faces = duplicates.iter().take(max_examples).copied().collect();

    let kinds = stages.run(progress, "vertices", || topo.vertex_kinds_polled(progress))?;
    let count = |k: VertexKind| kinds.iter().filter(|&&x| x == k).count();
    let list = |k: VertexKind| -> Vec<u32> {
        (0..kinds.len() as u32).filter(|&v| kinds[v as usize] == k).take(max_examples).collect()
    };
    let unreferenced = count(VertexKind::Unreferenced);
    let nm_vertices = count(VertexKind::NonManifold);
    let pinches = count(VertexKind::Pinch);
    ex.non_manifold_vertices = list(VertexKind::NonManifold);
    ex.pinch_vertices = list(VertexKind::Pinch);
    ex.unreferenced_vertices = list(VertexKind::Unreferenced);

    let (nm_edges, boundary_edges, inconsistent) = stages.run(progress, "edges", || {
        Ok((topo.non_manifold_edges(), topo.boundary_edges().len(), topo.inconsistent_edges()))
    })?;
    ex.non_manifold_edges = nm_edges.iter().take(max_examples).map(|&e| topo.edge(e)).collect();
    ex.inconsistent_edges = inconsistent.iter().take(max_examples).map(|&e| topo.edge(e)).collect();

    let (components, components_by_vertex) = stages.run(progress, "components", || {
        Ok((
            topo.components(Connectivity::SharedEdge).count(),
            topo.components(Connectivity::SharedVertex).count(),
        ))
    })?;

    let (mut loop_lengths, chains) = stages.run(progress, "boundary_loops", || {
        let loops = topo.boundary_loops();
        let chains = loops.iter().filter(|l| !l.closed).count();
        Ok((loops.iter().filter(|l| l.closed).map(|l| l.edges.len()).collect::<Vec<_>>(), chains))
    })?;
    loop_lengths.sort_unstable_by(|a, b| b.cmp(a));

    let referenced = n.max(topo.vertex_count()) - unreferenced;
    let chi = referenced as i64 - topo.edge_count() as i64 + faces.len() as i64;
    let closed = boundary_edges == 0 && !faces.is_empty();
    let manifold = nm_edges.is_empty() && nm_vertices == 0;
    let oriented = inconsistent.is_empty();
    let genus = (closed && manifold && pinches == 0 && (2 * components as i64 - chi) % 2 == 0)
        .then(|| (2 * components as i64 - chi) / 2);
    let volume = (closed && manifold && oriented && out_of_range == 0)
        .then(|| geometry::signed_volume(&mesh.positions, faces));

    Ok(Report {
        vertices: n,
        faces: faces.len(),
        edges: topo.edge_count(),
        face_arity,
        components,
        components_by_vertex,
        boundary_edges,
        boundary_loops: loop_lengths.len(),
        boundary_loop_lengths: loop_lengths,
        boundary_chains: chains,
        non_manifold_edges: nm_edges.len(),
        non_manifold_vertices: nm_vertices,
        pinch_vertices: pinches,
        degenerate_faces: degenerate.len(),
        duplicate_faces: duplicates.len(),
        unreferenced_vertices: unreferenced,
        inconsistent_orientation: inconsistent.len(),
        out_of_range_indices: out_of_range,
        non_finite_coordinates: non_finite,
        euler_characteristic: chi,
        genus,
        closed,
        manifold,
        consistently_oriented: oriented,
        bbox,
        bbox_diagonal: diag,
        area,
        volume,
        examples: ex,
    })
}

/// What one pass over the faces finds.
struct FaceScan {
    /// Face count per arity ("3", "4", …).
    arity: std::collections::BTreeMap<String, usize>,
    /// Faces with an index past the vertex list (skipped by everything else here).
    out_of_range: usize,
    /// Faces with fewer than three distinct corners or (near) zero area.
    degenerate: Vec<usize>,
    area: f64,
    duplicates: Vec<usize>,
}

/// Arity, out-of-range indices, degenerate faces (area below [`ZERO_AREA_REL`] of the squared
/// bounding-box diagonal `diag`), total area and duplicate faces.
fn scan_faces(mesh: &Mesh, diag: f64, progress: &Progress) -> Result<FaceScan> {
    let n = mesh.positions.len();
    let mut scan = FaceScan {
        arity: Default::default(),
        out_of_range: 0,
        degenerate: Vec::new(),
        area: 0.0,
        duplicates: Vec::new(),
    };
    let zero = ZERO_AREA_REL * diag * diag;
    for (fi, f) in mesh.faces.iter().enumerate() {
        *scan.arity.entry(f.len().to_string()).or_insert(0) += 1;
        if f.iter().any(|&v| v as usize >= n) {
            scan.out_of_range += 1;
            continue;
        }
        let a = polygon_area(&mesh.positions, f);
        scan.area += a;
        if distinct_count(f) < 3 || !(a > zero) {
            scan.degenerate.push(fi);
        }
        if fi % 65536 == 0 {
            progress.check()?;
        }
    }
    scan.duplicates = duplicate_faces_polled(&mesh.faces, progress)?;
    Ok(scan)
}

/// Area of a polygon from its vector area (Newell), exact for planar polygons of any arity.
pub fn polygon_area(positions: &[Point3], f: &[u32]) -> f64 {
    if f.len() < 3 {
        return 0.0;
    }
    let a = positions[f[0] as usize];
    let mut s = [0.0; 3];
    for k in 1..f.len() - 1 {
        let c = geometry::triangle_cross(a, positions[f[k] as usize], positions[f[k + 1] as usize]);
        s = geometry::add(s, c);
    }
    0.5 * geometry::norm(s)
}

/// Number of distinct indices in a (short) face.
pub fn distinct_count(f: &[u32]) -> usize {
    (0..f.len()).filter(|&i| !f[..i].contains(&f[i])).count()
}

/// Indices of faces whose vertex set equals that of an earlier face (winding and start ignored),
/// ascending.
pub fn duplicate_faces(faces: &crate::mesh::Faces) -> Vec<usize> {
    duplicate_faces_polled(faces, &Progress::new()).expect(
        "duplicate_faces_polled fails only through progress.check(), and a fresh Progress is never cancelled",
    )
}

/// Faces between two polls of [`duplicate_faces_polled`]: a few ms of hashing.
const DUPLICATE_POLL: usize = 32_768;

/// [`duplicate_faces`], polling `progress` every [`DUPLICATE_POLL`] faces. One pass with a hash
/// set of the sorted vertex lists instead of a sort of all keys: a sort of 280k keys is one
/// uninterruptible call (136 ms at load 12 on the 140k-vertex bunny), the pass is not.
pub fn duplicate_faces_polled(faces: &crate::mesh::Faces, progress: &Progress) -> Result<Vec<usize>> {
    let mut dup = Vec::new();
    match faces.as_triangles() {
        Some(tris) => {
            let mut seen = IntSet::with_capacity_and_hasher(tris.len() / 3, Default::default());
            for (i, t) in tris.chunks_exact(3).enumerate() {
                progress.check_every(i, DUPLICATE_POLL)?;
                let mut k = [t[0], t[1], t[2]];
                k.sort_unstable();
                if !seen.insert(TriangleKey(k)) {
                    dup.push(i);
                }
            }
        }
        None => {
            let mut seen = IntSet::with_capacity_and_hasher(faces.len(), Default::default());
            for (i, f) in faces.iter().enumerate() {
                progress.check_every(i, DUPLICATE_POLL)?;
                let mut k = f.to_vec();
                k.sort_unstable();
                if !seen.insert(k) {
                    dup.push(i);
                }
            }
        }
    }
    Ok(dup)
}

/// A sorted triangle as a hash key: two words for [`IntHasher`](crate::hash::IntHasher) instead
/// of the twelve bytes (one word each) the array's own `Hash` would feed it.
#[derive(PartialEq, Eq)]
struct TriangleKey([u32; 3]);

impl std::hash::Hash for TriangleKey {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        h.write_u64((self.0[0] as u64) << 32 | self.0[1] as u64);
        h.write_u32(self.0[2]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Faces;
    use crate::shapes;

    fn mesh(pos: Vec<Point3>, faces: &[&[u32]]) -> Mesh {
        let mut f = Faces::new();
        for face in faces {
            f.push(face, 0);
        }
        Mesh::new(pos, f)
    }

    #[test]
    fn icosphere_closed_genus_zero_outward() {
        let m = shapes::icosphere(3, 2.0);
        let r = analyze(&m);
        assert_eq!(r.vertices, 642);
        assert_eq!(r.faces, 1280);
        assert_eq!(r.edges, 1920);
        assert_eq!(r.euler_characteristic, 2);
        assert_eq!(r.genus, Some(0));
        assert!(r.closed && r.manifold && r.consistently_oriented);
        assert_eq!(r.components, 1);
        assert_eq!(r.boundary_loops, 0);
        assert_eq!(r.face_arity.get("3"), Some(&1280));
        // Inscribed polyhedron: volume a little below 4/3 π r³ and positive (outward).
        let v = r.volume.unwrap();
        let sphere = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
        assert!(v > 0.97 * sphere && v < sphere, "{v}");
    }

    #[test]
    fn torus_genus_one_quads() {
        let m = shapes::torus(24, 12, 2.0, 0.5, true);
        let r = analyze(&m);
        assert_eq!(r.face_arity.get("4"), Some(&(24 * 12)));
        assert_eq!(r.euler_characteristic, 0);
        assert_eq!(r.genus, Some(1));
        assert!(r.closed && r.manifold);
    }

    #[test]
    fn grid_one_boundary_loop_not_closed() {
        let m = shapes::grid(5, 4, 0.1, false);
        let r = analyze(&m);
        assert_eq!(r.boundary_loops, 1);
        assert_eq!(r.boundary_loop_lengths, vec![2 * (5 + 4)]);
        assert!(!r.closed);
        assert_eq!(r.genus, None);
        assert_eq!(r.volume, None);
        assert_eq!(r.euler_characteristic, 1); // a disk
    }

    #[test]
    fn bowtie_is_pinch_not_non_manifold() {
        let pos =
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, -1.0, 0.0]];
        let r = analyze(&mesh(pos, &[&[0, 1, 2], &[0, 3, 4]]));
        assert_eq!(r.non_manifold_vertices, 0);
        assert_eq!(r.pinch_vertices, 1);
        assert!(r.manifold);
        assert_eq!(r.components, 2);
        assert_eq!(r.components_by_vertex, 1);
    }

    #[test]
    fn three_faces_on_an_edge_and_flipped_face() {
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, -1.0, 0.0], [0.5, 0.0, 1.0]];
        let r = analyze(&mesh(pos, &[&[0, 1, 2], &[1, 0, 3], &[0, 1, 4]]));
        assert_eq!(r.non_manifold_edges, 1);
        assert_eq!(r.examples.non_manifold_edges, vec![[0, 1]]);
        assert!(!r.manifold);
        assert_eq!(r.genus, None);

        let mut m = shapes::icosphere(1, 1.0);
        let f0: Vec<u32> = m.faces.get(0).to_vec();
        let mut faces = Faces::new();
        faces.push(&[f0[0], f0[2], f0[1]], 0);
        for i in 1..m.faces.len() {
            faces.push(m.faces.get(i), 0);
        }
        m.faces = faces;
        let r = analyze(&m);
        assert_eq!(r.inconsistent_orientation, 3);
        assert!(!r.consistently_oriented);
        assert_eq!(r.volume, None);
        assert_eq!(r.genus, Some(0)); // orientation does not change the topology
    }

    #[test]
    fn degenerate_duplicate_unreferenced_nonfinite() {
        let pos =
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0], [9.0, 9.0, f64::NAN]];
        // face 1: repeated index; face 2: collinear (zero area); face 3: duplicate of 0 (reversed).
        let r = analyze(&mesh(pos, &[&[0, 1, 2], &[0, 1, 1], &[0, 1, 3], &[2, 1, 0]]));
        assert_eq!(r.degenerate_faces, 2);
        assert_eq!(r.examples.degenerate_faces, vec![1, 2]);
        assert_eq!(r.duplicate_faces, 1);
        assert_eq!(r.examples.duplicate_faces, vec![3]);
        assert_eq!(r.unreferenced_vertices, 1);
        assert_eq!(r.non_finite_coordinates, 1);
    }

    /// A mesh followed by copies of some of its faces (rotated, reversed): the copies, and only
    /// they, are duplicates, in ascending order.
    fn with_copies(m: &Mesh, every: usize) -> (Mesh, Vec<usize>) {
        let mut f = m.faces.clone();
        let mut expected = Vec::new();
        for i in (0..m.faces.len()).step_by(every) {
            let mut c = m.faces.get(i).to_vec();
            c.rotate_left(1);
            if i % 2 == 0 {
                c.reverse();
            }
            expected.push(f.len());
            f.push(&c, 0);
        }
        (Mesh::new(m.positions.clone(), f), expected)
    }

    #[test]
    fn duplicates_are_the_later_copies_of_triangles_and_quads() {
        for (m, every) in [(shapes::icosphere(3, 1.0), 7), (shapes::torus(12, 8, 2.0, 0.5, true), 5)] {
            let (m, expected) = with_copies(&m, every);
            assert_eq!(duplicate_faces(&m.faces), expected);
        }
        // Same vertex set with a repeated index is a duplicate; another multiset is not.
        let mut f = Faces::new();
        for t in [[0, 1, 1], [1, 0, 1], [0, 0, 1], [0, 1, 2]] {
            f.push(&t, 0);
        }
        assert_eq!(duplicate_faces(&f), vec![1]);
    }

    #[test]
    fn duplicate_search_polls_and_stops_at_a_cancel() {
        let (m, expected) = with_copies(&shapes::icosphere(6, 1.0), 4); // 81,920 + 20,480 faces
        let p = Progress::new();
        assert_eq!(duplicate_faces_polled(&m.faces, &p).unwrap(), expected);
        // One poll per DUPLICATE_POLL faces (the first at face 0).
        assert_eq!(p.checks() as usize, m.faces.len().div_ceil(DUPLICATE_POLL));
        let p = Progress::new();
        p.cancel_at_check(1);
        assert!(matches!(duplicate_faces_polled(&m.faces, &p), Err(crate::Error::Cancelled)));
    }

    #[test]
    fn job_report_has_stages() {
        let m = shapes::icosphere(1, 1.0);
        let out = crate::job::run(
            crate::job::JobKind::Validate,
            vec![m],
            serde_json::json!({"max_examples": 3}),
            &Progress::new(),
        )
        .unwrap();
        assert_eq!(out.report["faces"], 80);
        assert!(out.report["stages"]["topology"].is_number());
        assert!(out.meshes.is_empty());
        let bad = crate::job::run(
            crate::job::JobKind::Validate,
            vec![shapes::icosphere(0, 1.0)],
            serde_json::json!({"bogus": 1}),
            &Progress::new(),
        );
        assert!(bad.is_err());
    }
}
