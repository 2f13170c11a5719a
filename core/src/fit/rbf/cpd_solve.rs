//! The RBF interpolation system `[Φ P; Pᵀ 0] [w; c] = [f; 0]` solved by a Cholesky factorisation
//! on the null space of Pᵀ, instead of a symmetric-indefinite LBLᵀ of the whole system.
//!
//! Why: φ(r) = r is conditionally negative definite of order 1 and φ(r) = r³ conditionally
//! positive definite of order 2, so for distinct centres `s·wᵀΦw > 0` (s = −1 for r, +1 for r³)
//! for every `w ≠ 0` with `Pᵀw = 0` (P holds 1 and the linear functions). With Y an orthonormal
//! basis of P's columns and Π = I − YYᵀ the projector onto Pᵀ's null space,
//!
//!   M = s·ΠΦΠ + YYᵀ
//!
//! is symmetric positive definite (s·ΠΦΠ on the null space, the identity on P's range), and
//! `M w = s·Π f` has exactly the interpolant's weights as solution: its range part is 0 (so
//! Pᵀw = 0) and ΠΦw = Πf says f − Φw lies in P's range, which gives c = R⁻¹Yᵀ(f − Φw) with
//! P = YR. M is Φ plus a symmetric rank-2p update (`M = s·Φ + YKᵀ + KYᵀ`), two passes over Φ.
//!
//! Measured on the headline's 2,156 centres: LBLᵀ ~120 ms sequential (faer's parallel mode made
//! it no faster and changed its pivots), Cholesky 67 ms sequential, ~45 ms on faer's rayon mode
//! (docs/benchmarks.md, session 11). When the centres are too close for M to be numerically
//! positive definite (nearly coincident centres, an in-plane polynomial under the cubic kernel
//! with centres slightly off the plane), [`solve`] returns None and the caller uses LBLᵀ.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::{factor as llt, solve as llt_solve};
use faer::{Mat, Par};
use rayon::prelude::*;

/// Solves the `m × m` system `a x = rhs` (rhs `m × 3`) whose first `n` rows and columns are Φ
/// and whose last `m − n` columns of the first `n` rows are P (the lower-right block is 0 and the
/// last `m − n` rows of rhs are 0). `sign` is s: −1 for φ(r) = r, +1 for φ(r) = r³; `par` is
/// faer's parallelism for the factorisation (see [`parallelism`]). None when P is rank-deficient
/// or M is not numerically positive definite; `a` is used up either way.
pub fn solve(mut a: Mat<f64>, rhs: &Mat<f64>, n: usize, sign: f64, par: Par) -> Option<Mat<f64>> {
    let p = a.nrows() - n;
    let columns: Vec<Vec<f64>> = (0..p).map(|k| (0..n).map(|i| a[(i, n + k)]).collect()).collect();
    let (y, r) = orthonormal_basis(columns)?;
    // The column passes use rayon only when faer may: this may run on a thread that is no rayon
    // worker while the pool's workers wait for it (see [`parallelism`]).
    let parallel = matches!(par, Par::Rayon(_));
    // G = ΦY, S = YᵀΦY.
    let g: Vec<Vec<f64>> = {
        let phi = a.as_ref().submatrix(0, 0, n, n);
        let row = |j: usize| -> Vec<f64> { y.iter().map(|yk| dot_col(phi.col(j), yk)).collect() };
        let rows: Vec<Vec<f64>> =
            if parallel { (0..n).into_par_iter().map(row).collect() } else { (0..n).map(row).collect() };
        (0..p).map(|k| rows.iter().map(|row| row[k]).collect()).collect()
    };
    let s: Vec<Vec<f64>> = (0..p).map(|k| (0..p).map(|l| dot(&y[k], &g[l])).collect()).collect();
    // K = −s·G + Y(s·S + I)/2, so that M = s·Φ + YKᵀ + KYᵀ.
    let k: Vec<Vec<f64>> = (0..p)
        .map(|kk| {
            (0..n)
                .map(|i| {
                    let mix: f64 =
                        (0..p).map(|l| y[l][i] * (sign * s[l][kk] + if l == kk { 1.0 } else { 0.0 })).sum();
                    -sign * g[kk][i] + 0.5 * mix
                })
                .collect()
        })
        .collect();
    let mut m = a.as_mut().submatrix_mut(0, 0, n, n);
    if parallel {
        m.as_mut().par_col_iter_mut().enumerate().for_each(|(j, col)| to_m_column(j, col, sign, &y, &k));
    } else {
        m.as_mut().col_iter_mut().enumerate().for_each(|(j, col)| to_m_column(j, col, sign, &y, &k));
    }
    let mut buf = MemBuffer::new(llt::cholesky_in_place_scratch::<f64>(n, par, Default::default()));
    llt::cholesky_in_place(m.as_mut(), Default::default(), par, MemStack::new(&mut buf), Default::default())
        .ok()?;
    // Right-hand side s·Πf.
    let mut w = Mat::<f64>::zeros(n, 3);
    for c in 0..3 {
        let f: Vec<f64> = (0..n).map(|i| rhs[(i, c)]).collect();
        let proj: Vec<f64> = y.iter().map(|yk| dot(yk, &f)).collect();
        for i in 0..n {
            let range: f64 = (0..p).map(|l| y[l][i] * proj[l]).sum();
            w[(i, c)] = sign * (f[i] - range);
        }
    }
    let mut buf = MemBuffer::new(llt_solve::solve_in_place_scratch::<f64>(n, 3, par));
    llt_solve::solve_in_place(m.as_ref(), w.as_mut(), par, MemStack::new(&mut buf));
    // c = R⁻¹(Yᵀf − Gᵀw).
    let mut x = Mat::<f64>::zeros(n + p, 3);
    for c in 0..3 {
        let f: Vec<f64> = (0..n).map(|i| rhs[(i, c)]).collect();
        let wc: Vec<f64> = (0..n).map(|i| w[(i, c)]).collect();
        let mut t: Vec<f64> = (0..p).map(|l| dot(&y[l], &f) - dot(&g[l], &wc)).collect();
        for l in (0..p).rev() {
            for q in l + 1..p {
                t[l] -= r[l][q] * t[q];
            }
            t[l] /= r[l][l];
        }
        for i in 0..n {
            x[(i, c)] = wc[i];
        }
        for l in 0..p {
            x[(n + l, c)] = t[l];
        }
    }
    Some(x)
}

/// Column j of Φ made column j of M = s·Φ + YKᵀ + KYᵀ, in place.
fn to_m_column(j: usize, mut col: faer::ColMut<'_, f64>, sign: f64, y: &[Vec<f64>], k: &[Vec<f64>]) {
    for i in 0..col.nrows() {
        let mut v = sign * col[i];
        for (yl, kl) in y.iter().zip(k) {
            v += yl[i] * kl[j] + kl[i] * yl[j];
        }
        col[i] = v;
    }
}

/// faer's parallelism for a factorisation of `n` unknowns requested from the current thread:
/// sequential inside a rayon job (never nest: a fit run by rayon workers that all wait for their
/// factorisation thread would leave faer's tasks in the global pool with no worker to run them)
/// and below a few hundred unknowns (a few ms, threads do not pay); faer's rayon mode otherwise.
/// Call it on the job's thread, not on the thread the factorisation then runs on (that one is
/// never a rayon worker).
pub fn parallelism(n: usize) -> Par {
    if rayon::current_thread_index().is_some() || n < 500 {
        Par::Seq
    } else {
        Par::rayon(0)
    }
}

/// Y with orthonormal columns and upper-triangular R with `columns = Y R` (modified Gram–Schmidt,
/// each column orthogonalised twice). None when a column is (numerically) in the span of the
/// earlier ones.
#[allow(clippy::type_complexity)]
fn orthonormal_basis(columns: Vec<Vec<f64>>) -> Option<(Vec<Vec<f64>>, Vec<Vec<f64>>)> {
    let p = columns.len();
    let mut r = vec![vec![0.0; p]; p];
    let mut y: Vec<Vec<f64>> = Vec::with_capacity(p);
    for (k, mut v) in columns.into_iter().enumerate() {
        let norm0 = dot(&v, &v).sqrt();
        for _ in 0..2 {
            for (l, yl) in y.iter().enumerate() {
                let h = dot(yl, &v);
                r[l][k] += h;
                for (vi, yi) in v.iter_mut().zip(yl) {
                    *vi -= h * yi;
                }
            }
        }
        let norm = dot(&v, &v).sqrt();
        if norm.is_nan() || norm <= 1e-10 * norm0 {
            return None;
        }
        r[k][k] = norm;
        v.iter_mut().for_each(|x| *x /= norm);
        y.push(v);
    }
    Some((y, r))
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn dot_col(col: faer::ColRef<'_, f64>, b: &[f64]) -> f64 {
    (0..b.len()).map(|i| col[i] * b[i]).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Point3;

    /// Points spread over a ball (a golden-angle spiral with varying radius): distinct, not coplanar.
    fn centres(n: usize) -> Vec<Point3> {
        (0..n)
            .map(|i| {
                let t = i as f64 * 2.399_963;
                let z = 2.0 * (i as f64 + 0.5) / n as f64 - 1.0;
                let r = (1.0 - z * z).sqrt() * (0.4 + 0.6 * ((i * 7 % 11) as f64 / 10.0));
                [r * t.cos(), r * t.sin(), z * 0.8]
            })
            .collect()
    }

    /// `[Φ P; Pᵀ 0]` with P = (x, y, z, 1), by hand (not the module under test's builder).
    fn system(q: &[Point3], cubic: bool) -> (Mat<f64>, Mat<f64>) {
        let n = q.len();
        let mut a = Mat::<f64>::zeros(n + 4, n + 4);
        let mut rhs = Mat::<f64>::zeros(n + 4, 3);
        for i in 0..n {
            for j in 0..n {
                let r = crate::geometry::dist(q[i], q[j]);
                a[(i, j)] = if cubic { r * r * r } else { r };
            }
            for k in 0..3 {
                a[(i, n + k)] = q[i][k];
                a[(n + k, i)] = q[i][k];
            }
            a[(i, n + 3)] = 1.0;
            a[(n + 3, i)] = 1.0;
            rhs[(i, 0)] = (3.0 * q[i][0]).sin();
            rhs[(i, 1)] = q[i][1] * q[i][2];
            rhs[(i, 2)] = 0.5 * q[i][0] - 2.0 * q[i][2] + 1.0;
        }
        (a, rhs)
    }

    /// max |a x − rhs| over all rows and columns.
    fn residual(a: &Mat<f64>, x: &Mat<f64>, rhs: &Mat<f64>) -> f64 {
        let mut worst = 0.0f64;
        for c in 0..3 {
            for i in 0..a.nrows() {
                let v: f64 = (0..a.ncols()).map(|j| a[(i, j)] * x[(j, c)]).sum();
                worst = worst.max((v - rhs[(i, c)]).abs());
            }
        }
        worst
    }

    #[test]
    fn the_null_space_cholesky_solves_both_kernels_systems() {
        let q = centres(300);
        for (cubic, sign) in [(false, -1.0), (true, 1.0)] {
            let (a, rhs) = system(&q, cubic);
            let x = solve(a.clone(), &rhs, q.len(), sign, Par::Seq).expect("definite on the null space");
            // Every equation, including the side conditions Pᵀw = 0 (the last four rows).
            let r = residual(&a, &x, &rhs);
            assert!(r < 1e-9, "cubic {cubic}: residual {r:e}");
        }
    }

    #[test]
    fn the_wrong_sign_or_a_rank_deficient_polynomial_gives_none() {
        let q = centres(120);
        // φ(r) = r with s = +1: M is indefinite, the Cholesky stops.
        let (a, rhs) = system(&q, false);
        assert!(solve(a, &rhs, q.len(), 1.0, Par::Seq).is_none());
        // All centres on the plane z = 0: the column of z is 0, P has rank 3.
        let flat: Vec<Point3> = q.iter().map(|p| [p[0], p[1], 0.0]).collect();
        let (a, rhs) = system(&flat, false);
        assert!(solve(a, &rhs, flat.len(), -1.0, Par::Seq).is_none());
    }
}
