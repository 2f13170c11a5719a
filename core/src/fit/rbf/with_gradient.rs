//! The field and its Jacobian at many points in one pass: the fine stage moves every vertex by the
//! field and the orientation count ([`crate::fit::orientation`]) needs the field's Jacobian at the
//! same points. Both sums run over the same distances r_i = |q − c_i| (φ(r) = r: value Σ α_i r_i,
//! gradient Σ α_i ⊗ (q − c_i)/r_i), so one loop computes both, in double precision: a division and
//! twelve multiply-adds per centre on top of the value's square root. Before, a second pass summed
//! the gradient in single precision with error bounds ([`Rbf::gradients_bounded`]), ~0.25 s of CPU
//! on the headline (100k points × 2,156 centres; session 16).
//!
//! The values are bitwise those of [`Rbf::eval_many`] (the same operations in the same order), so
//! the fit's output does not change. The gradients equal [`Rbf::gradient`]'s up to the rounding
//! of a double-precision sum (4 lanes with fused multiply-adds instead of one serial sum): the
//! count takes them as exact, as it takes [`Rbf::gradient`].

use rayon::prelude::*;

use crate::error::Result;
use crate::job::Progress;
use crate::mesh::Point3;

use super::{Kernel, Rbf};

/// `g[r][c]` = ∂(displacement r)/∂(p c), as [`Rbf::gradient`] gives it.
pub type Gradient = [[f64; 3]; 3];

impl Rbf {
    /// [`Rbf::eval_many`] and [`Rbf::gradient`] at every point (module doc). Polls `progress`
    /// between chunks.
    pub fn eval_with_gradients(
        &self,
        points: &[Point3],
        progress: &Progress,
    ) -> Result<(Vec<Point3>, Vec<Gradient>)> {
        let mut values = vec![[0.0; 3]; points.len()];
        let mut grads = vec![[[0.0; 3]; 3]; points.len()];
        #[cfg(target_arch = "x86_64")]
        let fused = self.kernel == Kernel::Linear
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
        #[cfg(not(target_arch = "x86_64"))]
        let fused = false;
        const CHUNK: usize = 32_768;
        let chunks = values.chunks_mut(CHUNK).zip(grads.chunks_mut(CHUNK)).zip(points.chunks(CHUNK));
        for (ci, ((v, g), p)) in chunks.enumerate() {
            progress.fraction((ci * CHUNK) as f64 / points.len().max(1) as f64)?;
            v.par_chunks_mut(256).zip(g.par_chunks_mut(256)).zip(p.par_chunks(256)).for_each(
                |((v, g), p)| {
                    for ((v, g), &p) in v.iter_mut().zip(g.iter_mut()).zip(p) {
                        (*v, *g) =
                            if fused { self.eval_and_gradient(p) } else { (self.eval(p), self.gradient(p)) };
                    }
                },
            );
        }
        Ok((values, grads))
    }

    /// Without the fused kernel (not x86-64; `eval_with_gradients` never calls it there).
    #[cfg(not(target_arch = "x86_64"))]
    fn eval_and_gradient(&self, p: Point3) -> (Point3, Gradient) {
        (self.eval(p), self.gradient(p))
    }

    /// The value and gradient at `p` from one fused sum (linear kernel, AVX2 + FMA checked).
    #[cfg(target_arch = "x86_64")]
    fn eval_and_gradient(&self, p: Point3) -> (Point3, Gradient) {
        let q = self.normalised(p);
        // SAFETY: `eval_with_gradients` calls this only after detecting AVX2 and FMA.
        let (radial, sums) = unsafe { self.radial_and_gradient_avx2(q) };
        let mut g = [[0.0; 3]; 3];
        for (r, row) in g.iter_mut().enumerate() {
            for (c, x) in row.iter_mut().enumerate() {
                *x = (sums[r * 3 + c] + self.affine[c][r]) / self.scale;
            }
        }
        (self.with_affine(q, radial), g)
    }

    /// [`Rbf::radial_avx2`] for φ(r) = r (the same operations, so the same sums), and
    /// Σ_j α_j ⊗ (q − c_j)/r_j (row-major) beside it. A point on a centre (r = 0) gets no term
    /// from it, as in [`Rbf::gradient`] (there 1/r is capped at 1e150 and multiplies q − c = 0).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn radial_and_gradient_avx2(&self, q: Point3) -> ((f64, f64, f64), [f64; 9]) {
        use std::arch::x86_64::*;
        let n = self.cx.len();
        let (cx, cy, cz) = (&self.cx[..n], &self.cy[..n], &self.cz[..n]);
        let (wx, wy, wz) = (&self.w[0][..n], &self.w[1][..n], &self.w[2][..n]);
        let (qx, qy, qz) = (_mm256_set1_pd(q[0]), _mm256_set1_pd(q[1]), _mm256_set1_pd(q[2]));
        let (mut ax, mut ay, mut az) = (_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd());
        let mut acc = [_mm256_setzero_pd(); 9];
        let (one, floor) = (_mm256_set1_pd(1.0), _mm256_set1_pd(1e-150));
        let chunks = n / 4;
        for c in 0..chunks {
            let j = c * 4;
            // SAFETY: j + 4 ≤ n for every slice (all have length n).
            let d = [
                _mm256_sub_pd(qx, _mm256_loadu_pd(cx.as_ptr().add(j))),
                _mm256_sub_pd(qy, _mm256_loadu_pd(cy.as_ptr().add(j))),
                _mm256_sub_pd(qz, _mm256_loadu_pd(cz.as_ptr().add(j))),
            ];
            let r2 = _mm256_fmadd_pd(d[2], d[2], _mm256_fmadd_pd(d[1], d[1], _mm256_mul_pd(d[0], d[0])));
            let r = _mm256_sqrt_pd(r2);
            let w = [
                _mm256_loadu_pd(wx.as_ptr().add(j)),
                _mm256_loadu_pd(wy.as_ptr().add(j)),
                _mm256_loadu_pd(wz.as_ptr().add(j)),
            ];
            ax = _mm256_fmadd_pd(r, w[0], ax);
            ay = _mm256_fmadd_pd(r, w[1], ay);
            az = _mm256_fmadd_pd(r, w[2], az);
            let y = _mm256_div_pd(one, _mm256_max_pd(r, floor));
            for (row, &wr) in w.iter().enumerate() {
                let a = _mm256_mul_pd(y, wr);
                for (k, &dk) in d.iter().enumerate() {
                    acc[row * 3 + k] = _mm256_fmadd_pd(a, dk, acc[row * 3 + k]);
                }
            }
        }
        let hsum = |v: __m256d| {
            let mut a = [0.0f64; 4];
            _mm256_storeu_pd(a.as_mut_ptr(), v);
            (a[0] + a[1]) + (a[2] + a[3])
        };
        let (mut sx, mut sy, mut sz) = (hsum(ax), hsum(ay), hsum(az));
        let mut g: [f64; 9] = std::array::from_fn(|k| hsum(acc[k]));
        for j in chunks * 4..n {
            let (dx, dy, dz) = (q[0] - cx[j], q[1] - cy[j], q[2] - cz[j]);
            let r2 = dx * dx + dy * dy + dz * dz;
            let f = r2.sqrt();
            sx += f * wx[j];
            sy += f * wy[j];
            sz += f * wz[j];
            let y = 1.0 / f.max(1e-150);
            for (row, wr) in [wx[j], wy[j], wz[j]].into_iter().enumerate() {
                for (k, dk) in [dx, dy, dz].into_iter().enumerate() {
                    g[row * 3 + k] += y * wr * dk;
                }
            }
        }
        ((sx, sy, sz), g)
    }
}
