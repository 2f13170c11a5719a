//! Fairing of hole patches: new vertices move to the harmonic position (each the mean of its
//! neighbours, uniform weights) with the loop vertices fixed. The system K_II x_I = A_IB x_B
//! (K = graph Laplacian D − A) is symmetric positive definite whenever every patch vertex is
//! connected to the loop, which refinement guarantees (and which is checked first); the three
//! coordinates are solved together by the crate's Jacobi-preconditioned CG ([`crate::solve::pcg`]).

use crate::error::{Error, Result};
use crate::job::Progress;
use crate::laplacian::Csr;
use crate::mesh::Point3;

/// Moves vertices `n_fixed..` of `pos` to the harmonic position over the triangles `tris`.
/// Returns the largest relative residual reached.
pub fn harmonic(pos: &mut [Point3], n_fixed: usize, tris: &[[u32; 3]], progress: &Progress) -> Result<f64> {
    let n = pos.len();
    let m = n - n_fixed;
    if m == 0 {
        return Ok(0.0);
    }
    let nbrs = neighbours(n, tris);
    if !all_reach_the_loop(&nbrs, n_fixed) {
        return Err(Error::numerical(
            "fair",
            "patch Laplacian is not positive definite (a vertex not connected to the loop)",
        ));
    }
    // K_II (degree on the diagonal, −1 per unknown neighbour) and b = Σ of the fixed neighbours,
    // three interleaved columns.
    let unknown = |v: u32| (v as usize) >= n_fixed;
    let mut a = Csr { n: m, row_ptr: vec![0], col: Vec::new(), val: Vec::new() };
    let mut b = vec![0.0; 3 * m];
    for i in 0..m {
        let v = n_fixed + i;
        let mut row: Vec<(u32, f64)> = vec![(i as u32, nbrs[v].len() as f64)];
        for &u in &nbrs[v] {
            if unknown(u) {
                row.push((u - n_fixed as u32, -1.0));
            } else {
                for c in 0..3 {
                    b[3 * i + c] += pos[u as usize][c];
                }
            }
        }
        row.sort_unstable_by_key(|e| e.0);
        a.col.extend(row.iter().map(|e| e.0));
        a.val.extend(row.iter().map(|e| e.1));
        a.row_ptr.push(a.col.len() as u32);
    }
    let mut x: Vec<f64> = pos[n_fixed..].iter().flatten().copied().collect();
    let info = crate::solve::pcg(&a, &b, &mut x, 3, 1e-12, 20 * m + 100, progress)?;
    for (p, xi) in pos[n_fixed..].iter_mut().zip(x.chunks_exact(3)) {
        p.copy_from_slice(xi);
    }
    Ok(info.relative_residual)
}

/// Neighbour lists of the unique undirected edges of `tris` (degenerate sides left out).
fn neighbours(n: usize, tris: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(tris.len() * 3);
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                edges.push((a.min(b), a.max(b)));
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let mut nbrs: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &(a, b) in &edges {
        nbrs[a as usize].push(b);
        nbrs[b as usize].push(a);
    }
    nbrs
}

/// Whether every vertex from `n_fixed` on is connected to some vertex below it.
fn all_reach_the_loop(nbrs: &[Vec<u32>], n_fixed: usize) -> bool {
    let mut seen = vec![false; nbrs.len()];
    let mut stack: Vec<usize> = (0..n_fixed).collect();
    for &v in &stack {
        seen[v] = true;
    }
    while let Some(v) = stack.pop() {
        for &u in &nbrs[v] {
            if !std::mem::replace(&mut seen[u as usize], true) {
                stack.push(u as usize);
            }
        }
    }
    seen.iter().all(|&s| s)
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
        let res = harmonic(&mut pos, 4, &tris, &Progress::new()).unwrap();
        assert!(res < 1e-10);
        for (a, b) in pos[4].iter().zip([0.5, 0.5, 0.0]) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    #[test]
    fn a_vertex_cut_off_from_the_loop_is_an_error_not_a_result() {
        // The square loop with its centre vertex 4, plus a triangle 5-6-7 touching nothing fixed.
        let mut pos = vec![[0.0; 3]; 8];
        pos[1] = [1.0, 0.0, 0.0];
        pos[2] = [1.0, 1.0, 0.0];
        pos[3] = [0.0, 1.0, 0.0];
        let tris = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [5, 6, 7]];
        let e = harmonic(&mut pos, 4, &tris, &Progress::new()).unwrap_err();
        assert!(e.to_string().contains("not connected to the loop"), "{e}");
    }
}
