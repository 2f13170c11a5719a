//! `--method highlight`: fairing a region of a triangle mesh with the highlight line model of seed
//! 001 ("Fairing Triangular Meshes with Highlight Line Model", Yong, Deng, Cheng, Wu).
//!
//! Stages (each timed in the report): `prepare` (connectivity, region, lights, movable set),
//! `model` (highlight lines, desired OGH curves and energies of the input), `fair` (Algorithm 2),
//! `metrics` (the same measures on the result, plus the usual smoothing measures).
//!
//! - [`lines`]: Algorithm 1 (eq. 1, 3, 4) and the polylines;
//! - [`target`]: desired lines (OGH curves, eq. 5, 12) and the deviation measures;
//! - [`fair`]: the energies (eq. 6–14), their Gauss–Newton QP and the iteration (eq. 15–17);
//! - [`qp`]: the bound-constrained QP solver.

pub mod fair;
pub mod lines;
pub mod qp;
pub mod target;

use serde_json::json;

use crate::error::{Error, Result};
use crate::geometry::{cross, dot, norm, normalize, scale, sub, Aabb};
use crate::job::{Output, Progress, Stages};
use crate::mesh::{Mesh, Point3};
use crate::metrics;

use super::SmoothParams;
use lines::{Adjacency, Lights};

/// Default N_max (the paper gives none).
pub const DEFAULT_ITERATIONS: u32 = 20;
/// Default ε of eq. 17 (the paper's value).
pub const DEFAULT_EPSILON: f64 = 1e-3;
/// Largest number of movable vertices (QP unknowns) accepted: the QP's Hessian couples two rings,
/// so memory grows ~50 entries per unknown and the method is meant for local regions (§5 of the
/// paper: "it may fail when the irregular region is relatively large").
pub const MAX_UNKNOWNS: usize = 50_000;
/// With the default spacing, about this many lights cross the region.
pub const DEFAULT_LINES: f64 = 16.0;

/// The region R as a vertex mask, from `region` (vertices), `region_faces`, `groups` or
/// `region_all`; an empty selection is an error (the method is local by design).
pub fn region(mesh: &Mesh, p: &SmoothParams) -> Result<Vec<bool>> {
    let n = mesh.vertex_count();
    if p.region_all {
        return Ok(vec![true; n]);
    }
    let mut r = vec![false; n];
    for &v in &p.region {
        if v as usize >= n {
            return Err(Error::params("region", format!("vertex {v} out of range (mesh has {n} vertices)")));
        }
        r[v as usize] = true;
    }
    for &f in &p.region_faces {
        if f as usize >= mesh.face_count() {
            return Err(Error::params(
                "region_faces",
                format!("face {f} out of range (mesh has {} faces)", mesh.face_count()),
            ));
        }
        for &v in mesh.faces.get(f as usize) {
            r[v as usize] = true;
        }
    }
    for name in &p.groups {
        let id = mesh.groups.iter().position(|g| g == name).ok_or_else(|| {
            Error::params("groups", format!("no face group named {name:?} (groups: {:?})", mesh.groups))
        })?;
        for fi in 0..mesh.face_count() {
            if mesh.faces.group(fi) as usize == id {
                for &v in mesh.faces.get(fi) {
                    r[v as usize] = true;
                }
            }
        }
    }
    if !r.iter().any(|&b| b) {
        return Err(Error::params(
            "region",
            "highlight fairing needs the region R to fair: `region` (vertex indices), `region_faces`, \
             `groups`, or `region_all: true`",
        ));
    }
    Ok(r)
}

fn unit(field: &str, v: [f64; 3]) -> Result<Point3> {
    if !v.iter().all(|c| c.is_finite()) || norm(v) == 0.0 {
        return Err(Error::params(field, format!("must be a finite non-zero vector, got {v:?}")));
    }
    Ok(normalize(v))
}

/// The lights from the params, defaults derived from the region (documented in docs/api.md):
/// normal = area-weighted mean normal of R's triangles; direction = the coordinate axis along
/// which R is longest once projected into the plane; origin = R's bounding-box centre moved one
/// bounding-box diagonal along the normal; spacing = (5th–95th percentile range of the highlight
/// distance over R) / 16.
pub fn lights(
    mesh: &Mesh,
    adj: &Adjacency,
    region: &[bool],
    p: &SmoothParams,
) -> Result<(Lights, Vec<&'static str>)> {
    let x = &mesh.positions;
    let mut defaults = Vec::new();
    let pts: Vec<Point3> = (0..x.len()).filter(|&v| region[v]).map(|v| x[v]).collect();
    let bb = Aabb::of(&pts).ok_or_else(|| Error::params("region", "empty region"))?;
    let given_dir = p.light_direction.map(|d| unit("light_direction", d)).transpose()?;
    let z = match p.light_normal {
        Some(z) => unit("light_normal", z)?,
        None => {
            defaults.push("light_normal");
            let mut s = [0.0; 3];
            for t in &adj.tris {
                if t.iter().all(|&v| region[v as usize]) {
                    let [a, b, c] = t.map(|v| x[v as usize]);
                    s = crate::geometry::add(s, cross(sub(b, a), sub(c, a)));
                }
            }
            // With a given direction, make the default normal perpendicular to it.
            if let Some(h) = given_dir {
                s = sub(s, scale(h, dot(s, h)));
            }
            if norm(s) <= 1e-9 * bb.diagonal().powi(2) {
                return Err(Error::params(
                    "light_normal",
                    "the region's normals cancel out (a closed region?): give `light_normal`",
                ));
            }
            normalize(s)
        }
    };
    let h = match given_dir {
        Some(h) => {
            if dot(h, z).abs() > 1e-6 {
                return Err(Error::params(
                    "light_direction",
                    format!(
                        "must lie in the light plane (perpendicular to light_normal {z:?}); its component \
                         along the normal is {}",
                        dot(h, z)
                    ),
                ));
            }
            normalize(sub(h, scale(z, dot(h, z))))
        }
        None => {
            defaults.push("light_direction");
            let ext = sub(bb.max, bb.min);
            let mut best = ([0.0; 3], -1.0);
            for k in 0..3 {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                let proj = sub(e, scale(z, dot(e, z)));
                let len = ext[k] * norm(proj);
                if norm(proj) > 1e-6 && len > best.1 {
                    best = (normalize(proj), len);
                }
            }
            best.0
        }
    };
    let origin = match p.light_origin {
        Some(o) => {
            if !o.iter().all(|c| c.is_finite()) {
                return Err(Error::params("light_origin", "must be finite"));
            }
            o
        }
        None => {
            defaults.push("light_origin");
            crate::geometry::add(bb.center(), scale(z, bb.diagonal().max(1e-300)))
        }
    };
    let mut l = Lights { normal: z, direction: h, origin, spacing: 1.0 };
    l.spacing = match p.light_spacing {
        Some(s) => {
            if !(s.is_finite() && s > 0.0) {
                return Err(Error::params("light_spacing", format!("must be a positive distance, got {s}")));
            }
            s
        }
        None => {
            defaults.push("light_spacing");
            let d = lines::distances(adj, x, &l);
            // Robust range (5th–95th percentile): near-grazing normals send d towards ±∞.
            let mut ds: Vec<f64> = (0..x.len()).filter(|&v| region[v]).filter_map(|v| d[v]).collect();
            ds.sort_by(f64::total_cmp);
            let (lo, hi) = match ds.len() {
                0 => (0.0, 0.0),
                k => (ds[k * 5 / 100], ds[(k * 95 / 100).min(k - 1)]),
            };
            if !(hi > lo) {
                return Err(Error::params(
                    "light_spacing",
                    "cannot derive a default: the highlight distance is undefined or constant over the region",
                ));
            }
            (hi - lo) / DEFAULT_LINES
        }
    };
    Ok((l, defaults))
}

fn positive(field: &str, v: Option<f64>, default: f64) -> Result<f64> {
    let v = v.unwrap_or(default);
    if !(v.is_finite() && v >= 0.0) {
        return Err(Error::params(field, format!("must be a finite number ≥ 0, got {v}")));
    }
    Ok(v)
}

fn lines_json(model: &lines::Model) -> serde_json::Value {
    json!(lines::polylines(model)
        .into_iter()
        .map(|(m, pts)| json!({"light": m, "points": pts}))
        .collect::<Vec<_>>())
}

/// Runs the highlight fairing job.
pub fn run(mesh: Mesh, p: &SmoothParams, progress: &Progress) -> Result<Output> {
    let r = p.resolve()?;
    let w = Weights::of(p)?;
    let mut stages = Stages::new();
    let (adj, setup, defaults) = stages.run(progress, "prepare", || prepare(&mesh, p, &w))?;
    let x0 = &mesh.positions;
    let before = stages.run(progress, "model", || Ok(measure(&adj, x0, &setup)))?;
    let outcome = stages.run(progress, "fair", || {
        fair::iterate(&adj, x0, &setup, r.iterations as usize, w.epsilon, progress)
    })?;
    let mut report = stages.run(progress, "metrics", || {
        let measured = Measured { mesh: &mesh, adj: &adj, setup: &setup, before: &before, outcome: &outcome };
        job_report(&measured, p, &r, &w, defaults, progress)
    })?;
    report["total_ms"] = json!(stages.total_ms());
    report["stages"] = stages.to_json();
    let mut out = mesh.clone();
    if out.normals.is_some() {
        out.normals = Some(adj.normals(&outcome.x));
    }
    out.positions = outcome.x;
    Ok(Output { meshes: vec![out], report, ..Default::default() })
}

/// The weights and bounds of Algorithm 2, checked.
struct Weights {
    /// Convergence threshold ε on the relative energy decrease.
    epsilon: f64,
    fair: f64,
    highlight: f64,
    /// Largest step as a fraction of the local edge length (≤ 0.5, §3.6).
    max_step_fraction: f64,
}

impl Weights {
    fn of(p: &SmoothParams) -> Result<Weights> {
        let w = Weights {
            epsilon: positive("convergence_threshold", p.convergence_threshold, DEFAULT_EPSILON)?,
            fair: positive("fairness_weight", p.fairness_weight, 1.0)?,
            highlight: positive("highlight_weight", p.highlight_weight, 1.0)?,
            max_step_fraction: positive("max_step_fraction", p.max_step_fraction, 0.5)?,
        };
        if w.max_step_fraction > 0.5 {
            return Err(Error::params("max_step_fraction", "at most 0.5 (the paper's bound, §3.6)"));
        }
        if w.fair == 0.0 && w.highlight == 0.0 {
            return Err(Error::params("fairness_weight", "fairness_weight and highlight_weight are both 0"));
        }
        Ok(w)
    }
}

/// Adjacency, region, pinned vertices and lights, and the setup of the optimisation; refuses a
/// problem too large for this local method or with nothing allowed to move. Also returns which
/// light settings were defaults.
fn prepare(
    mesh: &Mesh,
    p: &SmoothParams,
    w: &Weights,
) -> Result<(Adjacency, fair::Setup, Vec<&'static str>)> {
    let adj = Adjacency::new(mesh)?;
    let region = region(mesh, p)?;
    let pinned = pinned_mask(&p.pinned, mesh.vertex_count())?;
    let (lights, defaults) = lights(mesh, &adj, &region, p)?;
    let setup = fair::Setup::new(
        &adj,
        &mesh.positions,
        region,
        &pinned,
        lights,
        w.fair,
        w.highlight,
        w.max_step_fraction,
    );
    if setup.vars.len() > MAX_UNKNOWNS {
        return Err(Error::TooLarge {
            what: "highlight fairing: movable vertices (the method is local; select a smaller region)".into(),
            limit: MAX_UNKNOWNS as u64,
            actual: setup.vars.len() as u64,
        });
    }
    if setup.vars.is_empty() {
        return Err(Error::params(
            "region",
            format!(
                "no movable vertex: a vertex moves only when it is at least 3 edges away from every \
                 vertex outside R and from the mesh boundary (seed 001 §3.1); the region has {} \
                 vertices — select a larger one",
                setup.region.iter().filter(|b| **b).count()
            ),
        ));
    }
    Ok((adj, setup, defaults))
}

/// `pinned` as a per-vertex mask; an index past the mesh is a parameter error naming it.
fn pinned_mask(pinned: &[u32], n: usize) -> Result<Vec<bool>> {
    let mut mask = vec![false; n];
    for &v in pinned {
        if v as usize >= n {
            return Err(Error::params("pinned", format!("vertex {v} out of range (mesh has {n} vertices)")));
        }
        mask[v as usize] = true;
    }
    Ok(mask)
}

/// What the report is made from.
struct Measured<'a> {
    mesh: &'a Mesh,
    adj: &'a Adjacency,
    setup: &'a fair::Setup,
    before: &'a Measure,
    outcome: &'a fair::Outcome,
}

/// The job's report: parameters, the highlight and fairness measures before and after, how far
/// vertices moved, shape changes, the iteration history and warnings.
fn job_report(
    m: &Measured,
    p: &SmoothParams,
    r: &super::params::Resolved,
    w: &Weights,
    defaults: Vec<&'static str>,
    progress: &Progress,
) -> Result<serde_json::Value> {
    let (x0, x, f, setup, before) = (&m.mesh.positions, &m.outcome.x, &m.mesh.faces, m.setup, m.before);
    let outcome = m.outcome;
    let after = measure(m.adj, x, setup);
    progress.check()?;
    let (max_d, _) = metrics::displacement(x0, x);
    let moved: Vec<f64> =
        (0..x.len()).filter(|&v| x[v] != x0[v]).map(|v| crate::geometry::dist(x[v], x0[v])).collect();
    let mean_moved = if moved.is_empty() { 0.0 } else { moved.iter().sum::<f64>() / moved.len() as f64 };
    let (a0, a1) = (metrics::angle_stats(x0, f), metrics::angle_stats(x, f));
    let center = Aabb::of(x0).map(|b| b.center()).unwrap_or([0.0; 3]);
    let (v0, v1) = (metrics::volume_about(x0, f, center), metrics::volume_about(x, f, center));
    progress.check()?;
    let hausdorff =
        if r.hausdorff { Some(crate::spatial::hausdorff_vertices(x0, f, x, f, progress)?) } else { None };
    let mut rep = json!({
        "method": "highlight",
        "params": {
            "iterations": r.iterations,
            "convergence_threshold": w.epsilon,
            "fairness_weight": w.fair,
            "highlight_weight": w.highlight,
            "max_step_fraction": w.max_step_fraction,
        },
        "lights": setup.lights,
        "light_defaults_used": defaults,
        "vertices": m.mesh.vertex_count(),
        "faces": m.mesh.face_count(),
        "region_vertices": setup.region.iter().filter(|b| **b).count(),
        "movable_vertices": setup.vars.len(),
        "energy_vertices": setup.energy_vertices.len(),
        "vertices_moved": moved.len(),
        "mean_edge_length_region": setup.e,
        "iterations": outcome.steps.len(),
        "stop_reason": outcome.stop_reason,
        "history": outcome.steps,
        "steps_halved_for_shape": outcome.flips_prevented,
        "max_step_bound_use": outcome.max_bound_use,
        "highlight_before": summary(before),
        "highlight_after": summary(&after),
        "highlight_deviation_before": before.deviation,
        "highlight_deviation_after": after.deviation,
        "willmore_before": before.willmore,
        "willmore_after": after.willmore,
        "willmore_change": metrics::relative_change(before.willmore, after.willmore),
        "mean_curvature_std_before": before.h_std,
        "mean_curvature_std_after": after.h_std,
        "max_displacement": max_d,
        "max_displacement_relative": if setup.e > 0.0 { max_d / setup.e } else { 0.0 },
        "mean_displacement_moved": mean_moved,
        "volume_change": metrics::relative_change(v0, v1),
        "area_change": metrics::relative_change(metrics::area(x0, f), metrics::area(x, f)),
        "hausdorff": hausdorff,
        "min_angle_before": a0.min,
        "min_angle_after": a1.min,
        "mean_min_angle_before": a0.mean_min,
        "mean_min_angle_after": a1.mean_min,
        "flipped_faces": metrics::flipped_faces(x0, x, f),
        "solver": {
            "kind": "box_qp_gradient_projection_cg",
            "unknowns": outcome.qp_unknowns,
            "nonzeros": outcome.qp_nonzeros,
        },
        "warnings": warnings(before),
    });
    if p.highlight_lines {
        rep["highlight_lines"] =
            json!({"before": lines_json(&before.model), "after": lines_json(&after.model)});
    }
    Ok(rep)
}

/// What the user should know about the start state: no highlight line to fair, or vertices the
/// lights cannot measure.
fn warnings(before: &Measure) -> Vec<String> {
    let mut warnings = Vec::new();
    if before.runs.runs.is_empty() {
        warnings.push(
            "no highlight line crosses the movable part of the region: only the fairness term acts \
             (move or densify the lights: light_spacing, light_origin)"
                .to_string(),
        );
    }
    if before.model.invalid_vertices > 0 {
        warnings.push(format!(
            "{} vertices have normals (nearly) parallel to the light plane: no highlight distance there",
            before.model.invalid_vertices
        ));
    }
    warnings
}

/// Highlight model and energies of one state.
pub struct Measure {
    pub model: lines::Model,
    pub runs: target::Runs,
    pub deviation: target::Deviation,
    pub willmore: f64,
    pub h_std: f64,
}

pub fn measure(adj: &Adjacency, x: &[Point3], setup: &fair::Setup) -> Measure {
    let model = lines::model(adj, x, &setup.lights);
    let runs = setup.runs(adj, &model);
    let deviation = target::deviation(&model, &runs, setup.e);
    let (willmore, h_std) = fair::willmore(adj, x, setup);
    Measure { model, runs, deviation, willmore, h_std }
}

fn summary(m: &Measure) -> serde_json::Value {
    json!({
        "lines": m.model.lines.len(),
        "nodes": m.model.nodes.len(),
        "invalid_vertices": m.model.invalid_vertices,
        "skipped_edges": m.model.skipped_edges,
        "runs": m.runs.runs.len(),
        "untargeted_runs": m.runs.untargeted,
        "tangent_fallbacks": m.runs.tangent_fallbacks,
    })
}
