//! The RBF interpolation system: its matrix, and which factorisation solves it (the null-space
//! Cholesky of [`super::cpd_solve`] for large, well-spread centre sets; the pivoted LBLᵀ of the
//! whole system otherwise and as the fallback).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::Mat;
use faer::Par;
use rayon::prelude::*;

use super::{cpd_solve, spread_ratios, Kernel};
use crate::error::Result;
use crate::geometry::dist;
use crate::mesh::Point3;

/// From this many centres on, the system is solved by the null-space Cholesky
/// ([`super::cpd_solve`]); below, by the pivoted LBLᵀ of the whole system. Small systems (the
/// coarse alignment, the approach levels) take a few ms either way, and keeping their solve keeps
/// their round-off: with the Cholesky everywhere, one sweep case (icosphere vs sections of spot,
/// automatic pose, flagged ambiguous) went from 0 to 5 flipped faces (docs/benchmarks.md,
/// session 11).
pub const CHOLESKY_CENTRES: usize = 500;

/// ... and only when the centres are spread in all three directions (the smallest principal
/// spread at least this share of the largest). Nearly coplanar centre sets (thin shapes, planar
/// networks) are where the fit is most sensitive to round-off: with the Cholesky, flat icosphere 4
/// vs sections of the 1 × 0.6 × 0.04 ellipsoid (spread ratio ~0.05) went from 14 to 51 flipped
/// faces. The headline's centres (homer's sections) are far above it.
pub const CHOLESKY_MIN_SPREAD: f64 = 0.2;

/// The interpolation system's matrix `[Φ P; Pᵀ 0]` for normalised centres `q`: Φ_ij = φ(|q_i −
/// q_j|), P's rows (d · q_i for each direction, 1). Filled a column at a time, the columns in
/// parallel: faer's matrices are column-major, and the row-by-row fill writing both (i, j) and
/// (j, i) took ~46 ms at the headline's 2,156 centres (this one 27–31 ms with the system's right
/// side, at load ~5; the rest is the first touch of 37 MB). Φ is still bitwise symmetric:
/// |q_i − q_j| and |q_j − q_i| square the same differences up to sign.
pub(super) fn matrix(q: &[Point3], kernel: Kernel, directions: &[Point3]) -> Mat<f64> {
    let (n, nd) = (q.len(), directions.len());
    let m = n + nd + 1;
    let mut a = Mat::<f64>::zeros(m, m);
    a.as_mut().par_col_iter_mut().enumerate().for_each(|(j, mut col)| {
        if j < n {
            for (i, qi) in q.iter().enumerate() {
                col[i] = if i == j { kernel.phi(0.0) } else { kernel.phi(dist(*qi, q[j])) };
            }
            for (k, d) in directions.iter().enumerate() {
                col[n + k] = crate::geometry::dot(*d, q[j]);
            }
            col[n + nd] = 1.0;
        } else if j < n + nd {
            let d = directions[j - n];
            for (i, qi) in q.iter().enumerate() {
                col[i] = crate::geometry::dot(d, *qi);
            }
        } else {
            for i in 0..n {
                col[i] = 1.0;
            }
        }
    });
    a
}

/// Which factorisation solves the system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Method {
    /// The null-space Cholesky where it applies (many centres spread in 3D), else the LBLᵀ.
    Fastest,
    /// The pivoted LBLᵀ of the whole system: slower, and the more accurate on near-singular
    /// systems (feet a hair apart going to distant points).
    Pivoted,
}

/// The factorisation that produced a solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Factorisation {
    NullSpaceCholesky,
    Lblt,
}

/// The solve of `a x = rhs` (a from [`matrix`] of the normalised centres `q`), to run on the
/// job's thread or on one of its own. Which factorisation, and faer's parallelism, are decided
/// here, on the calling thread ([`cpd_solve::parallelism`]); the solve returns the one used.
pub(super) fn solver(
    a: Mat<f64>,
    rhs: Mat<f64>,
    q: &[Point3],
    kernel: Kernel,
    directions: &[Point3],
    method: Method,
) -> impl FnOnce() -> Result<(Mat<f64>, Factorisation)> + Send + 'static {
    let n = q.len();
    let cholesky = method == Method::Fastest
        && n >= CHOLESKY_CENTRES
        && directions.len() == 3
        && spread_ratios(q)[0] >= CHOLESKY_MIN_SPREAD;
    let par = cpd_solve::parallelism(n);
    let (q, directions) = (q.to_vec(), directions.to_vec());
    move || {
        let lblt = |a, rhs| symmetric_solve(a, rhs).map(|x| (x, Factorisation::Lblt));
        if !cholesky {
            return lblt(a, rhs);
        }
        match cpd_solve::solve(a, &rhs, n, kernel.definiteness_sign(), par) {
            Some(x) => Ok((x, Factorisation::NullSpaceCholesky)),
            // Not numerically definite on the null space: the pivoted indefinite solve of the
            // whole system (the matrix was used up, so it is built again).
            None => lblt(matrix(&q, kernel, &directions), rhs),
        }
    }
}

/// Dense symmetric-indefinite solve: Bunch–Kaufman LBLᵀ (half the flops of LU, pivoted, so the
/// zero diagonal and zero affine block are fine), sequential. The fallback of the null-space
/// Cholesky ([`super::cpd_solve`]) when the system is not numerically definite there.
fn symmetric_solve(mut a: Mat<f64>, mut rhs: Mat<f64>) -> Result<Mat<f64>> {
    use faer::linalg::cholesky::lblt::{factor as bk, solve as bks};
    let n = a.nrows();
    let mut subdiag = faer::diag::Diag::<f64>::zeros(n);
    let mut perm = vec![0usize; n];
    let mut perm_inv = vec![0usize; n];
    let par = Par::Seq;
    let mut buf = MemBuffer::new(bk::cholesky_in_place_scratch::<usize, f64>(n, par, Default::default()));
    let (_, p) = bk::cholesky_in_place(
        a.as_mut(),
        subdiag.as_mut(),
        &mut perm,
        &mut perm_inv,
        par,
        MemStack::new(&mut buf),
        Default::default(),
    );
    let mut buf2 = MemBuffer::new(bks::solve_in_place_scratch::<usize, f64>(n, rhs.ncols(), par));
    bks::solve_in_place(
        a.as_ref(),
        a.diagonal(),
        subdiag.as_ref(),
        p,
        rhs.as_mut(),
        par,
        MemStack::new(&mut buf2),
    );
    Ok(rhs)
}
