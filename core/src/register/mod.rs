//! Rigid and similarity registration (seed 003 §2.1, §4.3): PCA normalisation with a deterministic
//! axis-sign rule, Procrustes with known correspondences (Horn's quaternion method, seed 003
//! eq. 2.4), and point-to-plane ICP against a surface (closest points from the shared BVH, [`crate::spatial::Bvh`]).
//! Used by the morph job; available to `fit`.

use crate::geometry::{add, cross, dot, norm, scale, sub, triangle_area};
use crate::mesh::Point3;

/// x ↦ s·R·x + t.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Similarity {
    /// Row-major rotation (proper: det = +1).
    pub rotation: [[f64; 3]; 3],
    pub scale: f64,
    pub translation: Point3,
}

impl Default for Similarity {
    fn default() -> Self {
        Similarity::IDENTITY
    }
}

impl Similarity {
    pub const IDENTITY: Similarity = Similarity {
        rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        scale: 1.0,
        translation: [0.0; 3],
    };

    pub fn apply(&self, p: Point3) -> Point3 {
        add(scale(mat_vec(&self.rotation, p), self.scale), self.translation)
    }

    pub fn inverse(&self) -> Similarity {
        let rt = transpose(&self.rotation);
        let s = 1.0 / self.scale;
        Similarity { rotation: rt, scale: s, translation: scale(mat_vec(&rt, self.translation), -s) }
    }

    /// `self ∘ other` (apply `other` first).
    pub fn then_after(&self, other: &Similarity) -> Similarity {
        Similarity {
            rotation: mat_mul(&self.rotation, &other.rotation),
            scale: self.scale * other.scale,
            translation: self.apply(other.translation),
        }
    }
}

pub fn mat_vec(m: &[[f64; 3]; 3], v: Point3) -> Point3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

fn transpose(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = m[j][i];
        }
    }
    t
}

fn mat_mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// Eigen-decomposition of a small symmetric matrix (row-major n×n) by cyclic Jacobi rotations.
/// Returns eigenvalues (descending) and the matching unit eigenvectors.
pub fn symmetric_eigen(a: &[f64], n: usize) -> (Vec<f64>, Vec<Vec<f64>>) {
    let mut a = a.to_vec();
    let mut v = vec![0.0; n * n];
    for i in 0..n {
        v[i * n + i] = 1.0;
    }
    for _sweep in 0..64 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * n + j].powi(2))
            .sum();
        let diag: f64 = (0..n).map(|i| a[i * n + i].powi(2)).sum();
        if off <= 1e-30 * diag.max(1e-300) {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = a[p * n + q];
                if apq.abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let akp = a[k * n + p];
                    let akq = a[k * n + q];
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                for k in 0..n {
                    let apk = a[p * n + k];
                    let aqk = a[q * n + k];
                    a[p * n + k] = c * apk - s * aqk;
                    a[q * n + k] = s * apk + c * aqk;
                }
                for k in 0..n {
                    let vkp = v[k * n + p];
                    let vkq = v[k * n + q];
                    v[k * n + p] = c * vkp - s * vkq;
                    v[k * n + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    let mut idx: Vec<usize> = (0..n).collect();
    idx.sort_by(|&i, &j| a[j * n + j].partial_cmp(&a[i * n + i]).unwrap_or(std::cmp::Ordering::Equal));
    let vals = idx.iter().map(|&i| a[i * n + i]).collect();
    let vecs = idx.iter().map(|&i| (0..n).map(|k| v[k * n + i]).collect()).collect();
    (vals, vecs)
}

/// The result of PCA normalisation.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct PcaFrame {
    /// Maps the input into the normalised frame: centroid at the origin, principal axes on x, y, z
    /// (largest variance first), farthest vertex at distance 1.
    pub to_normalised: Similarity,
    /// Principal variances (descending), in input units².
    pub variances: [f64; 3],
    /// Third moment along each normalised axis (after the sign rule: ≥ 0 except possibly the
    /// axis flipped to keep the frame right-handed).
    pub skewness: [f64; 3],
}

/// PCA normalisation of a triangle surface. Moments are area-weighted over the surface (so two
/// meshes of one shape sampled differently get the same frame), and each axis sign is chosen so
/// that the surface's third moment along it is positive (seed 003 Fig. 4.8: unchecked signs flip
/// shapes). The axis whose third moment is smallest in magnitude gives way when the three signs
/// would make a left-handed frame.
pub fn pca_frame(pos: &[Point3], tris: &[[u32; 3]]) -> PcaFrame {
    // Area-weighted centroid and second moments, integrating each triangle exactly (for linear x,
    // ∫x xᵀ over a triangle = A/12 (Σ pᵢpᵢᵀ + (Σpᵢ)(Σpᵢ)ᵀ)).
    let mut area = 0.0;
    let mut c = [0.0; 3];
    for t in tris {
        let (a, b, d) = (pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
        let ar = triangle_area(a, b, d);
        area += ar;
        c = add(c, scale(add(add(a, b), d), ar / 3.0));
    }
    if area <= 0.0 {
        // Degenerate surface: fall back to the vertex average (scale below still guards).
        area = 1.0;
        c = scale(pos.iter().fold([0.0; 3], |s, &p| add(s, p)), 1.0 / pos.len().max(1) as f64);
    } else {
        c = scale(c, 1.0 / area);
    }
    let mut cov = [0.0; 9];
    for t in tris {
        let p = [sub(pos[t[0] as usize], c), sub(pos[t[1] as usize], c), sub(pos[t[2] as usize], c)];
        let ar = triangle_area(p[0], p[1], p[2]);
        let s = add(add(p[0], p[1]), p[2]);
        for i in 0..3 {
            for j in 0..3 {
                let sum_pp: f64 = p.iter().map(|q| q[i] * q[j]).sum();
                cov[i * 3 + j] += ar / 12.0 * (sum_pp + s[i] * s[j]);
            }
        }
    }
    for x in &mut cov {
        *x /= area.max(1e-300);
    }
    let (vals, vecs) = symmetric_eigen(&cov, 3);
    let mut axes: [Point3; 3] = [0, 1, 2].map(|i| [vecs[i][0], vecs[i][1], vecs[i][2]]);
    // Third moments along each axis, by 6-point quadrature-free vertex/area weighting (exact for
    // the sign decision's purpose: a smooth, sampling-independent statistic).
    let mut skew = [0.0; 3];
    for t in tris {
        let p = [sub(pos[t[0] as usize], c), sub(pos[t[1] as usize], c), sub(pos[t[2] as usize], c)];
        let ar = triangle_area(p[0], p[1], p[2]);
        let m = scale(add(add(p[0], p[1]), p[2]), 1.0 / 3.0);
        for k in 0..3 {
            // Mean of x³ over the triangle approximated by the average over corners and centroid.
            let vals: f64 =
                p.iter().map(|q| dot(*q, axes[k]).powi(3)).sum::<f64>() + 3.0 * dot(m, axes[k]).powi(3);
            skew[k] += ar * vals / 6.0;
        }
    }
    for k in 0..3 {
        if skew[k] < 0.0 {
            axes[k] = scale(axes[k], -1.0);
            skew[k] = -skew[k];
        }
    }
    if dot(cross(axes[0], axes[1]), axes[2]) < 0.0 {
        let weakest = (0..3)
            .min_by(|&i, &j| skew[i].partial_cmp(&skew[j]).unwrap_or(std::cmp::Ordering::Equal))
            .unwrap_or(2);
        axes[weakest] = scale(axes[weakest], -1.0);
        skew[weakest] = -skew[weakest];
    }
    let rotation = [axes[0], axes[1], axes[2]];
    let rmax = pos.iter().map(|&p| norm(sub(p, c))).fold(0.0, f64::max);
    let s = if rmax > 0.0 { 1.0 / rmax } else { 1.0 };
    let rot_c = mat_vec(&rotation, c);
    PcaFrame {
        to_normalised: Similarity { rotation, scale: s, translation: scale(rot_c, -s) },
        variances: [vals[0], vals[1], vals[2]],
        skewness: skew,
    }
}

/// The similarity (or rigid motion, `with_scale = false`) minimising Σ|T(srcᵢ) − dstᵢ|² for paired
/// points, by Horn's closed form: the rotation is the unit quaternion of the largest eigenvalue of
/// the 4×4 matrix built from the cross-covariance (seed 003 eq. 2.2–2.8).
pub fn procrustes(src: &[Point3], dst: &[Point3], with_scale: bool) -> Similarity {
    let n = src.len().min(dst.len());
    if n == 0 {
        return Similarity::IDENTITY;
    }
    let mu_s = scale(src[..n].iter().fold([0.0; 3], |a, &p| add(a, p)), 1.0 / n as f64);
    let mu_d = scale(dst[..n].iter().fold([0.0; 3], |a, &p| add(a, p)), 1.0 / n as f64);
    let mut sig = [[0.0; 3]; 3];
    let mut ss = 0.0;
    for i in 0..n {
        let a = sub(src[i], mu_s);
        let b = sub(dst[i], mu_d);
        ss += dot(a, a);
        for r in 0..3 {
            for c in 0..3 {
                sig[r][c] += a[r] * b[c];
            }
        }
    }
    let tr = sig[0][0] + sig[1][1] + sig[2][2];
    let d = [sig[1][2] - sig[2][1], sig[2][0] - sig[0][2], sig[0][1] - sig[1][0]];
    let mut q = [0.0; 16];
    q[0] = tr;
    for i in 0..3 {
        q[i + 1] = d[i];
        q[(i + 1) * 4] = d[i];
        for j in 0..3 {
            q[(i + 1) * 4 + j + 1] = sig[i][j] + sig[j][i] - if i == j { tr } else { 0.0 };
        }
    }
    let (_, vecs) = symmetric_eigen(&q, 4);
    let (q0, q1, q2, q3) = (vecs[0][0], vecs[0][1], vecs[0][2], vecs[0][3]);
    let rotation = [
        [q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, 2.0 * (q1 * q2 - q0 * q3), 2.0 * (q1 * q3 + q0 * q2)],
        [2.0 * (q1 * q2 + q0 * q3), q0 * q0 + q2 * q2 - q1 * q1 - q3 * q3, 2.0 * (q2 * q3 - q0 * q1)],
        [2.0 * (q1 * q3 - q0 * q2), 2.0 * (q2 * q3 + q0 * q1), q0 * q0 + q3 * q3 - q1 * q1 - q2 * q2],
    ];
    let s = if with_scale && ss > 0.0 {
        let num: f64 = (0..n).map(|i| dot(sub(dst[i], mu_d), mat_vec(&rotation, sub(src[i], mu_s)))).sum();
        (num / ss).max(1e-12)
    } else {
        1.0
    };
    let translation = sub(mu_d, scale(mat_vec(&rotation, mu_s), s));
    Similarity { rotation, scale: s, translation }
}

/// Outcome of [`icp`].
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct IcpResult {
    /// Maps the source points onto the target surface (rigid).
    pub transform: Similarity,
    pub iterations: usize,
    /// RMS point-to-surface distance before and after.
    pub rms_before: f64,
    pub rms_after: f64,
}

/// The surface ICP registers onto: the shared closest-point BVH ([`crate::spatial::Bvh`]) and
/// the unit normal of each triangle (zero for a degenerate one).
pub struct IcpTarget {
    bvh: crate::spatial::Bvh,
    normals: Vec<Point3>,
}

impl IcpTarget {
    pub fn new(pos: &[Point3], tris: &[[u32; 3]]) -> IcpTarget {
        let normals = tris
            .iter()
            .map(|t| {
                let n = cross(
                    sub(pos[t[1] as usize], pos[t[0] as usize]),
                    sub(pos[t[2] as usize], pos[t[0] as usize]),
                );
                let l = norm(n);
                if l > 0.0 {
                    scale(n, 1.0 / l)
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        IcpTarget { bvh: crate::spatial::Bvh::new(pos, &crate::mesh::Faces::from_triangles(tris)), normals }
    }

    fn closest(&self, p: Point3) -> Option<crate::spatial::Closest> {
        self.bvh.closest(p)
    }
}

/// Rigid point-to-plane ICP (seed 003 §2.1; Rusinkiewicz–Levoy's faster-converging metric): pairs
/// each source point with its closest surface point, solves the linearised 6×6 least-squares
/// system for a small rotation + translation, repeats until the RMS stops improving.
pub fn icp(src: &[Point3], target: &IcpTarget, max_iterations: usize) -> IcpResult {
    let mut total = Similarity::IDENTITY;
    let mut cur: Vec<Point3> = src.to_vec();
    let rms_of = |pts: &[Point3]| -> f64 {
        let s: f64 = pts.iter().filter_map(|&p| target.closest(p)).map(|h| h.dist2).sum();
        (s / pts.len().max(1) as f64).sqrt()
    };
    let rms_before = rms_of(&cur);
    let mut rms = rms_before;
    let mut it = 0;
    while it < max_iterations {
        it += 1;
        let mut ata = [0.0; 36];
        let mut atb = [0.0; 6];
        for &p in &cur {
            let Some(h) = target.closest(p) else { continue };
            let nrm = target.normals[h.face as usize];
            if dot(nrm, nrm) == 0.0 {
                continue;
            }
            let cxn = cross(p, nrm);
            let row = [cxn[0], cxn[1], cxn[2], nrm[0], nrm[1], nrm[2]];
            let r = dot(sub(h.point, p), nrm);
            for i in 0..6 {
                atb[i] += row[i] * r;
                for j in 0..6 {
                    ata[i * 6 + j] += row[i] * row[j];
                }
            }
        }
        let Some(x) = solve_dense(&ata, &atb, 6) else { break };
        // Small-angle rotation (α, β, γ) made exact by orthonormalising through a quaternion.
        let (a, b, g) = (x[0], x[1], x[2]);
        let q = [1.0, a / 2.0, b / 2.0, g / 2.0];
        let qn = (q.iter().map(|v| v * v).sum::<f64>()).sqrt();
        let (q0, q1, q2, q3) = (q[0] / qn, q[1] / qn, q[2] / qn, q[3] / qn);
        let rotation = [
            [q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, 2.0 * (q1 * q2 - q0 * q3), 2.0 * (q1 * q3 + q0 * q2)],
            [2.0 * (q1 * q2 + q0 * q3), q0 * q0 + q2 * q2 - q1 * q1 - q3 * q3, 2.0 * (q2 * q3 - q0 * q1)],
            [2.0 * (q1 * q3 - q0 * q2), 2.0 * (q2 * q3 + q0 * q1), q0 * q0 + q3 * q3 - q1 * q1 - q2 * q2],
        ];
        let step = Similarity { rotation, scale: 1.0, translation: [x[3], x[4], x[5]] };
        let next: Vec<Point3> = cur.iter().map(|&p| step.apply(p)).collect();
        let new_rms = rms_of(&next);
        if new_rms >= rms * (1.0 - 1e-6) {
            break;
        }
        cur = next;
        total = step.then_after(&total);
        rms = new_rms;
    }
    IcpResult { transform: total, iterations: it, rms_before, rms_after: rms }
}

/// Gaussian elimination with partial pivoting on a small dense system; None when singular.
pub fn solve_dense(a: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut m = a.to_vec();
    let mut x = b.to_vec();
    let scale_ref = m.iter().fold(0.0f64, |s, v| s.max(v.abs())).max(1e-300);
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| {
            m[i * n + col].abs().partial_cmp(&m[j * n + col].abs()).unwrap_or(std::cmp::Ordering::Equal)
        })?;
        if m[piv * n + col].abs() <= 1e-14 * scale_ref {
            return None;
        }
        if piv != col {
            for k in 0..n {
                m.swap(piv * n + k, col * n + k);
            }
            x.swap(piv, col);
        }
        let d = m[col * n + col];
        for r in col + 1..n {
            let f = m[r * n + col] / d;
            if f == 0.0 {
                continue;
            }
            for k in col..n {
                m[r * n + k] -= f * m[col * n + k];
            }
            x[r] -= f * x[col];
        }
    }
    for col in (0..n).rev() {
        let mut s = x[col];
        for k in col + 1..n {
            s -= m[col * n + k] * x[k];
        }
        x[col] = s / m[col * n + col];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(axis: Point3, angle: f64) -> [[f64; 3]; 3] {
        let a = crate::geometry::normalize(axis);
        let (s, c) = angle.sin_cos();
        let t = 1.0 - c;
        [
            [t * a[0] * a[0] + c, t * a[0] * a[1] - s * a[2], t * a[0] * a[2] + s * a[1]],
            [t * a[0] * a[1] + s * a[2], t * a[1] * a[1] + c, t * a[1] * a[2] - s * a[0]],
            [t * a[0] * a[2] - s * a[1], t * a[1] * a[2] + s * a[0], t * a[2] * a[2] + c],
        ]
    }

    #[test]
    fn procrustes_recovers_known_similarity() {
        let truth =
            Similarity { rotation: rot([1.0, 2.0, -0.5], 1.1), scale: 2.5, translation: [3.0, -1.0, 0.25] };
        let src: Vec<Point3> = (0..30)
            .map(|i| {
                let t = i as f64;
                [t.sin(), (1.3 * t).cos() * 2.0, (0.7 * t).sin() - 0.3]
            })
            .collect();
        let dst: Vec<Point3> = src.iter().map(|&p| truth.apply(p)).collect();
        let est = procrustes(&src, &dst, true);
        assert!((est.scale - 2.5).abs() < 1e-10);
        for i in 0..3 {
            assert!((est.translation[i] - truth.translation[i]).abs() < 1e-9);
            for j in 0..3 {
                assert!((est.rotation[i][j] - truth.rotation[i][j]).abs() < 1e-10);
            }
        }
    }

    #[test]
    fn pca_normalises_a_moved_ellipsoid_to_the_same_frame() {
        // An asymmetric blob: an icosphere stretched along axes and bulged on +x (so the third
        // moment fixes the signs). Moving it by a known similarity must not change its normal form.
        let mut m = crate::shapes::icosphere(3, 1.0);
        for p in &mut m.positions {
            let bulge = if p[0] > 0.0 { 1.0 + 0.5 * p[0] } else { 1.0 };
            *p = [3.0 * p[0] * bulge, 2.0 * p[1] + 0.3 * p[0] * p[0], 1.0 * p[2] + 0.2 * p[1] * p[1]];
        }
        let tris = crate::shapes::fan_triangles(&m.faces);
        let f0 = pca_frame(&m.positions, &tris);
        let moved =
            Similarity { rotation: rot([0.3, -1.0, 0.8], 2.3), scale: 0.2, translation: [10.0, 5.0, -7.0] };
        let p2: Vec<Point3> = m.positions.iter().map(|&p| moved.apply(p)).collect();
        let f1 = pca_frame(&p2, &tris);
        for (a, b) in m.positions.iter().zip(&p2) {
            let x = f0.to_normalised.apply(*a);
            let y = f1.to_normalised.apply(*b);
            assert!(norm(sub(x, y)) < 1e-9, "{x:?} vs {y:?}");
        }
        let det = dot(
            cross(f0.to_normalised.rotation[0], f0.to_normalised.rotation[1]),
            f0.to_normalised.rotation[2],
        );
        assert!((det - 1.0).abs() < 1e-12);
    }

    #[test]
    fn icp_recovers_a_small_rigid_motion() {
        let mut m = crate::shapes::icosphere(3, 1.0);
        for p in &mut m.positions {
            *p = [2.0 * p[0], p[1] + 0.3 * p[0] * p[0], 0.6 * p[2]];
        }
        let tris = crate::shapes::fan_triangles(&m.faces);
        let idx = IcpTarget::new(&m.positions, &tris);
        let motion =
            Similarity { rotation: rot([0.2, 1.0, 0.1], 0.12), scale: 1.0, translation: [0.05, -0.04, 0.03] };
        let src: Vec<Point3> = m.positions.iter().map(|&p| motion.apply(p)).collect();
        let r = icp(&src, &idx, 100);
        assert!(r.rms_after < 1e-3 * r.rms_before.max(1e-3), "{r:?}");
        let back = r.transform.then_after(&motion);
        for i in 0..3 {
            assert!(back.translation[i].abs() < 1e-3, "{back:?}");
        }
    }
}
