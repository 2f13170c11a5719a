//! Radial basis function deformation (seed 000, eq. 2.6–2.10).
//!
//! We interpolate *displacements* d_i = v'_i − v_i at the centres v_i with
//! `s(x) = Σ α_j φ(|x − v_j|) + R x + t` and move every point to `x + s(x)`. With the full affine
//! block this is the same map as the thesis's position interpolation (the interpolant is linear in
//! the data and reproduces affine functions).
//!
//! The system (2.8) has φ(0) = 0 on the diagonal and a 4×4 zero block: it is symmetric
//! **indefinite** (the thesis's "positive definite" is wrong), so no Cholesky of the whole system.
//! It is definite on the null space of the polynomial block (φ = r is conditionally negative
//! definite): [`super::cpd_solve`] factors it there with a Cholesky, and a pivoted LBLᵀ of the
//! whole system is the fallback. It is singular for duplicate centres and for fewer than 4
//! non-coplanar ones; both are rejected before the solve with a message naming the centres. Coplanar centres
//! can instead be fitted with the polynomial part restricted to their plane
//! ([`Rbf::fit_in_plane`]).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::{Mat, Par};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::geometry::{dist, Aabb};
use crate::job::{interruptible, Progress};
use crate::mesh::Point3;

use super::align::sym_eigen;
use super::kdtree::KdTree;

/// The radial function φ.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize, utoipa::ToSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum Kernel {
    /// φ(r) = r, the biharmonic kernel the seed prefers (linear, global interpolation).
    #[default]
    Linear,
    /// φ(r) = r³, triharmonic (smoother, distorts more between centres per §2.2.3).
    Cubic,
}

impl Kernel {
    #[inline]
    fn phi(self, r: f64) -> f64 {
        match self {
            Kernel::Linear => r,
            Kernel::Cubic => r * r * r,
        }
    }

    /// s with s·wᵀΦw > 0 for weights orthogonal to the affine functions: r is conditionally
    /// negative definite (order 1), r³ conditionally positive definite (order 2).
    fn definiteness_sign(self) -> f64 {
        match self {
            Kernel::Linear => -1.0,
            Kernel::Cubic => 1.0,
        }
    }
}

/// A solved RBF displacement field. Coordinates are normalised internally (centre and scale of
/// the centres) to keep the system well conditioned whatever the model units.
pub struct Rbf {
    kernel: Kernel,
    origin: Point3,
    scale: f64,
    /// The polynomial part is affine in the centres' plane only ([`Rbf::fit_in_plane`]).
    in_plane: bool,
    cx: Vec<f64>,
    cy: Vec<f64>,
    cz: Vec<f64>,
    /// Weights α_j per coordinate.
    w: [Vec<f64>; 3],
    /// Affine part: rows x, y, z, 1 → 3 output columns.
    affine: [[f64; 3]; 4],
}

/// Why a centre set cannot be interpolated.
#[derive(Debug, Clone, PartialEq)]
pub enum Degenerate {
    TooFew(usize),
    Duplicate(usize, usize),
    /// All centres on one plane (or line); the ratio is the smallest to largest spread.
    Coplanar(f64),
}

/// Checks the centres for the two singular cases before any solve.
pub fn check_centres(centres: &[Point3]) -> std::result::Result<(), Degenerate> {
    let n = centres.len();
    if n < 4 {
        return Err(Degenerate::TooFew(n));
    }
    let diag = Aabb::of(centres).map(|b| b.diagonal()).unwrap_or(0.0);
    let tol = diag * 1e-9;
    // Duplicates: nearest other centre by k-d tree (not O(n²)).
    let tree = KdTree::new(centres);
    for (i, &c) in centres.iter().enumerate() {
        if let Some((j, d2)) = tree.nearest_filtered(c, |j| j as usize != i) {
            if d2.sqrt() <= tol {
                return Err(Degenerate::Duplicate(i.min(j as usize), i.max(j as usize)));
            }
        }
    }
    let ratios = spread_ratios(centres);
    if ratios[0] < 1e-6 {
        return Err(Degenerate::Coplanar(ratios[0]));
    }
    Ok(())
}

/// Unit principal axes of a point set, largest spread first (the last is the normal of the
/// best-fitting plane).
pub fn principal_axes(points: &[Point3]) -> [Point3; 3] {
    let (_, cov) = covariance(points);
    let (vals, vecs) = sym_eigen(&cov, 3);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| vals[b].total_cmp(&vals[a]));
    order.map(|k| [vecs[k], vecs[3 + k], vecs[6 + k]])
}

fn covariance(points: &[Point3]) -> (Point3, Vec<f64>) {
    let n = points.len().max(1) as f64;
    let mut mean = [0.0; 3];
    for c in points {
        for k in 0..3 {
            mean[k] += c[k] / n;
        }
    }
    let mut cov = vec![0.0; 9];
    for c in points {
        let d = [c[0] - mean[0], c[1] - mean[1], c[2] - mean[2]];
        for r in 0..3 {
            for s in 0..3 {
                cov[r * 3 + s] += d[r] * d[s] / n;
            }
        }
    }
    (mean, cov)
}

/// Principal spreads of a point set relative to the largest: [smallest, middle] (square roots of
/// covariance eigenvalue ratios). 0 in the first = coplanar, 0 in both = collinear.
pub fn spread_ratios(points: &[Point3]) -> [f64; 2] {
    let (_, cov) = covariance(points);
    let (mut vals, _) = sym_eigen(&cov, 3);
    vals.sort_by(f64::total_cmp);
    let max = vals[2];
    if max <= 0.0 {
        return [0.0, 0.0];
    }
    [(vals[0].max(0.0) / max).sqrt(), (vals[1].max(0.0) / max).sqrt()]
}

/// The interpolation system's matrix `[Φ P; Pᵀ 0]` for normalised centres `q`: Φ_ij = φ(|q_i −
/// q_j|), P's rows (d · q_i for each direction, 1). Filled a column at a time, the columns in
/// parallel: faer's matrices are column-major, and the row-by-row fill writing both (i, j) and
/// (j, i) took ~46 ms at the headline's 2,156 centres (this one 27–31 ms with the system's right
/// side, at load ~5; the rest is the first touch of 37 MB). Φ is still bitwise symmetric:
/// |q_i − q_j| and |q_j − q_i| square the same differences up to sign.
fn system_matrix(q: &[Point3], kernel: Kernel, directions: &[Point3]) -> Mat<f64> {
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

impl Rbf {
    /// Solves for the field taking value `values[i]` at `centres[i]`. `stage` names the caller in
    /// errors. Call [`check_centres`] first for a message that names the offending centres; this
    /// function repeats the check and reports it generically.
    pub fn fit(centres: &[Point3], values: &[Point3], kernel: Kernel, stage: &str) -> Result<Rbf> {
        Self::fit_polled(centres, values, kernel, stage, &Progress::new())
    }

    /// [`Rbf::fit`] that a cancel (or deadline) of `progress` stops within a millisecond, even
    /// inside the dense factorisation (see [`INTERRUPTIBLE_CENTRES`]).
    pub fn fit_polled(
        centres: &[Point3],
        values: &[Point3],
        kernel: Kernel,
        stage: &str,
        progress: &Progress,
    ) -> Result<Rbf> {
        if let Err(d) = check_centres(centres) {
            return Err(Error::numerical(stage, format!("degenerate RBF centres: {d:?}")));
        }
        Self::fit_with_directions(
            centres,
            values,
            kernel,
            stage,
            &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            progress,
        )
    }

    /// The field for (nearly) coplanar centres: the polynomial part is affine *in the centres'
    /// plane* only (basis 1, u, v), so the system is regular for any non-collinear centres and
    /// nothing is extrapolated across the plane.
    ///
    /// Why not the full affine part: along the plane's normal the centres give no information, so
    /// its normal gradient is set by round-off (exactly coplanar) or by the centres' tiny spread
    /// off the plane (nearly coplanar: feet of a planar loop on a faceted sphere), and points
    /// far from the plane (a sphere's poles) move by that gradient × their distance: folds. The
    /// seed's remedy, centres offset along the vertex normals, fails for the most natural planar
    /// network, a section of a surface, because there the normals lie *in* the section plane (a
    /// circle on a sphere's equator: radial normals), so the augmented set stays coplanar. With
    /// the in-plane basis the field is even about the plane and bounded away from it, and it
    /// reproduces any displacement that is affine in the plane exactly (the equator of a unit
    /// sphere sent to a circle of radius r: the sphere becomes the ellipsoid (r, r, 1)).
    pub fn fit_in_plane(centres: &[Point3], values: &[Point3], kernel: Kernel, stage: &str) -> Result<Rbf> {
        Self::fit_in_plane_polled(centres, values, kernel, stage, &Progress::new())
    }

    /// [`Rbf::fit_in_plane`], stopped by a cancel of `progress` as [`Rbf::fit_polled`] is.
    pub fn fit_in_plane_polled(
        centres: &[Point3],
        values: &[Point3],
        kernel: Kernel,
        stage: &str,
        progress: &Progress,
    ) -> Result<Rbf> {
        match check_centres(centres) {
            Ok(()) | Err(Degenerate::Coplanar(_)) => {}
            Err(d) => return Err(Error::numerical(stage, format!("degenerate RBF centres: {d:?}"))),
        }
        if spread_ratios(centres)[1] < 1e-6 {
            return Err(Error::numerical(stage, "degenerate RBF centres: all on one line".to_string()));
        }
        let [u, v, _] = principal_axes(centres);
        Self::fit_with_directions(centres, values, kernel, stage, &[u, v], progress)
    }

    /// Solves the interpolation system with the polynomial part spanned by 1 and the linear
    /// functions `d · q` for each unit direction `d` (3 axes: the full affine part of eq. 2.6).
    fn fit_with_directions(
        centres: &[Point3],
        values: &[Point3],
        kernel: Kernel,
        stage: &str,
        directions: &[Point3],
        progress: &Progress,
    ) -> Result<Rbf> {
        if centres.len() != values.len() {
            return Err(Error::Internal("rbf: centres and values differ in length".into()));
        }
        let n = centres.len();
        let bb = Aabb::of(centres).ok_or_else(|| Error::Internal("rbf: no centres".into()))?;
        let origin = bb.center();
        let scale = (bb.diagonal() / 2.0).max(f64::MIN_POSITIVE);
        let q: Vec<Point3> = centres
            .iter()
            .map(|c| [(c[0] - origin[0]) / scale, (c[1] - origin[1]) / scale, (c[2] - origin[2]) / scale])
            .collect();
        let nd = directions.len();
        let m = n + nd + 1;
        let a = system_matrix(&q, kernel, directions);
        let mut rhs = Mat::<f64>::zeros(m, 3);
        for i in 0..n {
            for k in 0..3 {
                rhs[(i, k)] = values[i][k];
            }
        }
        let (q_copy, dirs) = (q.clone(), directions.to_vec());
        let cholesky = n >= CHOLESKY_CENTRES && nd == 3 && spread_ratios(&q)[0] >= CHOLESKY_MIN_SPREAD;
        // Decided here, on the job's thread: the solve may run on a thread of its own.
        let par = super::cpd_solve::parallelism(n);
        let solve = move || {
            if !cholesky {
                return symmetric_solve(a, rhs);
            }
            match super::cpd_solve::solve(a, &rhs, n, kernel.definiteness_sign(), par) {
                Some(x) => Ok(x),
                // Not numerically definite on the null space: the pivoted indefinite solve of the
                // whole system (the matrix was used up, so it is built again).
                None => symmetric_solve(system_matrix(&q_copy, kernel, &dirs), rhs),
            }
        };
        let x = if n >= INTERRUPTIBLE_CENTRES { interruptible(progress, solve)?? } else { solve()? };
        let col = |k: usize| (0..n).map(|i| x[(i, k)]).collect::<Vec<_>>();
        // The polynomial part as the rows x, y, z, 1 of a full affine map (Σ_k d_k ⊗ coefficient_k).
        let mut affine = [[0.0; 3]; 4];
        for (k, d) in directions.iter().enumerate() {
            for r in 0..3 {
                for c in 0..3 {
                    affine[r][c] += d[r] * x[(n + k, c)];
                }
            }
        }
        for c in 0..3 {
            affine[3][c] = x[(n + nd, c)];
        }
        let rbf = Rbf {
            kernel,
            origin,
            scale,
            in_plane: nd < 3,
            cx: q.iter().map(|p| p[0]).collect(),
            cy: q.iter().map(|p| p[1]).collect(),
            cz: q.iter().map(|p| p[2]).collect(),
            w: [col(0), col(1), col(2)],
            affine,
        };
        // Residual guard: an ill-conditioned system shows up here rather than as a silent misfit.
        // The system's rows are evaluated from the solved field (no copy of the n × n matrix:
        // 37 MB at the headline's 2,156 centres): the field at each centre minus its value, and
        // the side conditions Σ α_j = 0, Σ α_j (d · q_j) = 0.
        let mut rmax = 0.0f64;
        let finite = (0..m).all(|i| (0..3).all(|k| x[(i, k)].is_finite()));
        for (i, qi) in q.iter().enumerate() {
            let e = rbf.eval_normalised(*qi);
            for k in 0..3 {
                rmax = rmax.max((e[k] - values[i][k]).abs());
            }
        }
        let mut side = vec![[0.0f64; 3]; nd + 1];
        for (i, qi) in q.iter().enumerate() {
            for k in 0..3 {
                let a = x[(i, k)];
                for (s, d) in side.iter_mut().zip(directions) {
                    s[k] += crate::geometry::dot(*d, *qi) * a;
                }
                side[nd][k] += a;
            }
        }
        rmax = side.iter().flatten().fold(rmax, |acc, r| acc.max(r.abs()));
        let vmax = values.iter().flat_map(|v| v.iter()).fold(0.0f64, |m, c| m.max(c.abs())).max(1e-300);
        if !finite || !rmax.is_finite() || rmax > 1e-6 * vmax.max(1.0) {
            return Err(Error::numerical(
                stage,
                format!("RBF system is ill-conditioned (residual {rmax:.3e})"),
            ));
        }
        Ok(rbf)
    }

    /// Whether the polynomial part is restricted to the centres' plane ([`Rbf::fit_in_plane`]).
    pub fn in_plane(&self) -> bool {
        self.in_plane
    }

    pub fn centre_count(&self) -> usize {
        self.cx.len()
    }

    /// The field's value at `p`.
    pub fn eval(&self, p: Point3) -> Point3 {
        let q = [
            (p[0] - self.origin[0]) / self.scale,
            (p[1] - self.origin[1]) / self.scale,
            (p[2] - self.origin[2]) / self.scale,
        ];
        self.eval_normalised(q)
    }

    /// The field's value at `q` in the normalised coordinates of the centres.
    #[inline]
    fn eval_normalised(&self, q: Point3) -> Point3 {
        let (sx, sy, sz) = self.radial(q);
        let a = &self.affine;
        [
            sx + a[0][0] * q[0] + a[1][0] * q[1] + a[2][0] * q[2] + a[3][0],
            sy + a[0][1] * q[0] + a[1][1] * q[1] + a[2][1] * q[2] + a[3][1],
            sz + a[0][2] * q[0] + a[1][2] * q[1] + a[2][2] * q[2] + a[3][2],
        ]
    }

    /// Σ_j φ(|q − c_j|) α_j, with AVX2 + FMA when the CPU has them (4 square roots per instruction
    /// instead of 2: this loop is the 100k × 2k kernel evaluations of the fine stage).
    #[inline]
    fn radial(&self, q: Point3) -> (f64, f64, f64) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            // SAFETY: the features were just detected on this CPU.
            return unsafe { self.radial_avx2(q) };
        }
        match self.kernel {
            Kernel::Linear => self.radial_sum(q, |r| r),
            Kernel::Cubic => self.radial_sum(q, |r| r * r * r),
        }
    }

    /// The same sum with explicit 4-lane AVX2 (the auto-vectoriser only used 2 lanes here).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn radial_avx2(&self, q: Point3) -> (f64, f64, f64) {
        use std::arch::x86_64::*;
        let n = self.cx.len();
        let (cx, cy, cz) = (&self.cx[..n], &self.cy[..n], &self.cz[..n]);
        let (wx, wy, wz) = (&self.w[0][..n], &self.w[1][..n], &self.w[2][..n]);
        let cubic = self.kernel == Kernel::Cubic;
        let (qx, qy, qz) = (_mm256_set1_pd(q[0]), _mm256_set1_pd(q[1]), _mm256_set1_pd(q[2]));
        let (mut ax, mut ay, mut az) = (_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd());
        let chunks = n / 4;
        for c in 0..chunks {
            let j = c * 4;
            // SAFETY: j + 4 ≤ n for every slice (all have length n).
            let dx = _mm256_sub_pd(qx, _mm256_loadu_pd(cx.as_ptr().add(j)));
            let dy = _mm256_sub_pd(qy, _mm256_loadu_pd(cy.as_ptr().add(j)));
            let dz = _mm256_sub_pd(qz, _mm256_loadu_pd(cz.as_ptr().add(j)));
            let r2 = _mm256_fmadd_pd(dz, dz, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dx, dx)));
            let r = _mm256_sqrt_pd(r2);
            let f = if cubic { _mm256_mul_pd(r, r2) } else { r };
            ax = _mm256_fmadd_pd(f, _mm256_loadu_pd(wx.as_ptr().add(j)), ax);
            ay = _mm256_fmadd_pd(f, _mm256_loadu_pd(wy.as_ptr().add(j)), ay);
            az = _mm256_fmadd_pd(f, _mm256_loadu_pd(wz.as_ptr().add(j)), az);
        }
        let hsum = |v: __m256d| {
            let mut a = [0.0f64; 4];
            _mm256_storeu_pd(a.as_mut_ptr(), v);
            (a[0] + a[1]) + (a[2] + a[3])
        };
        let (mut sx, mut sy, mut sz) = (hsum(ax), hsum(ay), hsum(az));
        for j in chunks * 4..n {
            let (dx, dy, dz) = (q[0] - cx[j], q[1] - cy[j], q[2] - cz[j]);
            let r2 = dx * dx + dy * dy + dz * dz;
            let f = if cubic { r2 * r2.sqrt() } else { r2.sqrt() };
            sx += f * wx[j];
            sy += f * wy[j];
            sz += f * wz[j];
        }
        (sx, sy, sz)
    }

    /// Σ_j φ(|q − c_j|) α_j. Equal-length slices and a kernel fixed per call let the compiler
    /// vectorise the loop (sqrt included); 4 partial sums break the add dependency chain.
    #[inline(always)]
    fn radial_sum(&self, q: Point3, phi: impl Fn(f64) -> f64) -> (f64, f64, f64) {
        let n = self.cx.len();
        let (cx, cy, cz) = (&self.cx[..n], &self.cy[..n], &self.cz[..n]);
        let (wx, wy, wz) = (&self.w[0][..n], &self.w[1][..n], &self.w[2][..n]);
        let mut acc = [[0.0f64; 4]; 3];
        let chunks = n / 4;
        for c in 0..chunks {
            for l in 0..4 {
                let j = c * 4 + l;
                let (dx, dy, dz) = (q[0] - cx[j], q[1] - cy[j], q[2] - cz[j]);
                let f = phi((dx * dx + dy * dy + dz * dz).sqrt());
                acc[0][l] += f * wx[j];
                acc[1][l] += f * wy[j];
                acc[2][l] += f * wz[j];
            }
        }
        for j in chunks * 4..n {
            let (dx, dy, dz) = (q[0] - cx[j], q[1] - cy[j], q[2] - cz[j]);
            let f = phi((dx * dx + dy * dy + dz * dz).sqrt());
            acc[0][0] += f * wx[j];
            acc[1][0] += f * wy[j];
            acc[2][0] += f * wz[j];
        }
        let s = |a: [f64; 4]| (a[0] + a[1]) + (a[2] + a[3]);
        (s(acc[0]), s(acc[1]), s(acc[2]))
    }

    /// The field at many points (rayon over chunks; polls `progress` between chunks).
    pub fn eval_many(&self, points: &[Point3], progress: &Progress) -> Result<Vec<Point3>> {
        let mut out = vec![[0.0; 3]; points.len()];
        const CHUNK: usize = 4096;
        for (ci, (o, p)) in out.chunks_mut(CHUNK * 8).zip(points.chunks(CHUNK * 8)).enumerate() {
            progress.fraction((ci * CHUNK * 8) as f64 / points.len().max(1) as f64)?;
            o.par_chunks_mut(256).zip(p.par_chunks(256)).for_each(|(o, p)| {
                for (o, &p) in o.iter_mut().zip(p) {
                    *o = self.eval(p);
                }
            });
        }
        Ok(out)
    }
}

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

/// From this many centres on, the dense factorisation runs on a worker thread while the job
/// polls for a cancel ([`interruptible`]): faer's factorisations cannot be interrupted, and at the
/// headline's ~2,000 centres they take ~50–200 ms (the fit's worst cancel overshoot, measured by
/// `cancel_latency 8 fit`). On a cancel the factorisation finishes in the background on its own
/// copy and is dropped. Below this (≤ 8 ms at load 1) the thread is not worth starting.
pub const INTERRUPTIBLE_CENTRES: usize = 500;

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

/// Dense LU with partial pivoting, sequential (faer's parallel mode is never used: see DESIGN).
#[allow(dead_code)]
fn lu_solve(mut a: Mat<f64>, mut rhs: Mat<f64>) -> Result<Mat<f64>> {
    let n = a.nrows();
    let mut perm = vec![0usize; n];
    let mut perm_inv = vec![0usize; n];
    let par = Par::Seq;
    let mut buf = MemBuffer::new(factor::lu_in_place_scratch::<usize, f64>(n, n, par, Default::default()));
    let (_, p) = factor::lu_in_place(
        a.as_mut(),
        &mut perm,
        &mut perm_inv,
        par,
        MemStack::new(&mut buf),
        Default::default(),
    );
    let mut buf2 = MemBuffer::new(solve::solve_in_place_scratch::<usize, f64>(n, rhs.ncols(), par));
    solve::solve_in_place(a.as_ref(), a.as_ref(), p, rhs.as_mut(), par, MemStack::new(&mut buf2));
    Ok(rhs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_corners() -> Vec<Point3> {
        let mut v = Vec::new();
        for i in 0..8 {
            v.push([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
        }
        v.push([0.3, 0.7, 0.2]);
        v
    }

    #[test]
    fn interpolates_exactly_at_centres() {
        let c = cube_corners();
        // Arbitrary non-affine values (hand-picked numbers).
        let vals: Vec<Point3> =
            (0..c.len()).map(|i| [i as f64 * 0.1, (i * i) as f64 * 0.01, -(i as f64)]).collect();
        for kernel in [Kernel::Linear, Kernel::Cubic] {
            let f = Rbf::fit(&c, &vals, kernel, "test").unwrap();
            for (p, v) in c.iter().zip(&vals) {
                let e = f.eval(*p);
                for k in 0..3 {
                    assert!((e[k] - v[k]).abs() < 1e-10, "{kernel:?} {e:?} vs {v:?}");
                }
            }
        }
    }

    #[test]
    fn reproduces_an_affine_map_everywhere() {
        let c = cube_corners();
        // d(x) = A x + b, hand-chosen.
        let a = [[0.5, 0.1, 0.0], [-0.2, 0.3, 0.4], [0.0, 0.0, -0.7]];
        let b = [1.0, -2.0, 0.5];
        let d = |p: Point3| -> Point3 {
            let mut r = b;
            for i in 0..3 {
                for j in 0..3 {
                    r[i] += a[i][j] * p[j];
                }
            }
            r
        };
        let vals: Vec<Point3> = c.iter().map(|&p| d(p)).collect();
        let f = Rbf::fit(&c, &vals, Kernel::Linear, "test").unwrap();
        for p in [[5.0, -3.0, 2.0], [0.5, 0.5, 0.5], [-10.0, 0.0, 7.5]] {
            let (e, t) = (f.eval(p), d(p));
            for k in 0..3 {
                assert!((e[k] - t[k]).abs() < 1e-9 * (1.0 + t[k].abs()), "{e:?} vs {t:?}");
            }
        }
    }

    #[test]
    fn simd_and_scalar_sums_agree() {
        // 23 centres (not a multiple of 4: the tail runs too), pseudo-random values.
        let c: Vec<Point3> = (0..23)
            .map(|i| [(i as f64 * 0.37).sin(), (i as f64 * 0.91).cos(), (i * i % 7) as f64 * 0.1])
            .collect();
        let vals: Vec<Point3> =
            (0..23).map(|i| [(i as f64).sin(), 0.1 * i as f64, -0.05 * (i % 5) as f64]).collect();
        for kernel in [Kernel::Linear, Kernel::Cubic] {
            let f = Rbf::fit(&c, &vals, kernel, "test").unwrap();
            for q in [[0.1, 0.2, 0.3], [-2.0, 1.0, 0.5]] {
                let a = match kernel {
                    Kernel::Linear => f.radial_sum(q, |r| r),
                    Kernel::Cubic => f.radial_sum(q, |r| r * r * r),
                };
                let b = f.radial(q);
                for (x, y) in [(a.0, b.0), (a.1, b.1), (a.2, b.2)] {
                    assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()), "{kernel:?}: {x} vs {y}");
                }
            }
        }
    }

    /// Centres on a Fibonacci sphere (no two alike, none coplanar) and a smooth displacement.
    fn sphere_data(n: usize) -> (Vec<Point3>, Vec<Point3>) {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let c: Vec<Point3> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let t = golden * i as f64;
                [r * t.cos(), r * t.sin(), z]
            })
            .collect();
        let v = c.iter().map(|p| [0.1 * p[1], 0.05 * p[0] * p[2], -0.02 * p[2] * p[2]]).collect();
        (c, v)
    }

    #[test]
    fn fits_run_by_every_worker_of_the_global_pool_finish() {
        // Each worker waits (not as a rayon task) for its factorisation thread. Had that thread
        // asked the same pool for faer's tasks, no worker would be free to run them: a hang.
        let (c, v) = sphere_data(800);
        assert!(c.len() >= CHOLESKY_CENTRES && spread_ratios(&c)[0] >= CHOLESKY_MIN_SPREAD);
        let n = rayon::current_num_threads();
        let ok = (0..n)
            .into_par_iter()
            .map(|_| Rbf::fit_polled(&c, &v, Kernel::Linear, "test", &Progress::new()).is_ok())
            .filter(|&ok| ok)
            .count();
        assert_eq!(ok, n);
    }

    #[test]
    fn a_large_solve_stops_at_a_cancel_during_the_factorisation() {
        // 1,500 centres: the factorisation takes tens of ms, far more than the 1 ms between the
        // polls made while it runs. Poll 1 is the entry check, poll 2 the first one during the
        // factorisation: cancelled there, the fit returns Cancelled without waiting for it.
        let (c, v) = sphere_data(1500);
        assert!(c.len() >= INTERRUPTIBLE_CENTRES);
        let p = Progress::new();
        p.cancel_at_check(2);
        assert!(matches!(Rbf::fit_polled(&c, &v, Kernel::Linear, "test", &p), Err(Error::Cancelled)));
        assert_eq!(p.checks(), 2);
        // Not cancelled, the same fit interpolates (the worker thread's result is used).
        let f = Rbf::fit_polled(&c, &v, Kernel::Linear, "test", &Progress::new()).unwrap();
        for i in [0, 777, 1499] {
            let e = f.eval(c[i]);
            for k in 0..3 {
                assert!((e[k] - v[i][k]).abs() < 1e-9, "{e:?} vs {:?}", v[i]);
            }
        }
        // Below the threshold nothing is polled inside the fit.
        let (c, v) = sphere_data(100);
        let p = Progress::new();
        Rbf::fit_polled(&c, &v, Kernel::Linear, "test", &p).unwrap();
        assert_eq!(p.checks(), 0);
    }

    #[test]
    fn duplicate_and_coplanar_centres_are_rejected() {
        let mut c = cube_corners();
        c.push(c[3]);
        assert_eq!(check_centres(&c), Err(Degenerate::Duplicate(3, 9)));
        let flat: Vec<Point3> = (0..10).map(|i| [i as f64, (i * i % 7) as f64, 2.0]).collect();
        assert!(matches!(check_centres(&flat), Err(Degenerate::Coplanar(_))));
        assert_eq!(check_centres(&c[..3]), Err(Degenerate::TooFew(3)));
        assert!(Rbf::fit(&flat, &flat, Kernel::Linear, "x").is_err());
    }
}
