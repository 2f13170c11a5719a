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
//!
//! Files: `energy` (the fairness energy of eq. 6–8: cotangent weights, vertex areas, Willmore),
//! `gauss_newton` (the convex QP of one step: derivatives of distances and nodes, eq. 11–15);
//! this file has the setup, the true target and the iteration with its step checks.

mod energy;
mod gauss_newton;
#[cfg(test)]
mod tests;

pub use energy::{bary_areas, cot_weights, willmore};
pub use gauss_newton::{distance_gradient, node_jacobian, quadratic, Quadratic};

use crate::error::Result;
use crate::geometry::{add, corner_angle, cross, dist, dot, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;

use super::lines::{self, Adjacency, Lights, Model};
use super::qp::{self, QpStats};
use super::target::{self, Runs};

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
