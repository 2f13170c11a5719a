//! Fairing of hole patches: new vertices move to the harmonic position (each the mean of its
//! neighbours, uniform weights) with the loop vertices fixed. The system K_II x_I = A_IB x_B
//! (K = graph Laplacian D − A) is symmetric positive definite whenever every patch vertex is
//! connected to the loop, which refinement guarantees; it is solved per coordinate by
//! unpreconditioned conjugate gradients (patches are small: hundreds to thousands of unknowns).

use crate::error::{Error, Result};
use crate::mesh::Point3;

/// Moves vertices `n_fixed..` of `pos` to the harmonic position over the triangles `tris`.
/// Returns the largest relative residual reached.
pub fn harmonic(pos: &mut [Point3], n_fixed: usize, tris: &[[u32; 3]]) -> Result<f64> {
    let n = pos.len();
    let m = n - n_fixed;
    if m == 0 {
        return Ok(0.0);
    }
    // Unique undirected edges → neighbour lists.
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(tris.len() * 3);
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b)));
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let mut nbrs: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &(a, b) in &edges {
        nbrs[a as usize].push(b);
        nbrs[b as usize].push(a);
    }
    let unknown = |v: u32| (v as usize) >= n_fixed;
    let apply = |x: &[f64], y: &mut [f64]| {
        for i in 0..m {
            let v = n_fixed + i;
            let mut s = nbrs[v].len() as f64 * x[i];
            for &u in &nbrs[v] {
                if unknown(u) {
                    s -= x[u as usize - n_fixed];
                }
            }
            y[i] = s;
        }
    };
    let mut worst: f64 = 0.0;
    for axis in 0..3 {
        let b: Vec<f64> = (0..m)
            .map(|i| nbrs[n_fixed + i].iter().filter(|&&u| !unknown(u)).map(|&u| pos[u as usize][axis]).sum())
            .collect();
        let mut x: Vec<f64> = (0..m).map(|i| pos[n_fixed + i][axis]).collect();
        let res = cg(&apply, &b, &mut x, 1e-12, 20 * m + 100)?;
        worst = worst.max(res);
        for i in 0..m {
            pos[n_fixed + i][axis] = x[i];
        }
    }
    Ok(worst)
}

/// Conjugate gradients for SPD `apply`; returns the final relative residual ‖b − Ax‖/‖b‖.
fn cg(
    apply: &dyn Fn(&[f64], &mut [f64]),
    b: &[f64],
    x: &mut [f64],
    tol: f64,
    max_iter: usize,
) -> Result<f64> {
    let m = b.len();
    let dotv = |a: &[f64], c: &[f64]| a.iter().zip(c).map(|(p, q)| p * q).sum::<f64>();
    let mut ax = vec![0.0; m];
    apply(x, &mut ax);
    let mut r: Vec<f64> = b.iter().zip(&ax).map(|(p, q)| p - q).collect();
    let mut p = r.clone();
    let bn = dotv(b, b).sqrt().max(1e-300);
    let mut rr = dotv(&r, &r);
    let mut ap = vec![0.0; m];
    for _ in 0..max_iter {
        if rr.sqrt() <= tol * bn {
            break;
        }
        apply(&p, &mut ap);
        let pap = dotv(&p, &ap);
        if !(pap > 0.0) {
            return Err(Error::numerical(
                "fair",
                "patch Laplacian is not positive definite (a vertex not connected to the loop)",
            ));
        }
        let alpha = rr / pap;
        for i in 0..m {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        let rr_new = dotv(&r, &r);
        let beta = rr_new / rr;
        rr = rr_new;
        for i in 0..m {
            p[i] = r[i] + beta * p[i];
        }
    }
    Ok(rr.sqrt() / bn)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_interior_vertex_goes_to_mean() {
        // Square loop with a displaced centre vertex joined to all four corners.
        let mut pos =
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.9, 0.1, 0.7]];
        let tris = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        let res = harmonic(&mut pos, 4, &tris).unwrap();
        assert!(res < 1e-10);
        for (a, b) in pos[4].iter().zip([0.5, 0.5, 0.0]) {
            assert!((a - b).abs() < 1e-12);
        }
    }
}
