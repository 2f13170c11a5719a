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
//! definite): [`cpd_solve`] factors it there with a Cholesky, and a pivoted LBLᵀ of the
//! whole system is the fallback. It is singular for duplicate centres and for fewer than 4
//! non-coplanar ones; both are rejected before the solve with a message naming the centres. Coplanar centres
//! can instead be fitted with the polynomial part restricted to their plane
//! ([`Rbf::fit_in_plane`]).

use faer::Mat;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::geometry::Aabb;
use crate::job::{interruptible, Progress};
use crate::mesh::Point3;

use super::align::sym_eigen;
use super::kdtree::KdTree;

mod cpd_solve;
mod gradient;
mod system;
mod with_gradient;

pub use gradient::BoundedGradient;
pub use with_gradient::Gradient;

pub use system::{CHOLESKY_CENTRES, CHOLESKY_MIN_SPREAD};

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
        let mut rhs = Mat::<f64>::zeros(m, 3);
        for i in 0..n {
            for k in 0..3 {
                rhs[(i, k)] = values[i][k];
            }
        }
        let solve = |method: system::Method| -> Result<(Mat<f64>, system::Factorisation)> {
            let a = system::matrix(&q, kernel, directions);
            let solve = system::solver(a, rhs.clone(), &q, kernel, directions, method);
            if n >= INTERRUPTIBLE_CENTRES {
                interruptible(progress, solve)?
            } else {
                solve()
            }
        };
        let frame = Frame { q: &q, values, kernel, origin, scale, directions };
        let (x, factorisation) = solve(system::Method::Fastest)?;
        // Residual guard: an ill-conditioned system shows up here rather than as a silent misfit.
        // The null-space Cholesky loses more digits than the pivoted LBLᵀ on a near-singular
        // system (a twisted bunny's feet 2.5e-8 of the diagonal apart going to points 3.7e-3
        // apart: residual 7.8e-6 with the Cholesky, under the bound with the LBLᵀ), so a failed
        // guard after the Cholesky is retried with the LBLᵀ before it is an error.
        let bound = 1e-6 * values.iter().flat_map(|v| v.iter()).fold(0.0f64, |m, c| m.max(c.abs())).max(1.0);
        let mut fitted = frame.solved(x);
        if factorisation == system::Factorisation::NullSpaceCholesky && !fitted.within(bound) {
            fitted = frame.solved(solve(system::Method::Pivoted)?.0);
        }
        if !fitted.within(bound) {
            return Err(Error::numerical(
                stage,
                format!("RBF system is ill-conditioned (residual {:.3e})", fitted.residual),
            ));
        }
        Ok(fitted.rbf)
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
        self.eval_normalised(self.normalised(p))
    }

    /// `p` in the normalised coordinates of the centres.
    #[inline]
    fn normalised(&self, p: Point3) -> Point3 {
        [
            (p[0] - self.origin[0]) / self.scale,
            (p[1] - self.origin[1]) / self.scale,
            (p[2] - self.origin[2]) / self.scale,
        ]
    }

    /// The field's value at `q` in the normalised coordinates of the centres.
    #[inline]
    fn eval_normalised(&self, q: Point3) -> Point3 {
        self.with_affine(q, self.radial(q))
    }

    /// The radial sums at `q` plus the polynomial part there: the field's value.
    #[inline]
    fn with_affine(&self, q: Point3, (sx, sy, sz): (f64, f64, f64)) -> Point3 {
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

    /// The field's Jacobian at `p`: `g[r][c]` = ∂(displacement r)/∂(p c). The map `x ↦ x + s(x)`
    /// has Jacobian I + g ([`super::orientation`]). φ = r has no gradient at a centre (a cone's
    /// apex): there that centre's term is left out.
    pub fn gradient(&self, p: Point3) -> [[f64; 3]; 3] {
        let q = [
            (p[0] - self.origin[0]) / self.scale,
            (p[1] - self.origin[1]) / self.scale,
            (p[2] - self.origin[2]) / self.scale,
        ];
        let mut g = match self.kernel {
            // φ'(r)/r: 1/r for φ = r, 3r for φ = r³.
            Kernel::Linear => self.gradient_sum(q, |r2| 1.0 / r2.max(1e-300).sqrt()),
            Kernel::Cubic => self.gradient_sum(q, |r2| 3.0 * r2.sqrt()),
        };
        for (r, row) in g.iter_mut().enumerate() {
            for (c, x) in row.iter_mut().enumerate() {
                *x = (*x + self.affine[c][r]) / self.scale;
            }
        }
        g
    }

    /// Σ_j α_j ⊗ (q − c_j) φ'(r_j)/r_j in the normalised frame, `dphi_over_r` given r².
    #[inline(always)]
    fn gradient_sum(&self, q: Point3, dphi_over_r: impl Fn(f64) -> f64) -> [[f64; 3]; 3] {
        let n = self.cx.len();
        let (cx, cy, cz) = (&self.cx[..n], &self.cy[..n], &self.cz[..n]);
        let (wx, wy, wz) = (&self.w[0][..n], &self.w[1][..n], &self.w[2][..n]);
        let mut g = [[0.0f64; 3]; 3];
        for j in 0..n {
            let d = [q[0] - cx[j], q[1] - cy[j], q[2] - cz[j]];
            let f = dphi_over_r(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            let a = [wx[j] * f, wy[j] * f, wz[j] * f];
            for r in 0..3 {
                for c in 0..3 {
                    g[r][c] += a[r] * d[c];
                }
            }
        }
        g
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

/// From this many centres on, the dense factorisation runs on a worker thread while the job
/// polls for a cancel ([`interruptible`]): faer's factorisations cannot be interrupted, and at the
/// headline's ~2,000 centres they take ~50–200 ms (the fit's worst cancel overshoot, measured by
/// `cancel_latency 8 fit`). On a cancel the factorisation finishes in the background on its own
/// copy and is dropped. Below this (≤ 8 ms at load 1) the thread is not worth starting.
pub const INTERRUPTIBLE_CENTRES: usize = 500;

#[cfg(test)]
mod tests;

/// The interpolation problem in the centres' normalised frame: what a solution vector is read
/// against.
struct Frame<'a> {
    /// The centres, normalised (`(c − origin) / scale`).
    q: &'a [Point3],
    values: &'a [Point3],
    kernel: Kernel,
    origin: Point3,
    scale: f64,
    directions: &'a [Point3],
}

impl Frame<'_> {
    /// The field of solution `x` (rows α_1..α_n, then one per polynomial direction, then the
    /// constant) with the largest entry of its residual.
    fn solved(&self, x: Mat<f64>) -> Solved {
        let (q, values, directions) = (self.q, self.values, self.directions);
        let (n, nd) = (q.len(), directions.len());
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
            kernel: self.kernel,
            origin: self.origin,
            scale: self.scale,
            in_plane: nd < 3,
            cx: q.iter().map(|p| p[0]).collect(),
            cy: q.iter().map(|p| p[1]).collect(),
            cz: q.iter().map(|p| p[2]).collect(),
            w: [col(0), col(1), col(2)],
            affine,
        };
        // The system's rows evaluated from the solved field (no copy of the n × n matrix: 37 MB
        // at the headline's 2,156 centres): the field at each centre minus its value, and the side
        // conditions Σ α_j = 0, Σ α_j (d · q_j) = 0.
        let mut rmax = 0.0f64;
        let finite = (0..n + nd + 1).all(|i| (0..3).all(|k| x[(i, k)].is_finite()));
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
        let residual = if finite && rmax.is_finite() { rmax } else { f64::INFINITY };
        Solved { rbf, residual }
    }
}

/// A solution of the interpolation system as a field, with the largest entry of its residual.
struct Solved {
    rbf: Rbf,
    /// max |b − A x|, infinite when x or the residual is not finite.
    residual: f64,
}

impl Solved {
    fn within(&self, bound: f64) -> bool {
        self.residual <= bound
    }
}
