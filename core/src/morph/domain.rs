//! Which domain the morph uses (spherical or planar), and the preparation of damaged inputs for it
//! (seed 003 §4.2, the step 1).
//!
//! The mesh alone cannot tell "a disk with an extra hole" from "a closed scan with holes": both
//! are open surfaces with several boundary loops. So the domain is a parameter (`domain`), and
//! `auto` (the default) states its rule:
//!
//! - without `repair`, input 0 decides as it is: a disk (connected, manifold, one boundary loop,
//!   genus 0) takes the planar domain, anything else the spherical one (which refuses what is not
//!   closed genus 0, saying what it found);
//! - with `repair`, input 0 is first cleaned (weld, degenerate/duplicate faces, non-manifold
//!   parts split, orientation, all but the largest component dropped; no hole filling), then its
//!   boundary loops are measured: it is a **disk** when the longest loop (by length) *spans* the
//!   shape — the diagonal of the loop's bounding box is at least [`RIM_SPAN`] of the mesh's — and
//!   *dominates* — at least [`RIM_DOMINANCE`] × the length of the next-longest loop. Otherwise
//!   (no loop, or only loops that are small or of similar length) it is a closed surface with holes:
//!   **sphere**.
//!
//! Preparation with `repair: true`, every input (the same cleaning as above, then):
//! - planar domain: every hole is filled except the outer boundary, which is the longest loop (ties:
//!   larger vector area); the report names it (edges, length). A mesh with no boundary after
//!   cleaning is refused (it cannot be a disk).
//! - spherical domain: every hole is filled, whatever its size (the limits of the `repair` job's
//!   `max_hole_edges` / `max_hole_area_ratio`, which keep an open sheet's rim open, are lifted:
//!   the user or the rule asked for a closed surface).
//!
//! Everything removed or added is counted per input in the report's `repair[k].summary`.

use serde::{Deserialize, Serialize};
use serde_json::json;

use crate::error::{Error, Result};
use crate::geometry::{add, cross, dist, norm, Aabb};
use crate::job::{Progress, Stages};
use crate::mesh::{Mesh, Point3};
use crate::repair::{self, holes, nonmanifold, NonManifoldMode, RepairParams};
use crate::topology::Topology;

use super::planar;
use super::trimesh::{self, TriMesh};
use super::{input_name, MorphParams};

/// Auto rule: the rim's bounding-box diagonal over the mesh's (a hemisphere's rim: 0.94; a flat
/// disk's: 1.0; the largest hole of the scanned bunny: see `core/tests/morph_domain.rs`).
pub const RIM_SPAN: f64 = 0.5;
/// Auto rule: the rim's length over the next-longest loop's.
pub const RIM_DOMINANCE: f64 = 2.0;

/// The domain the morph works on.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum MorphDomain {
    /// Input 0 decides: see the rule in docs/api.md ("Morph: domains").
    #[default]
    Auto,
    /// Spherical domain: closed genus-0 inputs; with `repair`, every hole is closed.
    #[serde(alias = "spherical")]
    Sphere,
    /// Planar domain: disk-like inputs; with `repair`, every hole but the outer boundary is closed.
    #[serde(alias = "planar")]
    Disk,
}

/// The domain chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Chosen {
    Spherical,
    Planar,
}

impl Chosen {
    pub fn name(self) -> &'static str {
        match self {
            Chosen::Spherical => "spherical",
            Chosen::Planar => "planar",
        }
    }
}

/// One boundary loop, measured.
#[derive(Debug, Clone, Serialize)]
pub struct LoopInfo {
    pub edges: usize,
    /// Sum of its edge lengths.
    pub length: f64,
    /// |½ Σ pᵢ × pᵢ₊₁|: its largest projected area.
    pub vector_area: f64,
    /// Diagonal of the loop's bounding box over the mesh's.
    pub span: f64,
    /// Two vertices of one of its edges (names the loop for the hole filler).
    #[serde(skip)]
    pub edge: [u32; 2],
}

/// The closed boundary loops of `mesh`, longest first (ties: larger vector area).
pub fn measure_loops(mesh: &Mesh) -> Vec<LoopInfo> {
    let topo = Topology::new(mesh);
    let diag = Aabb::of(&mesh.positions).map(|b| b.diagonal()).unwrap_or(0.0).max(1e-300);
    let mut out: Vec<LoopInfo> = topo
        .boundary_loops()
        .iter()
        .filter(|l| l.closed && l.vertices.len() >= 2)
        .map(|l| {
            let p: Vec<Point3> = l.vertices.iter().map(|&v| mesh.positions[v as usize]).collect();
            let n = p.len();
            let length: f64 = (0..n).map(|i| dist(p[i], p[(i + 1) % n])).sum();
            let va = (0..n).fold([0.0; 3], |s, i| add(s, cross(p[i], p[(i + 1) % n])));
            LoopInfo {
                edges: n,
                length,
                vector_area: 0.5 * norm(va),
                span: Aabb::of(&p).map(|b| b.diagonal()).unwrap_or(0.0) / diag,
                edge: [l.vertices[0], l.vertices[1 % n]],
            }
        })
        .collect();
    out.sort_by(|a, b| b.length.total_cmp(&a.length).then(b.vector_area.total_cmp(&a.vector_area)));
    out
}

/// The auto rule on measured loops (longest first): planar when the longest loop is a disk's rim,
/// with the measurements that decided it in words.
pub fn rim_rule(loops: &[LoopInfo]) -> (Chosen, String) {
    let Some(l1) = loops.first() else {
        return (Chosen::Spherical, "closed after cleaning (no boundary loop)".into());
    };
    let l2 = loops.get(1).map_or(0.0, |l| l.length);
    let dominance = if l2 > 0.0 { l1.length / l2 } else { f64::INFINITY };
    let facts = format!(
        "{} boundary loop(s); the longest ({} edges, length {:.4}) spans {:.0} % of the bounding-box \
         diagonal and is {} the next-longest",
        loops.len(),
        l1.edges,
        l1.length,
        100.0 * l1.span,
        if dominance.is_finite() { format!("{dominance:.2}×") } else { "unlike (there is none)".into() },
    );
    if l1.span >= RIM_SPAN && dominance >= RIM_DOMINANCE {
        (
            Chosen::Planar,
            format!(
                "{facts}: it is a disk's outer rim (span ≥ {:.0} % and ≥ {RIM_DOMINANCE}× the next), the \
                 other loops are holes",
                100.0 * RIM_SPAN
            ),
        )
    } else {
        (
            Chosen::Spherical,
            format!(
                "{facts}: no loop is a rim (needs span ≥ {:.0} % and ≥ {RIM_DOMINANCE}× the next), so all \
                 are holes of a closed surface",
                100.0 * RIM_SPAN
            ),
        )
    }
}

/// The inputs as the chosen domain's pipeline receives them.
pub struct Prepared {
    pub meshes: Vec<Mesh>,
    /// Input vertex → prepared vertex ([`u32::MAX`]: removed) when the repair ran.
    pub vertex_maps: Vec<Option<Vec<u32>>>,
    /// Per input: what the repair did (empty without `repair`).
    pub repair: Vec<serde_json::Value>,
    pub domain: Chosen,
    pub reason: String,
}

/// `TooLarge` when input `k` has more than `max_vertices` vertices. Checked before repair and
/// again after it (hole filling adds vertices).
pub(super) fn check_vertex_limit(k: usize, m: &Mesh, max_vertices: usize) -> Result<()> {
    if m.positions.len() > max_vertices {
        return Err(Error::TooLarge {
            what: format!("{} vertices", input_name(k)),
            limit: max_vertices as u64,
            actual: m.positions.len() as u64,
        });
    }
    Ok(())
}

/// Input vertex → triangulated vertex: `tri_map` (from `TriMesh::from_mesh`) after the repair's
/// vertex map when there was one, so feature indices still name the vertex the user meant.
/// `u32::MAX` = the vertex is gone.
pub(super) fn compose_vertex_maps(repair_map: Option<&[u32]>, tri_map: Vec<u32>) -> Vec<u32> {
    match repair_map {
        Some(rm) => {
            rm.iter()
                .map(|&r| {
                    if r == u32::MAX {
                        u32::MAX
                    } else {
                        tri_map.get(r as usize).copied().unwrap_or(u32::MAX)
                    }
                })
                .collect()
        }
        None => tri_map,
    }
}

/// Chooses the domain and, with `repair`, prepares every input for it (stage `repair`).
pub fn prepare(
    inputs: Vec<Mesh>,
    params: &MorphParams,
    progress: &Progress,
    stages: &mut Stages,
) -> Result<Prepared> {
    for (k, m) in inputs.iter().enumerate() {
        check_vertex_limit(k, m, params.max_vertices)?;
    }
    let k_in = inputs.len();
    if !params.repair {
        let (domain, reason) = match params.domain {
            MorphDomain::Sphere => (Chosen::Spherical, "requested by `domain: sphere`".to_string()),
            MorphDomain::Disk => (Chosen::Planar, "requested by `domain: disk`".to_string()),
            MorphDomain::Auto => match inputs.first() {
                Some(m) => {
                    let (t, _, _) = TriMesh::from_mesh(m);
                    let info = trimesh::topology(&t);
                    if planar::is_disk(&info) {
                        (Chosen::Planar, "input 0 is a disk (one boundary loop, genus 0)".to_string())
                    } else {
                        (Chosen::Spherical, format!("input 0 is not a disk ({})", planar::describe(&info)))
                    }
                }
                None => (Chosen::Spherical, "no input".to_string()),
            },
        };
        return Ok(Prepared {
            meshes: inputs,
            vertex_maps: vec![None; k_in],
            repair: Vec::new(),
            domain,
            reason,
        });
    }
    stages.run(progress, "repair", || {
        // 1. Clean every input (no hole filling yet).
        let mut cleaned = Vec::with_capacity(k_in);
        for m in inputs {
            progress.check()?;
            cleaned.push(clean(m, progress)?);
        }
        // 2. The domain.
        let (domain, reason) = match params.domain {
            MorphDomain::Sphere => (Chosen::Spherical, "requested by `domain: sphere`".to_string()),
            MorphDomain::Disk => (Chosen::Planar, "requested by `domain: disk`".to_string()),
            MorphDomain::Auto => {
                let (d, why) = rim_rule(&measure_loops(&cleaned[0].mesh));
                // A closed input cannot become a disk, so a disk-like input 0 with a closed partner
                // goes to the sphere (its rim is closed) rather than refusing the partner.
                let closed = cleaned.iter().position(|c| measure_loops(&c.mesh).is_empty());
                match (d, closed) {
                    (Chosen::Planar, Some(k)) => (
                        Chosen::Spherical,
                        format!(
                            "auto with repair: input 0 after cleaning has {why}; but {} is closed, so \
                             every input is closed into a sphere",
                            input_name(k)
                        ),
                    ),
                    _ => (d, format!("auto with repair: input 0 after cleaning has {why}")),
                }
            }
        };
        // 3. Fill holes for that domain.
        let (mut meshes, mut maps, mut reports) = (Vec::new(), Vec::new(), Vec::new());
        for (k, c) in cleaned.into_iter().enumerate() {
            let (mesh, rep) = fill_for(c.mesh, domain, k, &reason, progress)?;
            let summary = summarise(&c.report, &rep, &mesh);
            reports.push(json!({
                "input": k,
                "summary": summary,
                "holes": rep,
                "cleaning": c.report,
            }));
            meshes.push(mesh);
            maps.push(Some(c.map));
        }
        Ok(Prepared { meshes, vertex_maps: maps, repair: reports, domain, reason })
    })
}

struct Cleaned {
    mesh: Mesh,
    map: Vec<u32>,
    report: serde_json::Value,
}

/// The repair job without hole filling, keeping the largest component, with its vertex map.
fn clean(m: Mesh, progress: &Progress) -> Result<Cleaned> {
    let rp =
        RepairParams { keep_largest: true, fill_holes: false, report_vertex_map: true, ..Default::default() };
    let r = repair::run(m, &rp, progress)?;
    let map: Vec<u32> = r.report["vertex_map"]["map"]
        .as_array()
        .map(|a| a.iter().map(|x| x.as_i64().filter(|&v| v >= 0).map_or(u32::MAX, |v| v as u32)).collect())
        .ok_or_else(|| Error::Internal("repair returned no vertex map".into()))?;
    let mut report = r.report;
    if let Some(vm) = report.get_mut("vertex_map").and_then(|v| v.as_object_mut()) {
        vm.remove("map");
    }
    let mesh =
        r.meshes.into_iter().next().ok_or_else(|| Error::Internal("repair returned no mesh".into()))?;
    Ok(Cleaned { mesh, map, report })
}

/// Fills the holes the domain asks for; returns the mesh and a report of the loops and the fill.
/// New vertices are appended, so the cleaning's vertex map stays valid.
fn fill_for(
    mut mesh: Mesh,
    domain: Chosen,
    k: usize,
    reason: &str,
    progress: &Progress,
) -> Result<(Mesh, serde_json::Value)> {
    let loops = measure_loops(&mesh);
    let outer = match domain {
        Chosen::Planar => {
            let Some(o) = loops.first() else {
                let (t, _, _) = TriMesh::from_mesh(&mesh);
                return Err(Error::Topology(format!(
                    "{}: the planar domain ({reason}) needs a disk, but after repairing non-manifold parts \
                     and small components the mesh has no boundary ({}); use `domain: sphere` for a \
                     closed surface",
                    input_name(k),
                    planar::describe(&trimesh::topology(&t))
                )));
            };
            Some(o.clone())
        }
        Chosen::Spherical => None,
    };
    let opts = holes::FillOptions {
        // The patches are bounded by the loops; the domain, not a size limit, says which to close.
        max_hole_edges: usize::MAX,
        max_hole_area_ratio: f64::INFINITY,
        keep_open: outer.iter().map(|o| o.edge).collect(),
        ..Default::default()
    };
    let fill = if loops.is_empty() {
        holes::FillReport::default()
    } else {
        holes::fill(&mut mesh, &opts, progress)?
    };
    // As in the repair job: a filled hole touching another loop at a vertex may leave two fans there.
    let nm = if fill.filled > 0 {
        Some(nonmanifold::resolve(&mut mesh, NonManifoldMode::Split, progress)?)
    } else {
        None
    };
    let rep = json!({
        "loops": loops,
        "outer_boundary": outer.as_ref().map(|o| {
            // Length picks the rim; when another loop bounds a larger projected area the choice is
            // not clear-cut, and the user may want to look (or pick the domain differently).
            let by_area = loops.iter().map(|l| l.vector_area).fold(0.0, f64::max);
            json!({
                "rule": "longest boundary loop",
                "edges": o.edges,
                "length": o.length,
                "span": o.span,
                "vector_area": o.vector_area,
                "also_largest_vector_area": o.vector_area >= by_area,
            })
        }),
        "fill": fill,
        "non_manifold_after_fill": nm,
    });
    Ok((mesh, rep))
}

fn count(v: &serde_json::Value, path: &[&str]) -> u64 {
    let mut x = v;
    for p in path {
        x = &x[*p];
    }
    x.as_u64().unwrap_or(0)
}

/// The counts a user checks first: nothing is dropped without appearing here.
fn summarise(cleaning: &serde_json::Value, holes: &serde_json::Value, out: &Mesh) -> serde_json::Value {
    let s = &cleaning["steps"];
    json!({
        "vertices_in": count(cleaning, &["input", "vertices"]),
        "faces_in": count(cleaning, &["input", "faces"]),
        "vertices_merged": count(s, &["weld", "merged_vertices"]),
        "faces_removed_degenerate": count(s, &["clean", "dropped_repeated_index"]) + count(s, &["clean", "dropped_zero_area"]),
        "faces_removed_duplicate": count(s, &["clean", "dropped_duplicates"]),
        "faces_removed_non_manifold": count(s, &["non_manifold", "faces_removed"])
            + count(holes, &["non_manifold_after_fill", "faces_removed"]),
        "vertices_split_non_manifold": count(s, &["non_manifold", "vertices_added"])
            + count(holes, &["non_manifold_after_fill", "vertices_added"]),
        "components_removed": count(s, &["components", "components_removed"]),
        "faces_removed_small_components": count(s, &["components", "faces_removed"]),
        "vertices_removed_unreferenced": count(s, &["unreferenced", "removed_vertices"]),
        "holes_filled": count(holes, &["fill", "filled"]),
        "holes_left_open": count(holes, &["fill", "skipped"]),
        "outer_boundary_edges": holes["outer_boundary"]["edges"],
        "faces_added": count(holes, &["fill", "faces_added"]),
        "vertices_added": count(holes, &["fill", "vertices_added"]),
        "vertices_out": out.positions.len(),
        "faces_out": out.face_count(),
    })
}
