//! The fairness energy of seed 001 eq. 6–8 on the region: cotangent weights, barycentric vertex
//! areas, the discrete Willmore energy (printed `1/Aᵢ` convention).

use crate::geometry::{add, cross, dot, norm, scale, sub};
use crate::mesh::Point3;

use super::super::lines::Adjacency;
use super::Setup;

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
pub(super) fn curvature_sum(adj: &Adjacency, x: &[Point3], w: &[f64], i: usize) -> Point3 {
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
