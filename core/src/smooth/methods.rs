//! The seven methods, each a loop over steps on the prepared [`Ctx`].

use rayon::prelude::*;

use super::params::{BoundaryMode, Method};
use super::system::{self, estimated_cg_iterations, shifted, System};
use super::Ctx;
use crate::error::{Error, Result};
use crate::geometry::{add, dot, normalize, scale, sub};
use crate::laplacian::{self, Csr, OperatorKind, PairLayout, Stencil};
use crate::mesh::{Point3, MAX_COORDINATE};
use crate::solve::SolverChoice;
use crate::spatial::Bvh;

pub(super) fn run(ctx: &mut Ctx) -> Result<Vec<Point3>> {
    let mut x = ctx.mesh.positions.clone();
    match ctx.r.method {
        Method::Laplacian | Method::Taubin => {
            let rows = explicit_rows(ctx);
            let gain = explicit_gain(ctx);
            let n = ctx.r.iterations as usize;
            let factors: &[f64] =
                if ctx.r.method == Method::Taubin { &[ctx.r.lambda, ctx.r.mu] } else { &[ctx.r.lambda] };
            let mut out = x.clone();
            let keep_before = ctx.r.axes != [true; 3];
            for it in 0..n {
                ctx.tick(it, n)?;
                let before = if keep_before { x.clone() } else { Vec::new() };
                for &f in factors {
                    explicit_step(&rows, gain.as_deref(), &x, &mut out, f);
                    std::mem::swap(&mut x, &mut out);
                }
                if keep_before || ctx.r.preserve_volume {
                    ctx.finish_step(&mut x, &before);
                }
            }
        }
        Method::Implicit => implicit(ctx, &mut x, false)?,
        Method::Mcf => implicit(ctx, &mut x, true)?,
        Method::Inflate => inflate(ctx, &mut x)?,
        Method::Fair => fair(ctx, &mut x)?,
        Method::Tangential => tangential(ctx, &mut x)?,
        // Dispatched before the shared preparation (its own pipeline: smooth::highlight).
        Method::Highlight => return Err(Error::Internal("highlight reached the Laplacian methods".into())),
    }
    Ok(x)
}

/// Normalised explicit rows: `R = diag(S)⁻¹ S` (diagonal 1), boundary curve rows (½ of eq. 4-3,
/// times `lambda_border`) in curve mode. One matrix for every operator, so λ ∈ (0, 1] is stable
/// whatever the weights and the model's scale.
fn explicit_rows<'a>(ctx: &'a Ctx) -> Rows<'a> {
    let s = &ctx.op.stiffness;
    if ctx.op.kind == OperatorKind::Uniform
        && ctx.r.boundary != BoundaryMode::Curve
        && ctx.stencil.layout == PairLayout::Edges
    {
        return Rows::Umbrella(&ctx.stencil.pattern);
    }
    let mut r = s.clone();
    let curve = (ctx.r.boundary == BoundaryMode::Curve)
        .then(|| laplacian::boundary_curve_rows(&ctx.stencil, &ctx.mesh.positions, 1e-12 * ctx.edge_len));
    let diag = s.diagonal();
    for i in 0..s.n {
        let (a, b) = (r.row_ptr[i] as usize, r.row_ptr[i + 1] as usize);
        if let Some(Some(row)) = curve.as_ref().map(|c| &c[i]) {
            for p in a..b {
                let j = r.col[p] as usize;
                r.val[p] = if j == i {
                    ctx.r.lambda_border
                } else {
                    row.iter().find(|e| e.0 == j).map(|e| 0.5 * e.1 * ctx.r.lambda_border).unwrap_or(0.0)
                };
            }
        } else {
            let inv = if diag[i] > 0.0 { 1.0 / diag[i] } else { 0.0 };
            for v in &mut r.val[a..b] {
                *v *= inv;
            }
        }
    }
    Rows::General(r)
}

/// The explicit operator: general normalised rows, or the umbrella (uniform weights, no curve
/// rows) read straight from the stencil's pattern: its off-diagonal entries are all −1/valence,
/// so only column indices are read (half the memory traffic of a valued matrix).
enum Rows<'a> {
    General(Csr),
    Umbrella(&'a Csr),
}

/// Per-vertex step gain (soft weight, 0 for fixed vertices); `None` when every vertex moves with
/// weight 1, so the common case reads nothing per vertex but the positions and the rows.
fn explicit_gain(ctx: &Ctx) -> Option<Vec<f64>> {
    let (moving, w) = (&ctx.free.moving, &ctx.free.weight);
    if moving.iter().zip(w).all(|(&m, &w)| m && w == 1.0) {
        return None;
    }
    Some(moving.iter().zip(w).map(|(&m, &w)| if m { w } else { 0.0 }).collect())
}

/// `out_i = x_i − f·g_i·(R x)_i` (Jacobi update into a second buffer, so one pass over the rows
/// and the positions per step); `g` = [`explicit_gain`].
fn explicit_step(rows: &Rows, gain: Option<&[f64]>, x: &[Point3], out: &mut [Point3], f: f64) {
    let kernel = |(i, o): (usize, &mut Point3)| {
        let xi = x[i];
        let g = gain.map_or(1.0, |g| g[i]);
        if g == 0.0 {
            *o = xi;
            return;
        }
        let s = f * g;
        match rows {
            Rows::General(r) => {
                let (a, b) = (r.row_ptr[i] as usize, r.row_ptr[i + 1] as usize);
                let mut acc = [0.0f64; 3];
                for (&j, &v) in r.col[a..b].iter().zip(&r.val[a..b]) {
                    let xj = x[j as usize];
                    acc[0] += v * xj[0];
                    acc[1] += v * xj[1];
                    acc[2] += v * xj[2];
                }
                *o = [xi[0] - s * acc[0], xi[1] - s * acc[1], xi[2] - s * acc[2]];
            }
            Rows::Umbrella(p) => {
                let (a, b) = (p.row_ptr[i] as usize, p.row_ptr[i + 1] as usize);
                let valence = (b - a - 1) as f64; // the row holds the diagonal too
                if valence == 0.0 {
                    *o = xi;
                    return;
                }
                let mut acc = [0.0f64; 3];
                for &j in &p.col[a..b] {
                    let xj = x[j as usize];
                    acc[0] += xj[0];
                    acc[1] += xj[1];
                    acc[2] += xj[2];
                }
                // (R x)_i = x_i − mean of the neighbours; the sum included x_i itself.
                let t = s / valence;
                let c = 1.0 - s - t;
                *o = [c * xi[0] + t * acc[0], c * xi[1] + t * acc[1], c * xi[2] + t * acc[2]];
            }
        }
    };
    if x.len() >= 20_000 {
        out.par_iter_mut().enumerate().with_min_len(4096).for_each(kernel);
    } else {
        out.iter_mut().enumerate().for_each(kernel);
    }
}

/// Scale `d/w` of the implicit system (fixed vertices keep `d`; their rows are eliminated).
fn weighted_scale(ctx: &Ctx, d: &[f64]) -> Vec<f64> {
    let mean = {
        let (s, c) = d.iter().filter(|v| **v > 0.0).fold((0.0, 0), |(s, c), v| (s + v, c + 1));
        if c > 0 {
            s / c as f64
        } else {
            1.0
        }
    };
    d.iter()
        .zip(&ctx.free.weight)
        .zip(&ctx.free.moving)
        .map(|((&d, &w), &m)| {
            let d = if d > 0.0 { d } else { mean };
            if m {
                d / w
            } else {
                d
            }
        })
        .collect()
}

/// Resolves `auto` to Cholesky or CG for a system of `unknowns` run `steps` times.
fn choose_solver(ctx: &Ctx, s: &Csr, d: &[f64], h: f64, moving: &[bool], steps: usize) -> SolverChoice {
    match ctx.r.solver {
        SolverChoice::Auto => {
            let unknowns = moving.iter().filter(|m| **m).count();
            if unknowns < system::AUTO_CG_MIN_UNKNOWNS {
                return SolverChoice::Cholesky;
            }
            let it = estimated_cg_iterations(s, d, h, moving, ctx.r.cg_tolerance) * steps as f64;
            if it <= system::AUTO_CG_MAX_TOTAL_ITERATIONS {
                SolverChoice::Cg
            } else {
                SolverChoice::Cholesky
            }
        }
        c => c,
    }
}

/// Vertices the interior implicit system solves for (curve-mode boundaries are solved apart).
fn interior_moving(ctx: &Ctx) -> Vec<bool> {
    let curve = ctx.r.boundary == BoundaryMode::Curve;
    ctx.free.moving.iter().zip(&ctx.boundary).map(|(&m, &b)| m && !(curve && b)).collect()
}

/// One implicit step of the boundary curves (eq. 4-3 corrected), symmetrised by `E_i/2`:
/// `(diag(E/2w) + h·G) x_B = diag(E/2w) x_B⁰` with `G` the graph Laplacian of inverse lengths.
fn boundary_curve_step(ctx: &Ctx, x: &mut [Point3], h: f64) -> Result<()> {
    let rows = laplacian::boundary_curve_rows(&ctx.stencil, x, 1e-12 * ctx.edge_len);
    let st = &ctx.stencil.pattern;
    let n = st.n;
    let mut a = Csr { n, row_ptr: st.row_ptr.clone(), col: st.col.clone(), val: vec![0.0; st.nnz()] };
    let mut d = vec![1.0; n];
    let mut moving = vec![false; n];
    for i in 0..n {
        let Some(Some(row)) = rows.get(i) else { continue };
        if row.is_empty() || !ctx.free.moving[i] {
            continue;
        }
        moving[i] = true;
        // Recover e_ij and E_i from B_ij = −2 e_ij / E_i: the row's inverse lengths.
        let inv: Vec<(usize, f64)> = ctx
            .stencil
            .boundary_neighbours(i)
            .map(|j| (j, 1.0 / crate::geometry::dist(x[i], x[j]).max(1e-300)))
            .filter(|(j, _)| row.iter().any(|e| e.0 == *j))
            .collect();
        let e: f64 = inv.iter().map(|v| v.1).sum();
        d[i] = 0.5 * e / ctx.free.weight[i];
        for p in st.row_ptr[i] as usize..st.row_ptr[i + 1] as usize {
            let j = st.col[p] as usize;
            if j == i {
                a.val[p] = d[i] + h * ctx.r.lambda_border * e;
            } else if let Some(&(_, eij)) = inv.iter().find(|v| v.0 == j) {
                a.val[p] = -h * ctx.r.lambda_border * eij;
            }
        }
    }
    if !moving.iter().any(|m| *m) {
        return Ok(());
    }
    // Rows of non-boundary vertices are identity (eliminated anyway); keep A symmetric by also
    // zeroing curve entries towards them (they are zero already: only boundary neighbours set).
    let b: Vec<Point3> = x.iter().zip(&d).map(|(p, &d)| scale(*p, d)).collect();
    let mut sys = System::new(a, &moving, SolverChoice::Cholesky, ctx.r.cg_tolerance);
    sys.solve(&b, x, ctx.progress)
}

fn implicit(ctx: &mut Ctx, x: &mut Vec<Point3>, reassemble: bool) -> Result<()> {
    let h = ctx.implicit_step("time_step", ctx.r.time_step)?;
    let moving = interior_moving(ctx);
    let d = weighted_scale(ctx, &ctx.op.scale);
    let steps = ctx.r.iterations as usize;
    let choice = choose_solver(ctx, &ctx.op.stiffness, &d, h, &moving, steps);
    let mut sys = System::new(shifted(&ctx.op.stiffness, &d, h), &moving, choice, ctx.r.cg_tolerance);
    let mut d = d;
    for it in 0..steps {
        ctx.tick(it, steps)?;
        let before = x.clone();
        if reassemble && it > 0 {
            let op = laplacian::assemble(x, &ctx.mesh.faces, &ctx.stencil, OperatorKind::Cotan, ctx.r.mass);
            d = weighted_scale(ctx, &op.scale);
            sys.update(shifted(&op.stiffness, &d, h));
        }
        if ctx.r.boundary == BoundaryMode::Curve {
            boundary_curve_step(ctx, x, h)?;
        }
        let b: Vec<Point3> = x.iter().zip(&d).map(|(p, &d)| scale(*p, d)).collect();
        match sys.solve(&b, x, ctx.progress) {
            // The operator was assembled on the flow's own output: mean curvature flow pinches thin
            // parts and shrinks closed meshes to a point, and the collapsed faces make the system
            // singular. That is what the parameters asked of this mesh, not a failure on our side.
            Err(Error::Numerical { message, .. }) if reassemble && it > 0 => {
                return Err(Error::params(
                    "iterations",
                    format!(
                        "mean curvature flow collapsed parts of the mesh at step {} of {steps} (the \
                         re-assembled system is singular: {message}); use fewer `iterations` or a \
                         smaller `time_step`",
                        it + 1
                    ),
                ));
            }
            r => r?,
        }
        ctx.finish_step(x, &before);
    }
    ctx.solver = sys.stats;
    Ok(())
}

/// Seed 004 eq. 3-8 with the sign fixed: solve the smoothing step with |λ|, then move by
/// sign(λ)·(x' − x): λ < 0 exaggerates (inflates) the shape, λ > 0 smooths it.
fn inflate(ctx: &mut Ctx, x: &mut Vec<Point3>) -> Result<()> {
    let lambda = ctx.r.lambda;
    if lambda == 0.0 {
        return Ok(());
    }
    if ctx.r.iterations > 3 && lambda < 0.0 {
        ctx.warnings.push("inflation with more than 3 iterations is unstable (seed 004 §3.4.2)".into());
    }
    let h = ctx.implicit_step("lambda", lambda.abs())?;
    let moving = interior_moving(ctx);
    let d = weighted_scale(ctx, &ctx.op.scale);
    let steps = ctx.r.iterations as usize;
    let choice = choose_solver(ctx, &ctx.op.stiffness, &d, h, &moving, steps);
    let mut sys = System::new(shifted(&ctx.op.stiffness, &d, h), &moving, choice, ctx.r.cg_tolerance);
    for it in 0..steps {
        ctx.tick(it, steps)?;
        let before = x.clone();
        let mut smooth = x.clone();
        if ctx.r.boundary == BoundaryMode::Curve {
            boundary_curve_step(ctx, &mut smooth, h)?;
        }
        let b: Vec<Point3> = x.iter().zip(&d).map(|(p, &d)| scale(*p, d)).collect();
        sys.solve(&b, &mut smooth, ctx.progress)?;
        let sign = lambda.signum();
        for (p, s) in x.iter_mut().zip(&smooth) {
            *p = add(*p, scale(sub(*s, *p), sign));
        }
        ctx.finish_step(x, &before);
        // Inflation grows geometrically; unchecked, 10,000 steps on suzanne gave NaN positions
        // that the writer then blamed on the mesh ("invalid mesh at vertex 0").
        let blown = x.iter().position(|p| p.iter().any(|c| !(c.abs() <= MAX_COORDINATE)));
        if let Some(v) = blown {
            return Err(Error::params(
                "iterations",
                format!(
                    "inflation diverged at step {} of {steps}: vertex {v} went beyond ±{MAX_COORDINATE:e} \
                     (inflating more than 3 steps is unstable, seed 004 §3.4.2); use fewer `iterations` or \
                     a smaller |lambda|",
                    it + 1
                ),
            ));
        }
    }
    ctx.solver = sys.stats;
    Ok(())
}

/// k-harmonic fairing: `S (D⁻¹S)^(k−1) x = 0` on the region, everything else fixed (Dirichlet).
/// The matrix is symmetric positive definite on the region when the region does not cover a
/// whole component; it is factored by Cholesky (CG converges slowly on k ≥ 2).
fn fair(ctx: &mut Ctx, x: &mut Vec<Point3>) -> Result<()> {
    let moving = ctx.free.moving.clone();
    if !moving.iter().any(|m| *m) {
        ctx.warnings.push("the region has no movable vertex".into());
        return Ok(());
    }
    let s = &ctx.op.stiffness;
    let dinv: Vec<f64> = weighted_scale(ctx, &ctx.op.scale).iter().map(|d| 1.0 / d).collect();
    let k = ctx.r.order;
    let a = power_rows(s, &dinv, k, &moving);
    let choice = match ctx.r.solver {
        SolverChoice::Cg => SolverChoice::Cg,
        _ => SolverChoice::Cholesky,
    };
    ctx.tick(0, 1)?;
    let mut sys = System::new(a, &moving, choice, ctx.r.cg_tolerance);
    let b = vec![[0.0; 3]; x.len()];
    let before = x.clone();
    sys.solve(&b, x, ctx.progress).map_err(|e| match e {
        Error::Numerical { .. } => Error::numerical(
            "fair",
            "the fairing system is singular: the region must not cover a whole component (nothing to hold it)",
        ),
        e => e,
    })?;
    ctx.finish_step(x, &before);
    ctx.solver = sys.stats;
    Ok(())
}

/// Rows `i` (where `rows[i]`) of `S (D⁻¹S)^(k−1)`; other rows are identity. Symmetric on the
/// selected block because `S(D⁻¹S)^(k−1)` is.
fn power_rows(s: &Csr, dinv: &[f64], k: u32, rows: &[bool]) -> Csr {
    let n = s.n;
    let row_lists: Vec<Vec<(u32, f64)>> = (0..n)
        .into_par_iter()
        .with_min_len(256)
        .map_init(
            || (vec![0.0f64; n], vec![false; n], Vec::<u32>::new()),
            |(acc, seen, list), i| {
                if !rows[i] {
                    return vec![(i as u32, 1.0)];
                }
                let (c, v) = s.row(i);
                let mut cur: Vec<(u32, f64)> = c.iter().copied().zip(v.iter().copied()).collect();
                for _ in 1..k {
                    list.clear();
                    for &(j, a) in &cur {
                        let (cj, vj) = s.row(j as usize);
                        let f = a * dinv[j as usize];
                        for (&m, &b) in cj.iter().zip(vj) {
                            if !seen[m as usize] {
                                seen[m as usize] = true;
                                list.push(m);
                            }
                            acc[m as usize] += f * b;
                        }
                    }
                    list.sort_unstable();
                    cur = list.iter().map(|&m| (m, acc[m as usize])).collect();
                    for &m in list.iter() {
                        acc[m as usize] = 0.0;
                        seen[m as usize] = false;
                    }
                }
                cur
            },
        )
        .collect();
    let mut row_ptr = Vec::with_capacity(n + 1);
    row_ptr.push(0u32);
    let mut col = Vec::new();
    let mut val = Vec::new();
    for r in row_lists {
        for (c, v) in r {
            col.push(c);
            val.push(v);
        }
        row_ptr.push(col.len() as u32);
    }
    Csr { n, row_ptr, col, val }
}

/// Seed 000 §4.3: (1) modified mean-curvature flow: the curvature step projected on the tangent
/// plane (area-weighted vertex normal, seed 001 eq. 3), then dropped back onto the *current*
/// surface; (2) modified Laplacian flow: the umbrella step projected on the tangent plane of
/// the nearest face of the *input* surface, then dropped onto the input surface. The printed
/// projection `v − (v·n)v` (eq. 4.9/4.11) is read as `v − (v·n)n`, and each Laplacian step starts
/// from the current position (not p⁰), as the note explains.
fn tangential(ctx: &mut Ctx, x: &mut Vec<Point3>) -> Result<()> {
    let mesh = ctx.mesh;
    let k1 = ctx.r.mcf_iterations as usize;
    let k2 = ctx.r.iterations as usize;
    let total = k1 + k2;
    let h = ctx.effective_step(ctx.r.time_step);
    let moving = ctx.free.moving.clone();
    let w = ctx.free.weight.clone();
    for it in 0..k1 {
        ctx.tick(it, total)?;
        let before = x.clone();
        let op = laplacian::assemble(x, &mesh.faces, &ctx.stencil, ctx.r.operator, ctx.r.mass);
        let mut y = vec![0.0; 3 * x.len()];
        op.stiffness.mul_vec(x.as_flattened(), &mut y, 3);
        let normals = super::vertex_normals(x, mesh);
        ctx.progress.check()?;
        let bvh = Bvh::new_polled(x, &mesh.faces, ctx.progress)?;
        let next: Vec<Point3> = (0..x.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|i| {
                ctx.progress.check_every(i, 4096)?;
                if !moving[i] || op.locked[i] {
                    return Ok(x[i]);
                }
                let v = scale([y[3 * i], y[3 * i + 1], y[3 * i + 2]], -h * w[i] / op.scale[i]);
                let n = normals[i];
                let t = sub(v, scale(n, dot(v, n)));
                Ok(bvh.closest(add(x[i], t)).map(|c| c.point).unwrap_or(x[i]))
            })
            .collect::<Result<_>>()?;
        *x = next;
        ctx.finish_step(x, &before);
    }
    // Umbrella rows (edge neighbours only) for the Laplacian phase.
    let st = Stencil::new(&mesh.faces, x.len(), PairLayout::Edges)?;
    let u = st.uniform_stiffness();
    let deg = u.diagonal();
    let bvh0 = Bvh::new_polled(&mesh.positions, &mesh.faces, ctx.progress)?;
    let lambda = ctx.r.lambda;
    for it in 0..k2 {
        ctx.tick(k1 + it, total)?;
        let before = x.clone();
        let mut y = vec![0.0; 3 * x.len()];
        u.mul_vec(x.as_flattened(), &mut y, 3);
        let next: Vec<Point3> = (0..x.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|i| {
                ctx.progress.check_every(i, 4096)?;
                if !moving[i] || deg[i] <= 0.0 {
                    return Ok(x[i]);
                }
                // Umbrella Δ = mean(neighbours) − x = −(U x)_i / deg_i.
                let d = scale([y[3 * i], y[3 * i + 1], y[3 * i + 2]], -lambda * w[i] / deg[i]);
                let Some(c) = bvh0.closest(x[i]) else { return Ok(x[i]) };
                let n =
                    normalize(crate::metrics::face_normal(&mesh.positions, mesh.faces.get(c.face as usize)));
                let t = sub(d, scale(n, dot(d, n)));
                Ok(bvh0.closest(add(x[i], t)).map(|c| c.point).unwrap_or(x[i]))
            })
            .collect::<Result<_>>()?;
        *x = next;
        ctx.finish_step(x, &before);
    }
    Ok(())
}
