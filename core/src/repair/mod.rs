//! Repair of damaged meshes (seed 003 §4.2): weld, drop degenerate/duplicate faces, resolve
//! non-manifold parts, orient, remove small components, fill holes, drop unreferenced vertices.
//!
//! Each step is optional, runs in the order below and reports what it changed, so a user can see
//! exactly what happened to their data; nothing is removed without being counted.
//!
//! 1. [`weld`]: merge vertices closer than `weld_tolerance` × bbox diagonal (spatial hashing).
//! 2. [`clean`]: collapse repeated consecutive indices, drop faces with < 3 distinct vertices or
//!    zero area, drop faces with the same vertex set as an earlier face.
//! 3. [`nonmanifold`]: split (duplicate vertices per fan, one face pair kept glued per edge) or
//!    remove (drop the faces) at non-manifold edges and vertices.
//! 4. [`orient`]: make orientation consistent by BFS over manifold edges.
//! 5. [`components`]: drop components below `min_component_faces`, or all but the largest.
//! 6. [`holes`]: fill boundary loops (Liepa minimum dihedral/area DP, centroid fan above
//!    `dp_max_edges`), optionally refine and fair the patch.
//! 7. [`orient::outward`]: flip closed components with negative signed volume.
//! 8. [`clean::compact`]: drop unreferenced vertices and renumber (old → new map kept).

pub mod clean;
pub mod components;
pub mod fair;
pub mod holes;
pub mod nonmanifold;
pub mod orient;
pub mod weld;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Location, Result};
use crate::job::{Output, Progress, Stages};
use crate::mesh::{Mesh, Point3};
use crate::topology::NONE;
use crate::validate;

/// What to do at non-manifold edges and vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum NonManifoldMode {
    /// Duplicate vertices so each fan gets its own copy; at an edge with > 2 faces the best
    /// matching pair (opposite winding, most nearly coplanar) stays glued, the others come loose.
    Split,
    /// Delete the faces on non-manifold edges and all fans but the largest at non-manifold
    /// vertices (leaves holes, which hole filling can close).
    Remove,
    /// Leave them as they are.
    Keep,
}

/// Parameters of the `repair` job. Every step can be switched off.
#[derive(Debug, Clone, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RepairParams {
    /// Merge vertices closer than `weld_tolerance` × bounding-box diagonal.
    pub weld: bool,
    /// Weld distance relative to the bounding-box diagonal (default 1e-6). 0 merges only exactly
    /// coincident positions.
    pub weld_tolerance: f64,
    /// Drop faces with < 3 distinct vertices or zero area (repeated consecutive indices in larger
    /// faces are collapsed first).
    pub remove_degenerate: bool,
    /// Drop faces with the same vertex set as an earlier face (winding ignored).
    pub remove_duplicates: bool,
    pub non_manifold: NonManifoldMode,
    /// Make face orientation consistent across manifold edges.
    pub orient: bool,
    /// Flip closed components whose signed volume is negative (needs `orient`).
    pub outward: bool,
    /// Drop connected components (by shared edges) with fewer faces than this (0: keep all).
    pub min_component_faces: usize,
    /// Keep only the component with most faces.
    pub keep_largest: bool,
    pub fill_holes: bool,
    /// Holes with more boundary edges than this are left open (and reported).
    pub max_hole_edges: usize,
    /// Holes whose patch area would exceed this fraction of their component's area are left
    /// open (an open sheet's rim is not a hole).
    pub max_hole_area_ratio: f64,
    /// Loops up to this many edges are triangulated by the minimum dihedral/area DP (O(n³));
    /// longer ones get a centroid fan.
    pub dp_max_edges: usize,
    /// Split patch triangles until edge lengths match the surrounding mesh (Liepa).
    pub refine: bool,
    /// Move new interior vertices to the harmonic (membrane) position, boundary fixed.
    pub fair: bool,
    /// Drop vertices no face or curve uses, renumbering the rest.
    pub remove_unreferenced: bool,
    /// Fail (unsupported-topology error) instead of returning a mesh that is not manifold.
    pub require_manifold: bool,
    /// Include the full old → new vertex index map in the report (can be large).
    pub report_vertex_map: bool,
}

impl Default for RepairParams {
    fn default() -> Self {
        RepairParams {
            weld: true,
            weld_tolerance: 1e-6,
            remove_degenerate: true,
            remove_duplicates: true,
            non_manifold: NonManifoldMode::Split,
            orient: true,
            outward: true,
            min_component_faces: 0,
            keep_largest: false,
            fill_holes: true,
            max_hole_edges: 1000,
            max_hole_area_ratio: 0.5,
            dp_max_edges: 200,
            refine: true,
            fair: true,
            remove_unreferenced: true,
            require_manifold: false,
            report_vertex_map: false,
        }
    }
}

impl RepairParams {
    fn check(&self) -> Result<()> {
        if !(self.weld_tolerance >= 0.0 && self.weld_tolerance.is_finite()) {
            return Err(Error::params("weld_tolerance", "must be a finite number ≥ 0"));
        }
        if self.weld_tolerance > 0.1 {
            return Err(Error::params(
                "weld_tolerance",
                "is relative to the bbox diagonal; > 0.1 would merge whole features",
            ));
        }
        if !(self.max_hole_area_ratio > 0.0) {
            return Err(Error::params("max_hole_area_ratio", "must be > 0"));
        }
        if self.dp_max_edges > 2000 {
            return Err(Error::params("dp_max_edges", "the DP is O(n³); at most 2000"));
        }
        Ok(())
    }
}

/// Tracks input vertex → current vertex through the steps.
#[derive(Debug, Clone)]
pub struct VertexMap {
    /// `map[i]` = current index of input vertex `i`, [`NONE`] when removed.
    pub map: Vec<u32>,
}

impl VertexMap {
    pub fn identity(n: usize) -> Self {
        VertexMap { map: (0..n as u32).collect() }
    }

    /// Composes with a step's map from current to new indices.
    pub fn then(&mut self, step: &[u32]) {
        for m in &mut self.map {
            if *m != NONE {
                *m = step[*m as usize];
            }
        }
    }
}

/// Appends a vertex at `p`, giving it the mean normal/UV of `like` when the mesh has those.
pub(crate) fn push_vertex(mesh: &mut Mesh, p: Point3, like: &[u32]) -> u32 {
    let id = mesh.positions.len() as u32;
    mesh.positions.push(p);
    if let Some(nr) = &mut mesh.normals {
        let mut s = [0.0; 3];
        for &v in like {
            s = crate::geometry::add(s, nr[v as usize]);
        }
        nr.push(crate::geometry::normalize(s));
    }
    if let Some(uv) = &mut mesh.uvs {
        let mut s = [0.0; 2];
        for &v in like {
            s[0] += uv[v as usize][0];
            s[1] += uv[v as usize][1];
        }
        let k = like.len().max(1) as f64;
        uv.push([s[0] / k, s[1] / k]);
    }
    id
}

/// The `repair` job.
pub fn run(mesh: Mesh, params: &RepairParams, progress: &Progress) -> Result<Output> {
    params.check()?;
    mesh.check()?;
    let mut stages = Stages::new();
    let input = stages.run(progress, "validate_input", || validate::analyze_polled(&mesh, progress))?;
    let mut r = Repairing {
        vmap: VertexMap::identity(mesh.positions.len()),
        mesh,
        stages,
        progress,
        steps: serde_json::Map::new(),
        dirty: false,
        holes: None,
    };
    mend_topology(&mut r, params, &input)?;
    close_and_compact(&mut r, params, &input)?;
    refuse_if_emptied(&r, input.faces)?;

    let out = if r.dirty {
        let mesh = &r.mesh;
        r.stages.run(progress, "validate_output", || validate::analyze_polled(mesh, progress))?
    } else {
        input.clone()
    };
    let why = why_not(&out, r.holes.as_ref(), params);
    if params.require_manifold && !(out.manifold && out.pinch_vertices == 0) {
        return Err(Error::Topology(format!("repaired mesh is not manifold: {}", why.join("; "))));
    }
    let report = job_report(&r, &input, &out, why, params.report_vertex_map);
    Ok(Output { meshes: vec![r.mesh], report, ..Default::default() })
}

/// Refuses a repair that removed every one of the input's `faces`: an empty mesh is no answer
/// (OBJ, PLY and OFF files of it are not even readable as meshes), so the caller gets the reason,
/// each step's removals by name, instead of a file with nothing in it.
fn refuse_if_emptied(r: &Repairing, faces: usize) -> Result<()> {
    if faces == 0 || r.mesh.face_count() > 0 {
        return Ok(());
    }
    let mut removed = Vec::new();
    for (step, report) in &r.steps {
        for (field, n) in report.as_object().into_iter().flatten() {
            let is_removal = field.starts_with("dropped_") || field == "faces_removed";
            if let Some(n) = n.as_u64().filter(|&n| is_removal && n > 0) {
                removed.push(format!("{step}.{field} {n}"));
            }
        }
    }
    Err(Error::InvalidMesh {
        location: Location::Face(0),
        message: format!(
            "the repair removed every face of the mesh ({faces} in all; {}): nothing is left to return",
            if removed.is_empty() { "no step names them".to_string() } else { removed.join(", ") }
        ),
    })
}

/// The repair in progress: the mesh, the timings, each step's report (or why it was skipped),
/// where every input vertex went, and `dirty`, whether the faces changed since the input was
/// analysed. While `dirty` is false, a step whose problem the input report shows absent is
/// skipped (said so in its report) instead of rebuilding topology.
struct Repairing<'a> {
    mesh: Mesh,
    stages: Stages,
    progress: &'a Progress,
    steps: serde_json::Map<String, serde_json::Value>,
    vmap: VertexMap,
    dirty: bool,
    /// The hole filling's report, for the `why_not` of an output that is still open.
    holes: Option<holes::FillReport>,
}

impl Repairing<'_> {
    /// Runs `f` on the mesh as the timed stage `stage`, records its report under `key`, and
    /// marks the faces changed when `changed` says it changed them.
    fn step<R: Serialize>(
        &mut self,
        stage: &str,
        key: &str,
        f: impl FnOnce(&mut Mesh, &Progress) -> Result<R>,
        changed: impl FnOnce(&R) -> bool,
    ) -> Result<R> {
        let (mesh, progress) = (&mut self.mesh, self.progress);
        let r = self.stages.run(progress, stage, || f(mesh, progress))?;
        self.dirty |= changed(&r);
        self.steps.insert(key.into(), to_json(&r));
        Ok(r)
    }

    fn skip(&mut self, key: &str, why: &str) {
        self.steps.insert(key.into(), serde_json::json!({ "skipped": why }));
    }
}

/// Steps 1–5: weld, clean, non-manifold parts, orientation, small components.
fn mend_topology(r: &mut Repairing, params: &RepairParams, input: &validate::Report) -> Result<()> {
    let diag = input.bbox_diagonal;
    if params.weld {
        r.step(
            "weld",
            "weld",
            |m, p| weld::weld(m, params.weld_tolerance * diag, p),
            |w| w.merged_vertices > 0,
        )?;
    }
    if params.remove_degenerate || params.remove_duplicates {
        r.step(
            "clean",
            "clean",
            |m, p| clean::clean(m, params.remove_degenerate, params.remove_duplicates, diag, p),
            |c| {
                c.collapsed_corners + c.dropped_repeated_index + c.dropped_zero_area + c.dropped_duplicates
                    > 0
            },
        )?;
    }
    if params.non_manifold != NonManifoldMode::Keep {
        if !r.dirty && input.non_manifold_edges == 0 && input.non_manifold_vertices == 0 {
            r.skip("non_manifold", "input has no non-manifold edges or vertices");
        } else {
            r.step(
                "non_manifold",
                "non_manifold",
                |m, p| nonmanifold::resolve(m, params.non_manifold, p),
                |n| n.vertices_added + n.faces_removed > 0,
            )?;
        }
    }
    if params.orient {
        if !r.dirty && input.inconsistent_orientation == 0 {
            r.skip("orient", "input is consistently oriented");
        } else {
            r.step("orient", "orient", |m, _| Ok(orient::make_consistent(m)), |o| o.faces_flipped > 0)?;
        }
    }
    if params.min_component_faces > 0 || params.keep_largest {
        r.step(
            "components",
            "components",
            |m, _| Ok(components::remove_small(m, params.min_component_faces, params.keep_largest)),
            |c| c.faces_removed > 0,
        )?;
    }
    Ok(())
}

/// Steps 6–8: fill holes, turn closed components outward, drop unreferenced vertices.
fn close_and_compact(r: &mut Repairing, params: &RepairParams, input: &validate::Report) -> Result<()> {
    if params.fill_holes {
        if !r.dirty && input.boundary_edges == 0 {
            r.skip("fill_holes", "input has no boundary");
        } else {
            let filled = r.step(
                "fill_holes",
                "fill_holes",
                |m, p| holes::fill(m, &holes::FillOptions::from(params), p),
                |h| h.filled > 0,
            )?;
            // A filled hole that touched a skipped one at a vertex leaves a closed fan next to an
            // open one there (a non-manifold vertex the fill created): resolve those the same way.
            if filled.filled > 0 && params.non_manifold != NonManifoldMode::Keep {
                r.step(
                    "non_manifold_after_fill",
                    "non_manifold_after_fill",
                    |m, p| nonmanifold::resolve(m, params.non_manifold, p),
                    |_| false,
                )?;
            }
            r.holes = Some(filled);
        }
    }
    if params.orient && params.outward {
        if !r.dirty && input.components == 1 && input.volume.is_some_and(|v| v > 0.0) {
            r.skip("outward", "input is one closed component with positive volume");
        } else {
            r.step("outward", "outward", orient::outward, |o| o.components_flipped > 0)?;
        }
    }
    if params.remove_unreferenced {
        let c =
            r.step("compact", "unreferenced", |m, _| Ok(clean::compact(m)), |c| c.removed_vertices > 0)?;
        r.vmap.then(&c.map);
    }
    Ok(())
}

/// The job's report: input and output summaries, each step, why the output is not a closed
/// manifold, where the vertices went (the whole map with `with_map`), and the timings.
fn job_report(
    r: &Repairing,
    input: &validate::Report,
    out: &validate::Report,
    why: Vec<String>,
    with_map: bool,
) -> serde_json::Value {
    let kept = r.vmap.map.iter().filter(|&&m| m != NONE).count();
    let mut report = serde_json::json!({
        "input": summary(input),
        "output": summary(out),
        "steps": r.steps,
        "manifold": out.manifold && out.pinch_vertices == 0,
        "closed": out.closed,
        "why_not": why,
        "vertex_map": {
            "input_vertices": r.vmap.map.len(),
            "kept": kept,
            "removed": r.vmap.map.len() - kept,
            "output_vertices": r.mesh.positions.len(),
        },
        "stages": r.stages.to_json(),
        "total_ms": r.stages.total_ms(),
    });
    if with_map {
        report["vertex_map"]["map"] = serde_json::json!(r
            .vmap
            .map
            .iter()
            .map(|&m| if m == NONE { -1 } else { m as i64 })
            .collect::<Vec<_>>());
    }
    report
}

/// Reasons the output is not a closed manifold, in words.
fn why_not(out: &validate::Report, holes: Option<&holes::FillReport>, params: &RepairParams) -> Vec<String> {
    let mut why = Vec::new();
    if out.non_manifold_edges > 0 {
        why.push(format!(
            "{} non-manifold edges (non_manifold = {:?})",
            out.non_manifold_edges, params.non_manifold
        ));
    }
    if out.non_manifold_vertices > 0 {
        why.push(format!(
            "{} non-manifold vertices (non_manifold = {:?})",
            out.non_manifold_vertices, params.non_manifold
        ));
    }
    if out.pinch_vertices > 0 {
        why.push(format!("{} vertices where boundary loops touch (pinches)", out.pinch_vertices));
    }
    if out.boundary_edges > 0 {
        match holes {
            None => why.push(format!("{} holes left open (fill_holes = false)", out.boundary_loops)),
            Some(h) => {
                for (reason, n) in &h.skipped_by_reason {
                    why.push(format!("{n} holes skipped: {reason}"));
                }
                if h.skipped_by_reason.is_empty() {
                    why.push(format!("{} boundary edges remain", out.boundary_edges));
                }
            }
        }
    }
    why
}

/// The headline counts of a validation report.
fn summary(r: &validate::Report) -> serde_json::Value {
    serde_json::json!({
        "vertices": r.vertices,
        "faces": r.faces,
        "components": r.components,
        "boundary_loops": r.boundary_loops,
        "non_manifold_edges": r.non_manifold_edges,
        "non_manifold_vertices": r.non_manifold_vertices,
        "pinch_vertices": r.pinch_vertices,
        "degenerate_faces": r.degenerate_faces,
        "duplicate_faces": r.duplicate_faces,
        "unreferenced_vertices": r.unreferenced_vertices,
        "inconsistent_orientation": r.inconsistent_orientation,
        "euler_characteristic": r.euler_characteristic,
        "genus": r.genus,
        "closed": r.closed,
        "manifold": r.manifold,
        "volume": r.volume,
    })
}

fn to_json<T: Serialize>(v: &T) -> serde_json::Value {
    serde_json::to_value(v).unwrap_or(serde_json::Value::Null)
}
