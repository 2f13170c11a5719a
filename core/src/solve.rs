//! Sparse symmetric positive-definite solvers behind one small API.
//!
//! * [`Cholesky`]: faer's sparse LLᵀ with AMD ordering. The symbolic analysis (ordering,
//!   elimination tree, supernodes) is kept, so re-factoring a matrix with the same pattern and new
//!   values (mean-curvature flow re-assembles every step) skips it. Always sequential
//!   (`Par::Seq`): on 2 cores faer's threading made the triangular solves 30–60× slower, and the
//!   service runs several jobs side by side.
//! * [`pcg`]: Jacobi-preconditioned conjugate gradients on several right-hand sides at once
//!   (interleaved, one sparse product per iteration for all columns), warm-started from the caller's
//!   guess. Written here rather than faer's because faer 0.24.4's CG with
//!   `InitialGuessStatus::Zero` returns wrong answers, and a fused 3-column loop is faster.
//! * [`Dirichlet`]: eliminates pinned unknowns (`A_FF x_F = b_F − A_FP x_P`), keeping a map so the
//!   reduced matrix can be refilled from a re-assembled full one without rebuilding its pattern.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymbolicCholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{MatMut, Par, Side};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::job::Progress;
use crate::laplacian::Csr;

/// Which linear solver an implicit step uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SolverChoice {
    /// Conjugate gradients when the system is large and well conditioned (estimated iteration
    /// count small), sparse Cholesky otherwise.
    #[default]
    Auto,
    /// Sparse Cholesky (AMD ordering), factored once and reused across iterations.
    Cholesky,
    /// Jacobi-preconditioned conjugate gradients warm-started from the current positions.
    Cg,
}

/// A sparse Cholesky factorisation whose symbolic part is reused across re-factorisations.
pub struct Cholesky {
    symbolic: SymbolicCholesky<u32>,
    values: Vec<f64>,
    n: usize,
    factored: bool,
}

fn as_faer(a: &Csr) -> Result<SparseColMatRef<'_, u32, f64>> {
    // Symmetric: the compressed rows of A are the compressed columns of Aᵀ = A.
    let sym = SymbolicSparseColMatRef::new_unsorted_checked(a.n, a.n, &a.row_ptr, None, &a.col);
    Ok(SparseColMatRef::new(sym, &a.val))
}

impl Cholesky {
    /// Symbolic analysis (AMD ordering, elimination tree, supernodes) of `a`'s pattern.
    pub fn analyze(a: &Csr) -> Result<Cholesky> {
        let m = as_faer(a)?;
        let symbolic =
            factorize_symbolic_cholesky(m.symbolic(), Side::Lower, Default::default(), Default::default())
                .map_err(|e| Error::numerical("cholesky analysis", format!("{e:?}")))?;
        let values = vec![0.0; symbolic.len_val()];
        Ok(Cholesky { symbolic, values, n: a.n, factored: false })
    }

    /// Numeric factorisation of `a`, which must have the analysed pattern.
    pub fn factor(&mut self, a: &Csr) -> Result<()> {
        let m = as_faer(a)?;
        let par = Par::Seq;
        let req = self.symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        let mut buf = MemBuffer::try_new(req).map_err(|_| Error::numerical("cholesky", "out of memory"))?;
        self.symbolic
            .factorize_numeric_llt::<f64>(
                &mut self.values,
                m,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut buf),
                Default::default(),
            )
            .map_err(|e| {
                Error::numerical(
                    "cholesky",
                    format!("matrix is not positive definite ({e:?}); degenerate mesh?"),
                )
            })?;
        self.factored = true;
        Ok(())
    }

    /// Solves A X = B in place; `b` holds `k` columns, column-major (b[c*n + i]).
    pub fn solve_in_place(&self, b: &mut [f64], k: usize) -> Result<()> {
        if !self.factored {
            return Err(Error::Internal("cholesky solve before factor".into()));
        }
        let par = Par::Seq;
        let llt = faer::sparse::linalg::cholesky::LltRef::new(&self.symbolic, &self.values);
        let mut buf = MemBuffer::try_new(self.symbolic.solve_in_place_scratch::<f64>(k, par))
            .map_err(|_| Error::numerical("cholesky", "out of memory"))?;
        let rhs = MatMut::from_column_major_slice_mut(b, self.n, k);
        llt.solve_in_place_with_conj(faer::Conj::No, rhs, par, MemStack::new(&mut buf));
        Ok(())
    }

    /// Stored values of the factor L (its fill).
    pub fn factor_nnz(&self) -> usize {
        self.symbolic.len_val()
    }
}

/// Result of a CG solve.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct CgInfo {
    pub iterations: usize,
    /// Largest final ‖r‖/‖b‖ over the columns.
    pub relative_residual: f64,
    pub converged: bool,
}

/// Jacobi-preconditioned CG on `k` ≤ 4 interleaved columns (x[i*k + c]); `x` holds the initial
/// guess and receives the solution. Stops when every column's ‖r‖ ≤ tol·‖b‖ or after `max_iter`.
/// Polls `progress` every [`CG_POLL_ITERATIONS`] iterations.
pub fn pcg(
    a: &Csr,
    b: &[f64],
    x: &mut [f64],
    k: usize,
    tol: f64,
    max_iter: usize,
    progress: &Progress,
) -> Result<CgInfo> {
    if b.len() != a.n * k || x.len() != a.n * k {
        return Err(Error::Internal(format!(
            "pcg: {} rows × {k} columns, but b has {} and x {} values",
            a.n,
            b.len(),
            x.len()
        )));
    }
    match k {
        1 => pcg_k::<1>(a, b, x, tol, max_iter, progress),
        2 => pcg_k::<2>(a, b, x, tol, max_iter, progress),
        3 => pcg_k::<3>(a, b, x, tol, max_iter, progress),
        4 => pcg_k::<4>(a, b, x, tol, max_iter, progress),
        _ => Err(Error::Internal(format!("pcg supports 1 to 4 interleaved columns, not {k}"))),
    }
}

/// CG iterations between two polls of `progress.check()` (~1 ms each on 100k rows).
const CG_POLL_ITERATIONS: usize = 8;

/// Below this many rows CG runs on the calling thread: a 35k-vertex solve is ~1 ms per
/// iteration, where three fork-joins per iteration cost more than they save on a busy machine.
const CG_PAR_ROWS: usize = 50_000;

/// Per-column sums of a row pass.
type Sums<const K: usize> = ([f64; K], [f64; K]);

fn add_sums<const K: usize>(mut a: Sums<K>, b: Sums<K>) -> Sums<K> {
    for c in 0..K {
        a.0[c] += b.0[c];
        a.1[c] += b.1[c];
    }
    a
}

/// Runs `f(i, u_i, v_i, w_i)` over the rows of three `K`-interleaved vectors and sums what it
/// returns, in parallel for large systems.
fn row_pass3<const K: usize, F>(par: bool, u: &mut [f64], v: &mut [f64], w: &mut [f64], f: F) -> Sums<K>
where
    F: Fn(usize, &mut [f64], &mut [f64], &mut [f64]) -> Sums<K> + Sync + Send,
{
    let zero = ([0.0; K], [0.0; K]);
    if par {
        u.par_chunks_mut(K)
            .zip(v.par_chunks_mut(K))
            .zip(w.par_chunks_mut(K))
            .enumerate()
            .with_min_len(4096)
            .map(|(i, ((u, v), w))| f(i, u, v, w))
            .reduce(|| zero, add_sums)
    } else {
        u.chunks_mut(K)
            .zip(v.chunks_mut(K))
            .zip(w.chunks_mut(K))
            .enumerate()
            .map(|(i, ((u, v), w))| f(i, u, v, w))
            .fold(zero, add_sums)
    }
}

/// [`row_pass3`] over one vector.
fn row_pass1<const K: usize, F>(par: bool, u: &mut [f64], f: F) -> Sums<K>
where
    F: Fn(usize, &mut [f64]) -> Sums<K> + Sync + Send,
{
    let zero = ([0.0; K], [0.0; K]);
    if par {
        u.par_chunks_mut(K).enumerate().with_min_len(4096).map(|(i, u)| f(i, u)).reduce(|| zero, add_sums)
    } else {
        u.chunks_mut(K).enumerate().map(|(i, u)| f(i, u)).fold(zero, add_sums)
    }
}

/// CG with the vector updates and dot products fused into three row passes per iteration
/// (A·p with p·Ap; x, r, z with r·r and r·z; p), in fixed-size column arrays.
fn pcg_k<const K: usize>(
    a: &Csr,
    b: &[f64],
    x: &mut [f64],
    tol: f64,
    max_iter: usize,
    progress: &Progress,
) -> Result<CgInfo> {
    let n = a.n;
    let par = n >= CG_PAR_ROWS;
    let inv_diag: Vec<f64> = a.diagonal().iter().map(|&d| if d > 0.0 { 1.0 / d } else { 1.0 }).collect();
    let row_mul = |i: usize, v: &[f64]| -> [f64; K] {
        let (s, e) = (a.row_ptr[i] as usize, a.row_ptr[i + 1] as usize);
        let mut acc = [0.0; K];
        for (&j, &aij) in a.col[s..e].iter().zip(&a.val[s..e]) {
            for c in 0..K {
                acc[c] += aij * v[j as usize * K + c];
            }
        }
        acc
    };
    let (mut r, mut z, mut p) = (vec![0.0; n * K], vec![0.0; n * K], vec![0.0; n * K]);
    let mut ap = vec![0.0; n * K];
    // r = b − A x, z = p = M⁻¹ r; sums r·r and r·z.
    let xs: &[f64] = x;
    let (mut rr, mut rz) = row_pass3::<K, _>(par, &mut r, &mut z, &mut p, |i, r, z, p| {
        let ax = row_mul(i, xs);
        let mut s = ([0.0; K], [0.0; K]);
        for c in 0..K {
            r[c] = b[i * K + c] - ax[c];
            z[c] = r[c] * inv_diag[i];
            p[c] = z[c];
            s.0[c] = r[c] * r[c];
            s.1[c] = r[c] * z[c];
        }
        s
    });
    let mut bb = [0.0; K];
    for (q, v) in b.iter().enumerate() {
        bb[q % K] += v * v;
    }
    let bnorm: Vec<f64> = bb.iter().map(|v| v.sqrt()).collect();
    let target: Vec<f64> = bnorm.iter().map(|&bn| tol * bn.max(f64::MIN_POSITIVE)).collect();
    let mut info = CgInfo::default();
    for it in 0..=max_iter {
        let rn: Vec<f64> = rr.iter().map(|v| v.sqrt()).collect();
        let done = rn.iter().zip(&target).all(|(r, t)| r <= t);
        info.iterations = it;
        info.relative_residual =
            rn.iter().zip(&bnorm).map(|(r, b)| if *b > 0.0 { r / b } else { *r }).fold(0.0, f64::max);
        if done {
            info.converged = true;
            break;
        }
        if it == max_iter {
            break;
        }
        progress.check_every(it, CG_POLL_ITERATIONS)?;
        // Ap and p·Ap.
        let ps: &[f64] = &p;
        let (pap, _) = row_pass1::<K, _>(par, &mut ap, |i, ap| {
            let v = row_mul(i, ps);
            let mut s = ([0.0; K], [0.0; K]);
            for c in 0..K {
                ap[c] = v[c];
                s.0[c] = ps[i * K + c] * v[c];
            }
            s
        });
        let mut alpha = [0.0; K];
        for c in 0..K {
            alpha[c] = if pap[c] > 0.0 { rz[c] / pap[c] } else { 0.0 };
        }
        // x += αp, r −= αAp, z = M⁻¹r; sums r·r and r·z.
        let aps: &[f64] = &ap;
        let (rr_new, rz_new) = row_pass3::<K, _>(par, x, &mut r, &mut z, |i, x, r, z| {
            let mut s = ([0.0; K], [0.0; K]);
            for c in 0..K {
                x[c] += alpha[c] * ps[i * K + c];
                r[c] -= alpha[c] * aps[i * K + c];
                z[c] = r[c] * inv_diag[i];
                s.0[c] = r[c] * r[c];
                s.1[c] = r[c] * z[c];
            }
            s
        });
        let mut beta = [0.0; K];
        for c in 0..K {
            beta[c] = if rz[c] > 0.0 { rz_new[c] / rz[c] } else { 0.0 };
        }
        (rr, rz) = (rr_new, rz_new);
        let zs: &[f64] = &z;
        row_pass1::<K, _>(par, &mut p, |i, p| {
            for c in 0..K {
                p[c] = zs[i * K + c] + beta[c] * p[c];
            }
            ([0.0; K], [0.0; K])
        });
    }
    Ok(info)
}

/// Elimination of pinned unknowns from a symmetric system.
pub struct Dirichlet {
    /// Full index of each free unknown.
    pub free: Vec<u32>,
    /// Free index of each full unknown (u32::MAX when pinned).
    pub map: Vec<u32>,
    /// Position in the full matrix's values of each reduced entry.
    src: Vec<u32>,
    pub reduced: Csr,
}

impl Dirichlet {
    /// Builds the reduced pattern of `a` without the `pinned` rows and columns and fills it.
    pub fn new(a: &Csr, pinned: &[bool]) -> Dirichlet {
        let n = a.n;
        let mut map = vec![u32::MAX; n];
        let mut free = Vec::new();
        for i in 0..n {
            if !pinned[i] {
                map[i] = free.len() as u32;
                free.push(i as u32);
            }
        }
        let mut row_ptr = Vec::with_capacity(free.len() + 1);
        row_ptr.push(0u32);
        let mut col = Vec::new();
        let mut src = Vec::new();
        for &i in &free {
            let i = i as usize;
            for p in a.row_ptr[i] as usize..a.row_ptr[i + 1] as usize {
                let j = map[a.col[p] as usize];
                if j != u32::MAX {
                    col.push(j);
                    src.push(p as u32);
                }
            }
            row_ptr.push(col.len() as u32);
        }
        let val = src.iter().map(|&p| a.val[p as usize]).collect();
        let reduced = Csr { n: free.len(), row_ptr, col, val };
        Dirichlet { free, map, src, reduced }
    }

    /// Refills the reduced values from `a` (same pattern as at construction).
    pub fn refill(&mut self, a: &Csr) {
        let src = &self.src;
        self.reduced
            .val
            .par_iter_mut()
            .zip(src)
            .with_min_len(8192)
            .for_each(|(v, &p)| *v = a.val[p as usize]);
    }

    /// Reduced right-hand side for column `c` of interleaved `k`-column data: `b_F − A_FP x_P`.
    pub fn rhs(&self, a: &Csr, b: &[f64], x: &[f64], k: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.free.len() * k];
        out.par_chunks_mut(k).zip(&self.free).with_min_len(4096).for_each(|(o, &i)| {
            let i = i as usize;
            for c in 0..k {
                o[c] = b[i * k + c];
            }
            for p in a.row_ptr[i] as usize..a.row_ptr[i + 1] as usize {
                let j = a.col[p] as usize;
                if self.map[j] == u32::MAX {
                    for c in 0..k {
                        o[c] -= a.val[p] * x[j * k + c];
                    }
                }
            }
        });
        out
    }
}

/// Interleaved (x[i*k+c]) → column-major (y[c*n+i]) and back.
pub fn to_column_major(x: &[f64], k: usize) -> Vec<f64> {
    let n = x.len() / k;
    let mut y = vec![0.0; x.len()];
    for i in 0..n {
        for c in 0..k {
            y[c * n + i] = x[i * k + c];
        }
    }
    y
}

pub fn from_column_major(y: &[f64], k: usize) -> Vec<f64> {
    let n = y.len() / k;
    let mut x = vec![0.0; y.len()];
    for i in 0..n {
        for c in 0..k {
            x[i * k + c] = y[c * n + i];
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laplacian::{operator, MassKind, OperatorKind};
    use crate::shapes::icosphere;

    /// (M + h S) for a small sphere: SPD.
    fn system() -> Csr {
        let m = icosphere(2, 1.0);
        let o = operator(&m.positions, &m.faces, OperatorKind::Cotan, MassKind::Voronoi).unwrap();
        let mut a = o.stiffness.clone();
        for v in &mut a.val {
            *v *= 0.01;
        }
        for (i, &d) in a.diagonal_positions().iter().enumerate() {
            a.val[d] += o.scale[i];
        }
        a
    }

    fn residual(a: &Csr, x: &[f64], b: &[f64], k: usize) -> f64 {
        let mut r = vec![0.0; x.len()];
        a.mul_vec(x, &mut r, k);
        r.iter().zip(b).map(|(r, b)| (r - b).abs()).fold(0.0, f64::max)
    }

    #[test]
    fn cholesky_and_cg_agree_and_solve() {
        let a = system();
        let n = a.n;
        let b: Vec<f64> = (0..n * 3).map(|q| ((q * 7919) % 101) as f64 / 101.0 - 0.5).collect();
        let mut ch = Cholesky::analyze(&a).unwrap();
        ch.factor(&a).unwrap();
        let mut y = to_column_major(&b, 3);
        ch.solve_in_place(&mut y, 3).unwrap();
        let x1 = from_column_major(&y, 3);
        assert!(residual(&a, &x1, &b, 3) < 1e-12);
        // Refactor with new values on the same pattern reuses the analysis.
        let mut a2 = a.clone();
        for v in &mut a2.val {
            *v *= 2.0;
        }
        ch.factor(&a2).unwrap();
        let mut y = to_column_major(&b, 3);
        ch.solve_in_place(&mut y, 3).unwrap();
        let x2 = from_column_major(&y, 3);
        assert!(x1.iter().zip(&x2).all(|(p, q)| (p - 2.0 * q).abs() < 1e-10));
        let mut x3 = vec![0.0; n * 3];
        let info = pcg(&a, &b, &mut x3, 3, 1e-12, 500, &Progress::new()).unwrap();
        assert!(info.converged, "{info:?}");
        assert!(x1.iter().zip(&x3).all(|(p, q)| (p - q).abs() < 1e-9));
        // Warm start at the solution: zero iterations.
        let info = pcg(&a, &b, &mut x3, 3, 1e-9, 500, &Progress::new()).unwrap();
        assert_eq!(info.iterations, 0);
    }

    #[test]
    fn dirichlet_elimination_matches_full_solution() {
        let a = system();
        let n = a.n;
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut b = vec![0.0; n];
        a.mul_vec(&x_true, &mut b, 1);
        let pinned: Vec<bool> = (0..n).map(|i| i % 5 == 0).collect();
        let d = Dirichlet::new(&a, &pinned);
        let rhs = d.rhs(&a, &b, &x_true, 1);
        let mut ch = Cholesky::analyze(&d.reduced).unwrap();
        ch.factor(&d.reduced).unwrap();
        let mut y = rhs.clone();
        ch.solve_in_place(&mut y, 1).unwrap();
        for (f, &i) in d.free.iter().enumerate() {
            assert!((y[f] - x_true[i as usize]).abs() < 1e-10);
        }
    }
}
