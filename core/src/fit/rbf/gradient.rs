//! The field's Jacobian at many points, in single precision with a proven error bound: the report's
//! orientation count ([`crate::fit::orientation`]) needs the Jacobian of every RBF map at every
//! vertex (~100k vertices × 2,156 centres on the headline). In double precision that was ~0.4 s of
//! the headline's ~1.4 s (fit-flipcount, sessions 13–14); the count only needs the sign of dot
//! products, so 8 lanes of f32 with a reciprocal square root do the sum, and each point gets a
//! bound on the error of its Jacobian. The count re-evaluates in double precision
//! ([`Rbf::gradient`]) only the corners of faces whose decision the bound leaves open. Since
//! session 16 the approach levels and the inserted fine stage take their gradients from the pass
//! that evaluates the field ([`Rbf::eval_with_gradients`], double precision, no second pass);
//! this one serves the fine stage of `matching = nearest_vertex`.
//!
//! The bound (normalised frame, u = 2⁻²⁴, per entry of the gradient, |α_i| = max over the three
//! coordinates of centre i's weight, M = the largest coordinate of the point and the centres):
//! - rounding q and c_i to f32 and subtracting: each coordinate of d = q − c_i is off by at most
//!   2uM + u|d|; so d/r is off by at most (1 + √3)(2uM + ur)/r;
//! - `rsqrt` (12 bits) and one Newton step: 1/r to ~10u relative (2·10⁻⁷ from the step, the rest
//!   rounding), the weight's rounding and two products 3u more;
//! - so a term α_i·d/r is off by at most |α_i|·u·(5.6M/r + 18), and summing B terms per lane in
//!   f32 before adding the blocks in f64 adds B·u·Σ|α_i| (|d/r| ≤ 1).
//!
//! Total: u·(5.6·M·E + (18 + B)·W) with E = Σ|α_i|/r_i (summed in the same pass) and
//! W = Σ|α_i|; a term whose r² is under [`TINY_R2`] in f32 is left out (as the exact gradient
//! leaves out a centre the point sits on) and its |α_i| added to the bound whole. The bound is
//! doubled for safety and given as a Frobenius norm (×3 over the 9 entries).

use rayon::prelude::*;

use crate::error::Result;
use crate::job::Progress;
use crate::mesh::Point3;

use super::{Kernel, Rbf};

/// Lane iterations summed in f32 before a block is added in f64 (8 centres each).
const BLOCK: usize = 32;

/// Squared distances below this (normalised frame) leave their term out.
const TINY_R2: f32 = 1e-30;

/// f32 unit roundoff.
const U: f64 = 1.0 / 16_777_216.0;

/// A Jacobian `g[r][c]` = ∂(displacement r)/∂(p c) and a bound on the Frobenius norm of its error.
pub type BoundedGradient = ([[f64; 3]; 3], f64);

/// The centres and weights in f32, padded to a multiple of 8 with zero weights.
struct Centres32 {
    c: [Vec<f32>; 3],
    w: [Vec<f32>; 3],
    /// max over the coordinates of |α_i|.
    w_abs: Vec<f32>,
    /// Σ|α_i| in f64 and the largest centre coordinate.
    w_sum: f64,
    c_max: f64,
    /// Each centre's index by the bits of its normalised coordinates: a point on a centre (a curve
    /// vertex at its foot) leaves that term out exactly as [`Rbf::gradient`] does, so it adds
    /// nothing to the bound.
    at: std::collections::HashMap<[u64; 3], usize>,
}

impl Centres32 {
    fn new(f: &Rbf) -> Centres32 {
        let n = f.cx.len();
        let padded = n.div_ceil(8) * 8;
        let pad = |v: &[f64]| {
            let mut out: Vec<f32> = v.iter().map(|&x| x as f32).collect();
            out.resize(padded, 0.0);
            out
        };
        let w_abs64: Vec<f64> =
            (0..n).map(|i| f.w[0][i].abs().max(f.w[1][i].abs()).max(f.w[2][i].abs())).collect();
        // Rounded up to f32 so that the bound's weights are never smaller than the true ones.
        let mut w_abs: Vec<f32> = w_abs64.iter().map(|&x| (x as f32) * (1.0 + f32::EPSILON)).collect();
        w_abs.resize(padded, 0.0);
        let c_max = f.cx.iter().chain(&f.cy).chain(&f.cz).fold(0.0f64, |m, x| m.max(x.abs()));
        Centres32 {
            c: [pad(&f.cx), pad(&f.cy), pad(&f.cz)],
            w: [pad(&f.w[0]), pad(&f.w[1]), pad(&f.w[2])],
            w_abs,
            w_sum: w_abs64.iter().sum(),
            c_max,
            at: (0..n).map(|i| ([f.cx[i].to_bits(), f.cy[i].to_bits(), f.cz[i].to_bits()], i)).collect(),
        }
    }
}

impl Rbf {
    /// [`Rbf::gradient`] at every point, with a bound on each one's error (module doc). Exact
    /// (bound 0) where single precision does not apply: the cubic kernel, a CPU without AVX2 + FMA.
    /// Polls `progress` between chunks.
    pub fn gradients_bounded(&self, points: &[Point3], progress: &Progress) -> Result<Vec<BoundedGradient>> {
        let mut out = vec![([[0.0; 3]; 3], 0.0); points.len()];
        #[cfg(target_arch = "x86_64")]
        let fast = self.kernel == Kernel::Linear
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
        #[cfg(not(target_arch = "x86_64"))]
        let fast = false;
        let centres = fast.then(|| Centres32::new(self));
        const CHUNK: usize = 32_768;
        for (ci, (o, p)) in out.chunks_mut(CHUNK).zip(points.chunks(CHUNK)).enumerate() {
            progress.fraction((ci * CHUNK) as f64 / points.len().max(1) as f64)?;
            o.par_chunks_mut(256).zip(p.par_chunks(256)).for_each(|(o, p)| {
                for (o, &p) in o.iter_mut().zip(p) {
                    *o = match &centres {
                        Some(c) => self.gradient_f32(c, p),
                        None => (self.gradient(p), 0.0),
                    };
                }
            });
        }
        Ok(out)
    }

    /// The single-precision gradient at `p` and its bound (linear kernel, AVX2 + FMA checked).
    fn gradient_f32(&self, c: &Centres32, p: Point3) -> BoundedGradient {
        let q = [
            (p[0] - self.origin[0]) / self.scale,
            (p[1] - self.origin[1]) / self.scale,
            (p[2] - self.origin[2]) / self.scale,
        ];
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `gradients_bounded` builds `Centres32` only after detecting AVX2 and FMA.
        let (sums, e, z) = unsafe { sums_avx2(c, q.map(|x| x as f32)) };
        #[cfg(not(target_arch = "x86_64"))]
        let (sums, e, z) = ([0.0; 9], f64::INFINITY, 0.0);
        // The centre the point sits on, if any: its lane was left out, as in the exact sum (the
        // rest of `z`, padded by the f32 sum's rounding, still counts).
        let z = match c.at.get(&q.map(f64::to_bits)) {
            Some(&k) => {
                let own = c.w_abs[k] as f64;
                let rest = z - own;
                if rest <= 1e-5 * z {
                    0.0
                } else {
                    rest + 1e-5 * z
                }
            }
            None => z,
        };
        let m = c.c_max.max(q[0].abs()).max(q[1].abs()).max(q[2].abs());
        let entry = U * (5.6 * m * e * 1.01 + (18 + BLOCK) as f64 * c.w_sum) + z;
        let bound = 2.0 * 3.0 * entry / self.scale;
        let mut g = [[0.0; 3]; 3];
        for (r, row) in g.iter_mut().enumerate() {
            for (k, x) in row.iter_mut().enumerate() {
                *x = (sums[r * 3 + k] + self.affine[k][r]) / self.scale;
            }
        }
        (g, if bound.is_finite() { bound } else { f64::INFINITY })
    }
}

/// Σ_i α_i ⊗ (q − c_i)/r_i (row-major), E = Σ|α_i|/r_i and Z = Σ|α_i| over the terms left out,
/// 8 centres per instruction in f32, blocks of [`BLOCK`] added in f64.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn sums_avx2(c: &Centres32, q: [f32; 3]) -> ([f64; 9], f64, f64) {
    use std::arch::x86_64::*;
    let n = c.w_abs.len();
    let (cx, cy, cz) = (&c.c[0][..n], &c.c[1][..n], &c.c[2][..n]);
    let (wx, wy, wz, wa) = (&c.w[0][..n], &c.w[1][..n], &c.w[2][..n], &c.w_abs[..n]);
    let (qx, qy, qz) = (_mm256_set1_ps(q[0]), _mm256_set1_ps(q[1]), _mm256_set1_ps(q[2]));
    let (half, three_halves, tiny) = (_mm256_set1_ps(0.5), _mm256_set1_ps(1.5), _mm256_set1_ps(TINY_R2));
    let mut total = [0.0f64; 11];
    let lanes = |v: __m256| {
        let mut a = [0.0f32; 8];
        _mm256_storeu_ps(a.as_mut_ptr(), v);
        a.iter().map(|&x| x as f64).sum::<f64>()
    };
    let mut start = 0;
    while start < n {
        let end = (start + 8 * BLOCK).min(n);
        let mut acc = [_mm256_setzero_ps(); 11];
        let mut j = start;
        while j < end {
            // SAFETY: n is a multiple of 8 and j + 8 ≤ end ≤ n for every slice (all have length n).
            let d = [
                _mm256_sub_ps(qx, _mm256_loadu_ps(cx.as_ptr().add(j))),
                _mm256_sub_ps(qy, _mm256_loadu_ps(cy.as_ptr().add(j))),
                _mm256_sub_ps(qz, _mm256_loadu_ps(cz.as_ptr().add(j))),
            ];
            let r2 = _mm256_fmadd_ps(d[2], d[2], _mm256_fmadd_ps(d[1], d[1], _mm256_mul_ps(d[0], d[0])));
            // 1/r: the 12-bit estimate and one Newton step, y(1.5 − 0.5·r²·y²); 0 where r² is tiny.
            let y0 = _mm256_rsqrt_ps(r2);
            let hy = _mm256_mul_ps(_mm256_mul_ps(half, r2), y0);
            let y = _mm256_mul_ps(y0, _mm256_fnmadd_ps(hy, y0, three_halves));
            let keep = _mm256_cmp_ps::<_CMP_GT_OQ>(r2, tiny);
            let y = _mm256_and_ps(y, keep);
            let w_abs = _mm256_loadu_ps(wa.as_ptr().add(j));
            acc[9] = _mm256_fmadd_ps(w_abs, y, acc[9]);
            acc[10] = _mm256_add_ps(acc[10], _mm256_andnot_ps(keep, w_abs));
            let a = [
                _mm256_mul_ps(y, _mm256_loadu_ps(wx.as_ptr().add(j))),
                _mm256_mul_ps(y, _mm256_loadu_ps(wy.as_ptr().add(j))),
                _mm256_mul_ps(y, _mm256_loadu_ps(wz.as_ptr().add(j))),
            ];
            for r in 0..3 {
                for k in 0..3 {
                    acc[r * 3 + k] = _mm256_fmadd_ps(a[r], d[k], acc[r * 3 + k]);
                }
            }
            j += 8;
        }
        for (t, &a) in total.iter_mut().zip(&acc) {
            *t += lanes(a);
        }
        start = end;
    }
    let mut sums = [0.0; 9];
    sums.copy_from_slice(&total[..9]);
    (sums, total[9], total[10])
}
