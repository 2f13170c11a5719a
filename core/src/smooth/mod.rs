//! The smooth job: explicit Laplacian and Taubin, implicit (backward Euler) diffusion, mean-curvature
//! flow, k-harmonic fairing, seed 004 shape inflation, seed 000 tangential flows.
//!
//! Every method works on one [`crate::laplacian::Operator`] (`L = D⁻¹S`, see that module for the
//! conventions) and one [`constraints::Freedom`] (which vertices move, with which weight). The
//! implicit methods solve `(D/w + hS) x = (D/w) x₀` over the moving vertices (fixed ones
//! eliminated), which is symmetric positive definite for every operator: the seed's sign slip in
//! eq. 3-8/4-2 (`I − λL` with a PSD `L`) is fixed by construction.

pub mod constraints;
pub mod highlight;
mod methods;
pub mod params;
pub mod system;

use serde_json::json;

pub use params::{BoundaryMode, Method, SmoothParams};

use crate::error::{Error, Result};
use crate::job::{Output, Progress, Stages};
use crate::laplacian::{self, Operator, Stencil};
use crate::mesh::{Mesh, Point3};
use crate::metrics;
use params::Resolved;
use system::SolverStats;

/// Everything a method needs, prepared once.
pub(crate) struct Ctx<'a> {
    pub mesh: &'a Mesh,
    pub r: &'a Resolved,
    pub progress: &'a Progress,
    pub stencil: Stencil,
    pub op: Operator,
    pub boundary: Vec<bool>,
    pub free: constraints::Freedom,
    /// Mean edge length of the input (the length unit of relative time steps).
    pub edge_len: f64,
    pub center: Point3,
    pub volume0: f64,
    pub solver: SolverStats,
    pub warnings: Vec<String>,
}

/// The largest implicit step, in mean edge lengths squared for the area-scaled operators (in the
/// operator's own units for the others): beyond it the mass term `D/h` of `D/h + S` is lost in the
/// round-off of `S`, whose rows sum to 0, and the Cholesky fails (homer with `time_step` 1e20,
/// suzanne with `inflate` `lambda` 1e308); every component has long reached its centroid anyway.
pub const MAX_RELATIVE_STEP: f64 = 1e12;

impl Ctx<'_> {
    /// The time step in the units of the operator (see `SmoothParams::time_step`).
    pub fn effective_step(&self, h: f64) -> f64 {
        if self.r.relative_time_step && self.r.operator.area_scaled() {
            h * self.edge_len * self.edge_len
        } else {
            h
        }
    }

    /// [`Ctx::effective_step`] of the implicit methods, refused by parameter name when it is
    /// beyond [`MAX_RELATIVE_STEP`].
    pub fn implicit_step(&self, field: &str, h: f64) -> Result<f64> {
        let step = self.effective_step(h);
        let area_scaled = self.r.operator.area_scaled();
        let unit = self.edge_len * self.edge_len;
        let (relative, units) = match (area_scaled, self.r.relative_time_step) {
            (true, true) => (h, " mean edge lengths squared"),
            (true, false) => (if unit > 0.0 { step / unit } else { 0.0 }, " mean edge lengths squared"),
            (false, _) => (step, ""),
        };
        if !(relative <= MAX_RELATIVE_STEP) {
            return Err(Error::params(
                field,
                format!(
                    "the implicit step is {relative:e}{units}, beyond {MAX_RELATIVE_STEP:e}: its system \
                     is numerically singular (every component would collapse to its centroid); use a \
                     smaller value"
                ),
            ));
        }
        Ok(step)
    }

    /// Applies the axis mask and volume preservation after a step from `before`.
    pub fn finish_step(&self, x: &mut [Point3], before: &[Point3]) {
        constraints::apply_axes(x, before, self.r.axes);
        if self.r.preserve_volume {
            constraints::preserve_volume(self.mesh, x, &self.free.moving, self.center, self.volume0);
        }
    }

    /// Reports progress of step `k` of `n` and checks for cancellation.
    pub fn tick(&self, k: usize, n: usize) -> Result<()> {
        self.progress.fraction(k as f64 / n.max(1) as f64)
    }
}

/// Runs the smooth job on `mesh`.
pub fn run(mesh: Mesh, params: &SmoothParams, progress: &Progress) -> Result<Output> {
    if params.method == Method::Highlight {
        return highlight::run(mesh, params, progress);
    }
    let r = params.resolve()?;
    let mut stages = Stages::new();
    if mesh.faces.is_empty() {
        return Err(Error::InvalidMesh {
            location: crate::error::Location::Face(0),
            message: "the mesh has no faces to smooth".into(),
        });
    }
    let n = mesh.vertex_count();
    let (stencil, op) = stages.run(progress, "assemble", || {
        // The umbrella needs no per-pair weights: its stencil is the cheap topological one.
        let st = if r.operator == laplacian::OperatorKind::Uniform {
            Stencil::uniform(&mesh.faces, n)?
        } else {
            Stencil::new(&mesh.faces, n, laplacian::layout_for(r.operator, &mesh.faces))?
        };
        let op = laplacian::assemble(&mesh.positions, &mesh.faces, &st, r.operator, r.mass);
        Ok((st, op))
    })?;
    let mut ctx = stages.run(progress, "prepare", || {
        let boundary = stencil.boundary_vertices();
        let free =
            constraints::freedom(&mesh, params, r.boundary, &boundary, &op.locked, r.method == Method::Fair)?;
        let edge_len = laplacian::mean_edge_length(&stencil, &mesh.positions);
        let center = centroid(&mesh.positions);
        let volume0 = metrics::volume_about(&mesh.positions, &mesh.faces, center);
        Ok(Ctx {
            mesh: &mesh,
            r: &r,
            progress,
            stencil,
            op,
            boundary,
            free,
            edge_len,
            center,
            volume0,
            solver: SolverStats { kind: "none".into(), ..Default::default() },
            warnings: Vec::new(),
        })
    })?;
    let x = stages.run(progress, "smooth", || methods::run(&mut ctx))?;
    let report = stages.run(progress, "metrics", || report(&ctx, &x))?;
    let mut report = report;
    let obj = report.as_object_mut().ok_or_else(|| Error::Internal("report".into()))?;
    obj.insert("total_ms".into(), json!(stages.total_ms()));
    obj.insert("stages".into(), stages.to_json());
    drop(ctx);
    // The input is ours: hand it back with the new positions (no copy of the faces).
    let mut out = mesh;
    if out.normals.is_some() {
        out.normals = Some(vertex_normals(&x, &out));
    }
    out.positions = x;
    Ok(Output { meshes: vec![out], report, ..Default::default() })
}

fn centroid(x: &[Point3]) -> Point3 {
    let mut c = [0.0; 3];
    for p in x {
        for k in 0..3 {
            c[k] += p[k];
        }
    }
    let n = x.len().max(1) as f64;
    [c[0] / n, c[1] / n, c[2] / n]
}

/// Area-weighted vertex normals (seed 001 eq. 3), unit length.
pub fn vertex_normals(x: &[Point3], mesh: &Mesh) -> Vec<Point3> {
    let mut nr = vec![[0.0; 3]; x.len()];
    for f in mesh.faces.iter() {
        let fnorm = metrics::face_normal(x, f);
        for &v in f {
            let a = &mut nr[v as usize];
            for k in 0..3 {
                a[k] += fnorm[k];
            }
        }
    }
    nr.into_iter().map(crate::geometry::normalize).collect()
}

fn report(ctx: &Ctx, x: &[Point3]) -> Result<serde_json::Value> {
    let mesh = ctx.mesh;
    let x0 = &mesh.positions;
    let f = &mesh.faces;
    let (max_d, mean_d) = metrics::displacement(x0, x);
    // One fused pass over the triangles for both states (areas, volume, angles, flips, curvature).
    let q = metrics::compare(x0, x, f, ctx.center, &ctx.boundary, ctx.r.report_curvature, ctx.progress)?;
    let (a0, a1) = (q.before.angles, q.after.angles);
    let vol1 = q.after.volume;
    let (area0, area1) = (q.before.area, q.after.area);
    let (h0, h1) = (q.before.mean_curvature, q.after.mean_curvature);
    let hausdorff = if ctx.r.hausdorff {
        Some(crate::spatial::hausdorff_vertices(x0, f, x, f, ctx.progress)?)
    } else {
        None
    };
    let diag = crate::geometry::Aabb::of(x0).map(|b| b.diagonal()).unwrap_or(0.0);
    let moving = ctx.free.moving.iter().filter(|m| **m).count();
    Ok(json!({
        "method": ctx.r.method,
        "operator": ctx.r.operator,
        "params": ctx.r,
        "vertices": mesh.vertex_count(),
        "faces": mesh.face_count(),
        "moving_vertices": moving,
        "pinned_vertices": ctx.free.pinned_count,
        "feature_vertices": ctx.free.feature_vertices,
        "boundary_vertices": ctx.boundary.iter().filter(|b| **b).count(),
        "locked_vertices": ctx.op.locked.iter().filter(|b| **b).count(),
        "degenerate_triangles": ctx.op.degenerate_triangles,
        "nonmanifold_edges": ctx.stencil.nonmanifold_edges(),
        "mean_edge_length": ctx.edge_len,
        "time_step_effective": ctx.effective_step(ctx.r.time_step),
        "volume_before": ctx.volume0,
        "volume_after": vol1,
        "volume_change": metrics::relative_change(ctx.volume0, vol1),
        "area_change": metrics::relative_change(area0, area1),
        "max_displacement": max_d,
        "mean_displacement": mean_d,
        "hausdorff": hausdorff,
        "hausdorff_relative": hausdorff.map(|h| if diag > 0.0 { h / diag } else { 0.0 }),
        "min_angle_before": a0.min,
        "min_angle_after": a1.min,
        "mean_min_angle_before": a0.mean_min,
        "mean_min_angle_after": a1.mean_min,
        "max_angle_before": a0.max,
        "max_angle_after": a1.max,
        "flipped_faces": q.flipped_faces,
        "mean_curvature_before": h0,
        "mean_curvature_after": h1,
        "solver": ctx.solver,
        "warnings": ctx.warnings,
    }))
}
