//! The planar map itself: boundary vertices on the unit circle by arc length, interior vertices
//! from the weighted spring (Dirichlet) system (ELRP, Tutte or inverse-length weights), solved with
//! one sparse Cholesky factorisation for both coordinates. [`solve_springs`] also serves the
//! sphere fallback's Tutte layout.

use std::f64::consts::TAU;

use super::{lift, PlanarMethod};
use crate::error::Result;
use crate::geometry::dist;
use crate::laplacian::Csr;
use crate::mesh::Point3;
use crate::morph::trimesh::TriMesh;
use crate::solve::Cholesky;

/// Boundary angles by arc length (eq. IV.42 = α_{i+1} = α_i + 2π ℓ_i / Σℓ), starting at 0.
pub fn arc_length_angles(pos: &[Point3], lp: &[u32]) -> Vec<f64> {
    let n = lp.len();
    let len: Vec<f64> = (0..n).map(|i| dist(pos[lp[i] as usize], pos[lp[(i + 1) % n] as usize])).collect();
    let total: f64 = len.iter().sum();
    let mut a = Vec::with_capacity(n);
    let mut acc = 0.0;
    for (i, l) in len.iter().enumerate() {
        // Degenerate (zero-length) boundary: equal spacing.
        a.push(if total > 0.0 { TAU * acc / total } else { TAU * i as f64 / n as f64 });
        acc += l;
    }
    a
}

/// Solves the interior of the spring system with the boundary fixed at `angles`.
pub(super) fn solve_interior(
    m: &TriMesh,
    lp: &[u32],
    angles: &[f64],
    method: PlanarMethod,
) -> Result<Vec<Point3>> {
    let n = m.pos.len();
    let mut at = vec![[0.0; 2]; n];
    let mut fixed = vec![false; n];
    for (&v, &a) in lp.iter().zip(angles) {
        fixed[v as usize] = true;
        at[v as usize] = [a.cos(), a.sin()];
    }
    let edges = m.edges();
    let mean_len = edges.iter().map(|&(a, b)| dist(m.pos[a as usize], m.pos[b as usize])).sum::<f64>()
        / edges.len().max(1) as f64;
    let weight = |a: u32, b: u32| -> f64 {
        match method {
            PlanarMethod::Tutte => 1.0,
            // A zero-length edge would give a zero weight (and possibly a singular row).
            PlanarMethod::Elrp => dist(m.pos[a as usize], m.pos[b as usize]).max(1e-9 * mean_len.max(1e-300)),
            PlanarMethod::InverseLength => {
                1.0 / dist(m.pos[a as usize], m.pos[b as usize]).max(1e-9 * mean_len.max(1e-300))
            }
        }
    };
    solve_springs(&mut at, &fixed, edges.iter().map(|&(a, b)| (a, b, weight(a, b))))?;
    Ok(at.iter().map(|p| lift(p[0], p[1])).collect())
}

/// The weighted spring (Dirichlet) system of a planar layout: every vertex with `fixed[v]` stays
/// at `at[v]`, every other lands at the weighted mean of its neighbours. `edges` lists each
/// undirected edge once with its weight (> 0). Both coordinates from one Cholesky factorisation;
/// shared by the disk maps here and the sphere fallback's Tutte layout.
pub(in crate::morph) fn solve_springs(
    at: &mut [[f64; 2]],
    fixed: &[bool],
    edges: impl IntoIterator<Item = (u32, u32, f64)>,
) -> Result<()> {
    let n = at.len();
    let mut free = vec![u32::MAX; n];
    let mut nf = 0usize;
    for v in 0..n {
        if !fixed[v] {
            free[v] = nf as u32;
            nf += 1;
        }
    }
    if nf == 0 {
        return Ok(());
    }
    let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); nf];
    let mut diag = vec![0.0; nf];
    let mut rhs = vec![0.0; 2 * nf];
    for (a, b, w) in edges {
        for (i, j) in [(a, b), (b, a)] {
            let fi = free[i as usize];
            if fi == u32::MAX {
                continue;
            }
            diag[fi as usize] += w;
            let fj = free[j as usize];
            if fj == u32::MAX {
                let p = at[j as usize];
                rhs[fi as usize] += w * p[0];
                rhs[nf + fi as usize] += w * p[1];
            } else {
                rows[fi as usize].push((fj, -w));
            }
        }
    }
    let mut row_ptr = Vec::with_capacity(nf + 1);
    let mut col = Vec::new();
    let mut val = Vec::new();
    row_ptr.push(0u32);
    for (i, row) in rows.iter_mut().enumerate() {
        row.push((i as u32, diag[i]));
        row.sort_unstable_by_key(|e| e.0);
        for &(j, w) in row.iter() {
            col.push(j);
            val.push(w);
        }
        row_ptr.push(col.len() as u32);
    }
    let a = Csr { n: nf, row_ptr, col, val };
    let mut chol = Cholesky::analyze(&a)?;
    chol.factor(&a)?;
    chol.solve_in_place(&mut rhs, 2)?;
    for v in 0..n {
        let f = free[v];
        if f != u32::MAX {
            at[v] = [rhs[f as usize], rhs[nf + f as usize]];
        }
    }
    Ok(())
}
