//! Fairing with highlight lines (seed 001 §3, Algorithm 2): movable vertices move along their
//! normals, `V̄ᵢ = Vᵢ + xᵢNᵢ`; each step minimises `ω₁ q_fair + ω₂ q_diff` over the box
//! `|xᵢ| ≤ ½ min incident edge` and the highlight model is rebuilt.
//!
//! How this differs from the paper (all in docs/api.md as well):
//! - `q_diff` is the Gauss–Newton model of eq. 11: node positions (eq. 13) are linearised in `x`
//!   (exact derivatives through eq. 1 and eq. 3) and the squared distances taken of that. The paper's
//!   full second-order Taylor expansion can have an indefinite Hessian (seed note §3.6); this one is
//!   PSD, so the QP is convex and its solution global.
//! - `f_diff` is measured in units of the region's mean edge length `e` (divided by `e³`): the
//!   printed `f_fair` is scale-free and `f_diff` has units length³, so `ω₁ = ω₂ = 1` would mean a
//!   different balance at every model scale.
//! - A step is accepted only if the true (non-approximated) target decreased; otherwise it is
//!   halved, up to `MAX_HALVINGS` times, and iterations stop when no halving helps. A step that
//!   would flip a triangle (turn its normal by more than 90° from the previous step or from the
//!   input) or shrink a triangle's smallest angle below half its input value is halved the same
//!   way (the ½-edge bound does not rule flips out, and coarse meshes can collapse triangles).
//! - `f_fair` keeps the printed eq. 8 (`1/Aᵢ`, not `1/(2Aᵢ)`), so `‖K‖² = 16H²`.

use crate::error::Result;
use crate::geometry::{add, corner_angle, cross, dist, dot, norm, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;

use super::lines::{self, Adjacency, Lights, Model};
use super::qp::{self, QpStats};
use super::target::{self, Runs};
use crate::laplacian::Csr;

/// Halvings tried when a step flips a triangle or does not lower the target.
pub const MAX_HALVINGS: usize = 6;
/// A step may not shrink any triangle's smallest angle below this fraction of its input value.
pub const MIN_ANGLE_KEPT: f64 = 0.5;

/// Which vertices move and what the energies sum over (fixed for the whole job).
#[derive(Debug, Clone)]
pub struct Setup {
    pub region: Vec<bool>,
    pub movable: Vec<bool>,
    /// Movable vertices and their one-rings: vertices whose highlight distance can change.
    pub affected: Vec<bool>,
    /// Vertex → unknown index.
    pub var: Vec<Option<u32>>,
    pub vars: Vec<u32>,
    /// Interior region vertices: the sum of eq. 6.
    pub energy_vertices: Vec<u32>,
    /// Mean edge length inside R (`e` of eq. 17).
    pub e: f64,
    pub lights: Lights,
    pub w_fair: f64,
    pub w_diff: f64,
    pub step_fraction: f64,
}

impl Setup {
    /// Movable: in R, not pinned, and at least 3 edges from every vertex outside R or on a mesh
    /// border (§3.1: not a support vertex of any outside vertex — its normal needs its one-ring —
    /// nor of any outside node, whose position needs both edge ends and their one-rings).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        adj: &Adjacency,
        x: &[Point3],
        region: Vec<bool>,
        pinned: &[bool],
        lights: Lights,
        w_fair: f64,
        w_diff: f64,
        step_fraction: f64,
    ) -> Setup {
        let n = x.len();
        let outside: Vec<bool> = (0..n).map(|v| !region[v] || adj.border[v]).collect();
        let near = grow(adj, &outside, 2);
        let movable: Vec<bool> = (0..n).map(|v| !near[v] && !pinned[v]).collect();
        let affected = grow(adj, &movable, 1);
        let mut var = vec![None; n];
        let mut vars = Vec::new();
        for v in 0..n {
            if movable[v] {
                var[v] = Some(vars.len() as u32);
                vars.push(v as u32);
            }
        }
        let energy_vertices =
            (0..n as u32).filter(|&v| region[v as usize] && !adj.border[v as usize]).collect();
        let (mut sum, mut cnt) = (0.0, 0usize);
        for &[a, b] in &adj.edges {
            if region[a as usize] && region[b as usize] {
                sum += dist(x[a as usize], x[b as usize]);
                cnt += 1;
            }
        }
        let e = if cnt > 0 { sum / cnt as f64 } else { 0.0 };
        Setup {
            region,
            movable,
            affected,
            var,
            vars,
            energy_vertices,
            e,
            lights,
            w_fair,
            w_diff,
            step_fraction,
        }
    }

    /// Nodes whose position can change: on an edge with an affected end.
    pub fn moving_nodes(&self, adj: &Adjacency, model: &Model) -> Vec<bool> {
        model
            .nodes
            .iter()
            .map(|nd| {
                let [a, b] = adj.edges[nd.edge as usize];
                self.affected[a as usize] || self.affected[b as usize]
            })
            .collect()
    }

    pub fn runs(&self, adj: &Adjacency, model: &Model) -> Runs {
        target::runs(model, &self.moving_nodes(adj, model), 0.25 * self.e)
    }
}

/// `seed` plus every vertex within `rings` edges of it.
pub fn grow(adj: &Adjacency, seed: &[bool], rings: usize) -> Vec<bool> {
    let mut cur = seed.to_vec();
    for _ in 0..rings {
        let mut next = cur.clone();
        for (v, nb) in adj.vert_nbrs.iter().enumerate() {
            if cur[v] {
                for &(u, _) in nb {
                    next[u as usize] = true;
                }
            }
        }
        cur = next;
    }
    cur
}

/// Cotangent weight `cot α + cot β` per edge (0 for a degenerate corner).
pub fn cot_weights(adj: &Adjacency, x: &[Point3]) -> Vec<f64> {
    let mut w = vec![0.0; adj.edges.len()];
    for (t, te) in adj.tris.iter().zip(&adj.tri_edges) {
        for k in 0..3 {
            // Edge k joins corners k, k+1; the opposite corner is k+2.
            let (a, b, c) = (x[t[k] as usize], x[t[(k + 1) % 3] as usize], x[t[(k + 2) % 3] as usize]);
            let (u, v) = (sub(a, c), sub(b, c));
            let s = norm(cross(u, v));
            if s > 1e-12 * dot(u, u).max(dot(v, v)) {
                w[te[k] as usize] += dot(u, v) / s;
            }
        }
    }
    w
}

/// Barycentric vertex areas (eq. 7).
pub fn bary_areas(adj: &Adjacency, x: &[Point3]) -> Vec<f64> {
    let mut a = vec![0.0; x.len()];
    for t in &adj.tris {
        let ar = crate::geometry::triangle_area(x[t[0] as usize], x[t[1] as usize], x[t[2] as usize]) / 3.0;
        for &v in t {
            a[v as usize] += ar;
        }
    }
    a
}

/// `Σⱼ wᵢⱼ (Vᵢ − Vⱼ)`: `Aᵢ K(Vᵢ)` of eq. 8.
fn curvature_sum(adj: &Adjacency, x: &[Point3], w: &[f64], i: usize) -> Point3 {
    let mut s = [0.0; 3];
    for &(j, e) in &adj.vert_nbrs[i] {
        s = add(s, scale(sub(x[i], x[j as usize]), w[e as usize]));
    }
    s
}

/// Discrete Willmore energy (eq. 6–8, printed `1/Aᵢ` convention) over the region's interior
/// vertices, and the standard deviation of the signed mean curvature `H = K·N/4` there.
pub fn willmore(adj: &Adjacency, x: &[Point3], setup: &Setup) -> (f64, f64) {
    let w = cot_weights(adj, x);
    let a = bary_areas(adj, x);
    let (mut e, mut hs) = (0.0, Vec::with_capacity(setup.energy_vertices.len()));
    for &i in &setup.energy_vertices {
        let i = i as usize;
        if a[i] <= 0.0 {
            continue;
        }
        let k = curvature_sum(adj, x, &w, i);
        e += dot(k, k) / a[i];
        let nrm = crate::geometry::normalize(adj.normal_sum(x, i));
        hs.push(dot(k, nrm) / a[i] / 4.0);
    }
    let n = hs.len().max(1) as f64;
    let mean = hs.iter().sum::<f64>() / n;
    let sd = (hs.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n).sqrt();
    (e, sd)
}

/// The true target `ω₁ f_fair + ω₂ f_diff / e³` at positions `x` (with its model and runs).
pub struct State {
    pub model: Model,
    pub runs: Runs,
    pub f_fair: f64,
    pub f_diff: f64,
}

impl State {
    pub fn new(adj: &Adjacency, x: &[Point3], setup: &Setup) -> State {
        let model = lines::model(adj, x, &setup.lights);
        let runs = setup.runs(adj, &model);
        let f_fair = willmore(adj, x, setup).0;
        let f_diff = target::deviation(&model, &runs, setup.e).f_diff_relative;
        State { model, runs, f_fair, f_diff }
    }

    pub fn objective(&self, setup: &Setup) -> f64 {
        setup.w_fair * self.f_fair + setup.w_diff * self.f_diff
    }
}

/// Sparse gradient row: (unknown, value).
type Row = Vec<(u32, f64)>;

/// `∂d_v/∂x` for every unknown it depends on (eq. 1 through eq. 3), or empty when `d_v` is
/// undefined.
pub fn distance_gradient(adj: &Adjacency, x: &[Point3], nrm: &[Point3], setup: &Setup, v: usize) -> Row {
    let l = &setup.lights;
    let (z, w) = (l.normal, l.across());
    let m = adj.normal_sum(x, v);
    let (mz, mw) = (dot(m, z), dot(m, w));
    if mz == 0.0 {
        return Vec::new();
    }
    let a = sub(x[v], l.origin);
    let az = dot(a, z);
    // d = a·W − (a·Z)(M·W)/(M·Z)
    let dd_da = sub(w, scale(z, mw / mz));
    let dd_dm = scale(sub(scale(w, mz), scale(z, mw)), -az / (mz * mz));
    let mut row: Row = Vec::new();
    if let Some(k) = setup.var[v] {
        row.push((k, dot(dd_da, nrm[v])));
    }
    // ∂M/∂p_k along u for triangle (p0, p1, p2): u × (p_{k+1} − p_{k−1}).
    for &t in &adj.vert_tris[v] {
        let tri = adj.tris[t as usize];
        for c in 0..3 {
            let k = tri[c] as usize;
            if let Some(var) = setup.var[k] {
                let e = sub(x[tri[(c + 1) % 3] as usize], x[tri[(c + 2) % 3] as usize]);
                row.push((var, dot(dd_dm, cross(nrm[k], e))));
            }
        }
    }
    merge(row)
}

fn merge(mut row: Row) -> Row {
    row.sort_unstable_by_key(|e| e.0);
    let mut out: Row = Vec::with_capacity(row.len());
    for (k, v) in row {
        match out.last_mut() {
            Some(last) if last.0 == k => last.1 += v,
            _ => out.push((k, v)),
        }
    }
    out
}

/// `∂Q/∂x` of a node (eq. 13 linearised): one row per coordinate.
pub fn node_jacobian(
    adj: &Adjacency,
    x: &[Point3],
    nrm: &[Point3],
    setup: &Setup,
    model: &Model,
    node: u32,
) -> [Row; 3] {
    let nd = model.nodes[node as usize];
    let [a, b] = adj.edges[nd.edge as usize];
    let (a, b) = (a as usize, b as usize);
    let mut rows: [Row; 3] = Default::default();
    let (Some(da), Some(db)) = (model.d[a], model.d[b]) else { return rows };
    let t = nd.t;
    let ab = sub(x[b], x[a]);
    // ∂t = −((1 − t) ∂d_a + t ∂d_b) / (d_b − d_a)
    let mut dt: Row = Vec::new();
    if db != da {
        for (k, g) in distance_gradient(adj, x, nrm, setup, a) {
            dt.push((k, -(1.0 - t) * g / (db - da)));
        }
        for (k, g) in distance_gradient(adj, x, nrm, setup, b) {
            dt.push((k, -t * g / (db - da)));
        }
    }
    let dt = merge(dt);
    for c in 0..3 {
        let mut r: Row = dt.iter().map(|&(k, g)| (k, g * ab[c])).collect();
        if let Some(k) = setup.var[a] {
            r.push((k, (1.0 - t) * nrm[a][c]));
        }
        if let Some(k) = setup.var[b] {
            r.push((k, t * nrm[b][c]));
        }
        rows[c] = merge(r);
    }
    rows
}

/// The Gauss–Newton QP `min ½xᵀHx + cᵀx` of eq. 15 at the current positions.
pub struct Quadratic {
    pub h: Csr,
    pub c: Vec<f64>,
    pub rows: usize,
}

/// Energy vertices (or line targets) whose rows are built between two polls of [`quadratic`].
const ROWS_PER_POLL: usize = 1024;

pub fn quadratic(
    adj: &Adjacency,
    x: &[Point3],
    nrm: &[Point3],
    setup: &Setup,
    state: &State,
    progress: &Progress,
) -> Result<Quadratic> {
    let n = setup.vars.len();
    // Millions of entries at 30k unknowns: reserving the fairness rows' share up front spares the
    // doublings, each one long uninterruptible copy.
    let fair_entries: usize = setup
        .energy_vertices
        .iter()
        .map(|&i| {
            let i = i as usize;
            let k = usize::from(setup.var[i].is_some())
                + adj.vert_nbrs[i].iter().filter(|&&(j, _)| setup.var[j as usize].is_some()).count();
            3 * k * k
        })
        .sum();
    let mut trip: Vec<(u32, u32, f64)> = Vec::with_capacity(fair_entries);
    let mut c = vec![0.0; n];
    let mut rows = 0;
    let mut add_row = |r0: f64, row: &Row| {
        for &(i, a) in row {
            c[i as usize] += r0 * a;
            for &(j, b) in row {
                trip.push((i, j, a * b));
            }
        }
        rows += 1;
    };
    // q_fair: residual sqrt(ω₁/Aᵢ) Σⱼ wᵢⱼ(V̄ᵢ − V̄ⱼ) with wᵢⱼ, Aᵢ frozen (§3.6).
    let w = cot_weights(adj, x);
    let area = bary_areas(adj, x);
    for (k, &i) in setup.energy_vertices.iter().enumerate() {
        progress.check_every(k, ROWS_PER_POLL)?;
        let i = i as usize;
        if !setup.affected[i] || area[i] <= 0.0 {
            continue;
        }
        let s = (setup.w_fair / area[i]).sqrt();
        let b = curvature_sum(adj, x, &w, i);
        let wsum: f64 = adj.vert_nbrs[i].iter().map(|&(_, e)| w[e as usize]).sum();
        for comp in 0..3 {
            let mut row: Row = Vec::new();
            if let Some(k) = setup.var[i] {
                row.push((k, s * wsum * nrm[i][comp]));
            }
            for &(j, e) in &adj.vert_nbrs[i] {
                if let Some(k) = setup.var[j as usize] {
                    row.push((k, -s * w[e as usize] * nrm[j as usize][comp]));
                }
            }
            add_row(s * b[comp], &row);
        }
    }
    // q_diff: residual sqrt(ω₂ lᵢ / e³)(Q̄ᵢ − Q̃ᵢ), Q̄ linearised.
    let e3 = setup.e.powi(3);
    for run in &state.runs.runs {
        progress.check()?;
        for (node, tgt, l) in target::targets(&state.model, run) {
            let s = (setup.w_diff * l / e3).sqrt();
            let q = state.model.nodes[node as usize].pos;
            let jac = node_jacobian(adj, x, nrm, setup, &state.model, node);
            for comp in 0..3 {
                let row: Row = jac[comp].iter().map(|&(k, g)| (k, s * g)).collect();
                add_row(s * (q[comp] - tgt[comp]), &row);
            }
        }
    }
    let mut h = Csr::from_triplets_polled(n, trip, progress)?;
    // A vanishing ridge keeps H definite for unknowns no residual sees (a flat, line-free patch).
    let dmax = h.diagonal().iter().fold(0.0f64, |m, v| m.max(*v));
    let ridge = 1e-12 * dmax.max(1e-300);
    for p in h.diagonal_positions() {
        h.val[p] += ridge;
    }
    Ok(Quadratic { h, c, rows })
}

/// One iteration's record for the report.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Step {
    pub iteration: usize,
    /// Eq. 17: max |xᵢ| / e of the applied step.
    pub max_step_relative: f64,
    pub halvings: usize,
    pub objective: f64,
    pub willmore: f64,
    pub f_diff_relative: f64,
    pub runs: usize,
    pub qp: QpStats,
}

/// Result of the iteration.
pub struct Outcome {
    pub x: Vec<Point3>,
    pub steps: Vec<Step>,
    pub stop_reason: &'static str,
    /// Trial steps rejected for flipping or degrading a triangle.
    pub flips_prevented: usize,
    /// Largest |xᵢ| / boundᵢ of any applied step (≤ 1 by construction).
    pub max_bound_use: f64,
    pub qp_unknowns: usize,
    pub qp_nonzeros: usize,
}

/// Algorithm 2.
pub fn iterate(
    adj: &Adjacency,
    x0: &[Point3],
    setup: &Setup,
    max_iterations: usize,
    epsilon: f64,
    progress: &Progress,
) -> Result<Outcome> {
    let mut x = x0.to_vec();
    let mut state = State::new(adj, &x, setup);
    let mut out = Outcome {
        x: Vec::new(),
        steps: Vec::new(),
        stop_reason: "max_iterations",
        flips_prevented: 0,
        max_bound_use: 0.0,
        qp_unknowns: setup.vars.len(),
        qp_nonzeros: 0,
    };
    for it in 0..max_iterations {
        progress.fraction(it as f64 / max_iterations.max(1) as f64)?;
        let nrm = adj.normals(&x);
        let quad = quadratic(adj, &x, &nrm, setup, &state, progress)?;
        out.qp_nonzeros = out.qp_nonzeros.max(quad.h.nnz());
        let bound: Vec<f64> = setup
            .vars
            .iter()
            .map(|&v| {
                let v = v as usize;
                let emin = adj.vert_nbrs[v]
                    .iter()
                    .map(|&(u, _)| dist(x[v], x[u as usize]))
                    .fold(f64::INFINITY, f64::min);
                setup.step_fraction * emin
            })
            .collect();
        let lo: Vec<f64> = bound.iter().map(|b| -b).collect();
        let (step, qp) = qp::solve_box(&quad.h, &quad.c, &lo, &bound, 1e-8, progress)?;
        let f0 = state.objective(setup);
        // Backtrack on flips and on an increase of the true target.
        let mut scale_f = 1.0;
        let mut accepted = None;
        let mut halvings = 0;
        for h in 0..=MAX_HALVINGS {
            // Each trial rebuilds the lines model of the whole region.
            progress.check()?;
            let trial = moved(&x, &nrm, setup, &step, scale_f);
            // Against the previous step and against the input: a face may not turn by more than
            // 90° in one step nor accumulate that over several.
            if flips(adj, &x, &trial, setup)
                || flips(adj, x0, &trial, setup)
                || degrades(adj, x0, &trial, setup)
            {
                out.flips_prevented += 1;
            } else {
                let st = State::new(adj, &trial, setup);
                if st.objective(setup) <= f0 {
                    accepted = Some((trial, st));
                    halvings = h;
                    break;
                }
            }
            scale_f *= 0.5;
        }
        let Some((trial, st)) = accepted else {
            out.stop_reason = "no_descent";
            break;
        };
        let max_x = step.iter().fold(0.0f64, |m, v| m.max(v.abs())) * scale_f;
        for (k, s) in step.iter().enumerate() {
            if bound[k] > 0.0 {
                out.max_bound_use = out.max_bound_use.max((s * scale_f).abs() / bound[k]);
            }
        }
        x = trial;
        state = st;
        let rel = if setup.e > 0.0 { max_x / setup.e } else { 0.0 };
        out.steps.push(Step {
            iteration: it + 1,
            max_step_relative: rel,
            halvings,
            objective: state.objective(setup),
            willmore: state.f_fair,
            f_diff_relative: state.f_diff,
            runs: state.runs.runs.len(),
            qp,
        });
        if rel < epsilon {
            out.stop_reason = "converged";
            break;
        }
    }
    out.x = x;
    Ok(out)
}

fn moved(x: &[Point3], nrm: &[Point3], setup: &Setup, step: &[f64], f: f64) -> Vec<Point3> {
    let mut y = x.to_vec();
    for (k, &v) in setup.vars.iter().enumerate() {
        let v = v as usize;
        y[v] = add(x[v], scale(nrm[v], step[k] * f));
    }
    y
}

/// True when a triangle around a movable vertex turned by more than 90°.
fn flips(adj: &Adjacency, before: &[Point3], after: &[Point3], setup: &Setup) -> bool {
    setup.vars.iter().any(|&v| {
        adj.vert_tris[v as usize].iter().any(|&t| {
            let [a, b, c] = adj.tris[t as usize].map(|i| i as usize);
            let n0 = cross(sub(before[b], before[a]), sub(before[c], before[a]));
            let n1 = cross(sub(after[b], after[a]), sub(after[c], after[a]));
            dot(n0, n1) <= 0.0
        })
    })
}

/// True when a triangle around a movable vertex lost more than half of its smallest angle
/// relative to the input (moves along normals can collapse triangles of coarse meshes; the paper
/// does not guard against it).
fn degrades(adj: &Adjacency, input: &[Point3], after: &[Point3], setup: &Setup) -> bool {
    let min_angle = |x: &[Point3], t: [u32; 3]| {
        let [a, b, c] = t.map(|i| x[i as usize]);
        corner_angle(a, b, c).min(corner_angle(b, c, a)).min(corner_angle(c, a, b))
    };
    setup.vars.iter().any(|&v| {
        adj.vert_tris[v as usize].iter().any(|&t| {
            let t = adj.tris[t as usize];
            min_angle(after, t) < MIN_ANGLE_KEPT * min_angle(input, t)
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::{grid, icosphere};

    fn lights() -> Lights {
        Lights {
            normal: [0.0, 0.0, 1.0],
            direction: [1.0, 0.0, 0.0],
            origin: [0.0, 0.31, 2.0],
            spacing: 0.05,
        }
    }

    /// A bumpy height field z = f(x, y) on the unit square, every vertex in R.
    fn bumpy() -> (Adjacency, Vec<Point3>, Setup) {
        let mut m = grid(12, 12, 1.0 / 12.0, false);
        for p in &mut m.positions {
            p[2] = 0.3 * (2.0 * p[0]).sin() * (1.5 * p[1]).cos() + 0.02 * (17.0 * p[0] * p[1]).sin();
        }
        let adj = Adjacency::new(&m).unwrap();
        let n = m.vertex_count();
        let setup = Setup::new(&adj, &m.positions, vec![true; n], &vec![false; n], lights(), 1.0, 1.0, 0.5);
        (adj, m.positions, setup)
    }

    fn moved_along(x: &[Point3], nrm: &[Point3], v: usize, h: f64) -> Vec<Point3> {
        let mut y = x.to_vec();
        y[v] = add(y[v], scale(nrm[v], h));
        y
    }

    #[test]
    fn movable_vertices_are_three_rings_inside() {
        // 12×12 cells: border vertices are outside; the movable ones are ≥ 3 edges from it, i.e.
        // grid indices 3..=9 in both directions: 7 × 7.
        let (_, _, setup) = bumpy();
        assert_eq!(setup.vars.len(), 49);
        for &v in &setup.vars {
            let (i, j) = (v as usize % 13, v as usize / 13);
            assert!((3..=9).contains(&i) && (3..=9).contains(&j));
        }
    }

    #[test]
    fn analytic_derivatives_match_finite_differences() {
        let (adj, x, setup) = bumpy();
        let nrm = adj.normals(&x);
        let md = lines::model(&adj, &x, &setup.lights);
        let h = 1e-6;
        // ∂d/∂x for vertices around the movable set.
        let mut checked = 0;
        for v in (0..x.len()).filter(|&v| setup.affected[v]) {
            let g = distance_gradient(&adj, &x, &nrm, &setup, v);
            for &(k, gk) in &g {
                let u = setup.vars[k as usize] as usize;
                let dp = setup
                    .lights
                    .distance(moved_along(&x, &nrm, u, h)[v], adj.normal_sum(&moved_along(&x, &nrm, u, h), v))
                    .unwrap();
                let dm = setup
                    .lights
                    .distance(
                        moved_along(&x, &nrm, u, -h)[v],
                        adj.normal_sum(&moved_along(&x, &nrm, u, -h), v),
                    )
                    .unwrap();
                let fd = (dp - dm) / (2.0 * h);
                assert!((fd - gk).abs() < 1e-6 * (1.0 + gk.abs()), "d_{v} wrt {u}: {gk} vs {fd}");
                checked += 1;
            }
        }
        assert!(checked > 100);
        // ∂Q/∂x of nodes (eq. 13) on edges near the movable set.
        let moving = setup.moving_nodes(&adj, &md);
        let mut nodes_checked = 0;
        for (id, nd) in md.nodes.iter().enumerate() {
            if !moving[id] || nd.t < 0.05 || nd.t > 0.95 {
                continue;
            }
            let jac = node_jacobian(&adj, &x, &nrm, &setup, &md, id as u32);
            for &(k, _) in &jac[0] {
                let u = setup.vars[k as usize] as usize;
                let at = |hh: f64| {
                    let y = moved_along(&x, &nrm, u, hh);
                    let m2 = lines::model(&adj, &y, &setup.lights);
                    m2.nodes.iter().find(|n2| n2.edge == nd.edge && n2.m == nd.m).map(|n2| n2.pos).unwrap()
                };
                let (p, q) = (at(h), at(-h));
                for c in 0..3 {
                    let fd = (p[c] - q[c]) / (2.0 * h);
                    let an = jac[c].iter().find(|e| e.0 == k).map(|e| e.1).unwrap_or(0.0);
                    assert!(
                        (fd - an).abs() < 1e-5 * (1.0 + an.abs()),
                        "node {id} coord {c} wrt {u}: {an} vs {fd}"
                    );
                }
            }
            nodes_checked += 1;
        }
        assert!(nodes_checked > 20, "{nodes_checked}");
    }

    #[test]
    fn willmore_energy_of_a_sphere_is_64_pi_in_the_printed_convention() {
        // ∫H² dA = 4π for any round sphere; eq. 8's 1/Aᵢ makes ‖K‖² = 16H², so E = 64π.
        for r in [1.0, 1e-3] {
            let m = icosphere(4, r);
            let adj = Adjacency::new(&m).unwrap();
            let n = m.vertex_count();
            let setup =
                Setup::new(&adj, &m.positions, vec![true; n], &vec![false; n], lights(), 1.0, 1.0, 0.5);
            let (e, h_sd) = willmore(&adj, &m.positions, &setup);
            let want = 64.0 * std::f64::consts::PI;
            assert!((e - want).abs() < 0.02 * want, "E = {e}, want {want}");
            assert!(h_sd < 0.02 / r, "H sd {h_sd}");
        }
    }

    #[test]
    fn gauss_newton_model_matches_the_true_target_for_small_steps() {
        // Eq. 15's model, with eq. 12's targets and eq. 14's weights frozen at the current line
        // (as the paper forms them), against the exact energies after a small step along the
        // model's steepest descent: equal to first order (signs and scales of both terms).
        let (adj, x, setup) = bumpy();
        let nrm = adj.normals(&x);
        let st = State::new(&adj, &x, &setup);
        let quad = quadratic(&adj, &x, &nrm, &setup, &st, &Progress::new()).unwrap();
        let frozen = |y: &[Point3]| -> f64 {
            let m2 = lines::model(&adj, y, &setup.lights);
            let mut f = 0.0;
            for run in &st.runs.runs {
                for (node, tgt, l) in target::targets(&st.model, run) {
                    let nd = st.model.nodes[node as usize];
                    let q = m2.nodes.iter().find(|n2| n2.edge == nd.edge && n2.m == nd.m).unwrap().pos;
                    f += l * crate::geometry::norm2(sub(q, tgt));
                }
            }
            setup.w_fair * willmore(&adj, y, &setup).0 + setup.w_diff * f / setup.e.powi(3)
        };
        let g2: f64 = quad.c.iter().map(|g| g * g).sum();
        assert!(g2 > 0.0);
        for eps in [1e-6, 1e-7] {
            let step: Vec<f64> = quad.c.iter().map(|g| -eps * g / g2.sqrt()).collect();
            let y = moved(&x, &nrm, &setup, &step, 1.0);
            let predicted: f64 = 2.0 * quad.c.iter().zip(&step).map(|(g, s)| g * s).sum::<f64>();
            let actual = frozen(&y) - frozen(&x);
            assert!(predicted < 0.0);
            assert!(
                (actual - predicted).abs() < 0.01 * predicted.abs(),
                "actual {actual} predicted {predicted}"
            );
        }
    }
}
