//! The Gauss–Newton model of one fairing step (eq. 11–15): the derivatives of the highlight
//! distances (eq. 1, 3) and of the line nodes (eq. 13) in the normal offsets `x`, and the convex
//! QP `min ½xᵀHx + cᵀx` they give with the linearised fairness residuals.

use crate::error::Result;
use crate::geometry::{cross, dot, scale, sub};
use crate::job::Progress;
use crate::laplacian::Csr;
use crate::mesh::Point3;

use super::super::lines::{Adjacency, Model};
use super::super::target;
use super::energy::{bary_areas, cot_weights, curvature_sum};
use super::{Setup, State};

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
