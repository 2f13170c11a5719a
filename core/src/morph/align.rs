//! Feature alignment on the sphere (seed 002 §5.7): the parameterisations are first rotated onto
//! each other (Procrustes about the centre on the feature points), then every feature point is
//! moved towards the normalised mean of its partners by a stepwise compactly supported RBF warp
//! (CTPS C²a with a linear polynomial, seed 002 Table V.1 row 7), re-projecting onto the sphere
//! after each step. A step that would flip a spherical triangle is split in two; vertex moves that
//! would flip a sliver of the map (rounding alone does that) are held back (`held_vertices`).
//!
//! CTPS C²a: φ(h) = 1 − 30h² − 10h³ + 45h⁴ − 6h⁵ − 60h³·ln h for h < 1, else 0. The thesis prints
//! log₂; with log₂ φ'(1) = 60 − 60/ln 2 ≠ 0, so the function would not be C² (not even C¹) at
//! the support boundary. With the natural log φ(1) = φ'(1) = φ''(1) = 0, as de Boer et al. (the
//! thesis's source) intend; we use ln.

use crate::error::{Error, Result};
use crate::geometry::{add, dot, norm, normalize, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;
use crate::register::{mat_vec, procrustes, solve_dense};

use super::param::count_foldovers;
use super::sphere_fallback::orient_sign;

/// CTPS C²a (natural log; see the module docs).
pub fn ctps_c2a(h: f64) -> f64 {
    if h >= 1.0 {
        return 0.0;
    }
    if h <= 0.0 {
        return 1.0;
    }
    1.0 - 30.0 * h * h - 10.0 * h.powi(3) + 45.0 * h.powi(4) - 6.0 * h.powi(5) - 60.0 * h.powi(3) * h.ln()
}

/// s(x) = Σ αᵢ φ(|x − cᵢ|/r) + β·[1 x y z], interpolating displacements at the centres.
pub struct RbfWarp {
    centres: Vec<Point3>,
    alpha: Vec<Point3>,
    beta: [Point3; 4],
    radius: f64,
}

impl RbfWarp {
    /// Solves the (n+4)² system of eq. V.20 per coordinate. The polynomial block carries a tiny
    /// negative diagonal so that fewer than 4 centres (an under-determined affine part) give the
    /// least-norm solution, as the thesis's SVD pseudo-inverse does.
    pub fn fit(centres: &[Point3], disp: &[Point3], radius: f64) -> Result<RbfWarp> {
        let n = centres.len();
        let m = n + 4;
        let mut a = vec![0.0; m * m];
        for i in 0..n {
            for j in 0..n {
                a[i * m + j] = ctps_c2a(norm(sub(centres[i], centres[j])) / radius);
            }
            let row = [1.0, centres[i][0], centres[i][1], centres[i][2]];
            for k in 0..4 {
                a[i * m + n + k] = row[k];
                a[(n + k) * m + i] = row[k];
            }
        }
        for k in 0..4 {
            a[(n + k) * m + n + k] = -1e-9;
        }
        let mut sol = vec![[0.0; 3]; m];
        for d in 0..3 {
            let mut b = vec![0.0; m];
            for i in 0..n {
                b[i] = disp[i][d];
            }
            let x = solve_dense(&a, &b, m).ok_or_else(|| {
                Error::params("features", "feature points coincide on the sphere; the warp is singular")
            })?;
            for i in 0..m {
                sol[i][d] = x[i];
            }
        }
        Ok(RbfWarp {
            centres: centres.to_vec(),
            alpha: sol[..n].to_vec(),
            beta: [sol[n], sol[n + 1], sol[n + 2], sol[n + 3]],
            radius,
        })
    }

    pub fn displacement(&self, x: Point3) -> Point3 {
        let mut d = add(
            self.beta[0],
            add(scale(self.beta[1], x[0]), add(scale(self.beta[2], x[1]), scale(self.beta[3], x[2]))),
        );
        for (c, a) in self.centres.iter().zip(&self.alpha) {
            let r = norm(sub(x, *c));
            if r < self.radius {
                d = add(d, scale(*a, ctps_c2a(r / self.radius)));
            }
        }
        d
    }
}

/// Point at fraction t along the great arc from a to b.
pub fn slerp(a: Point3, b: Point3, t: f64) -> Point3 {
    let c = dot(a, b).clamp(-1.0, 1.0);
    let th = c.acos();
    if th < 1e-12 {
        return b;
    }
    let s = th.sin();
    normalize(add(scale(a, ((1.0 - t) * th).sin() / s), scale(b, (t * th).sin() / s)))
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct AlignReport {
    pub feature_points: usize,
    /// Rotation angle (radians) applied to each input's sphere to pre-align its features to input 0's.
    pub prealign_rotation: Vec<f64>,
    pub warp_steps: Vec<usize>,
    /// Largest angle (radians) between a feature point and its goal before and after the warp.
    pub max_feature_gap_before: f64,
    pub max_feature_gap_after: f64,
    /// Vertex moves undone because they would have flipped a spherical triangle (summed over
    /// steps and inputs; those vertices keep their place for that step).
    pub held_vertices: usize,
    /// Faces flipped after alignment (must be 0).
    pub foldovers: usize,
}

pub struct AlignSettings {
    pub steps: usize,
    pub support_radius: f64,
}

/// Aligns the feature points of every sphere (`features[i][k]`: vertex of feature i in input k).
pub fn align(
    spheres: &mut [Vec<Point3>],
    tris: &[&[[u32; 3]]],
    features: &[Vec<u32>],
    s: &AlignSettings,
    progress: &Progress,
) -> Result<AlignReport> {
    let mut rep = AlignReport { feature_points: features.len(), ..Default::default() };
    let k_in = spheres.len();
    if features.is_empty() {
        return Ok(rep);
    }
    // 1. Rigid pre-alignment about the centre: Procrustes on the features and their antipodes
    //    (so both centroids are the origin and only a rotation remains).
    rep.prealign_rotation.push(0.0);
    for k in 1..k_in {
        let mut src = Vec::new();
        let mut dst = Vec::new();
        for f in features {
            let (p, q) = (spheres[k][f[k] as usize], spheres[0][f[0] as usize]);
            src.extend([p, scale(p, -1.0)]);
            dst.extend([q, scale(q, -1.0)]);
        }
        let r = procrustes(&src, &dst, false);
        let tr = r.rotation[0][0] + r.rotation[1][1] + r.rotation[2][2];
        rep.prealign_rotation.push(((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos());
        for p in spheres[k].iter_mut() {
            *p = normalize(mat_vec(&r.rotation, *p));
        }
    }
    // 2. Goals: the normalised mean of each feature's positions.
    let mut goals = Vec::with_capacity(features.len());
    for (i, f) in features.iter().enumerate() {
        let m = (0..k_in).fold([0.0; 3], |a, k| add(a, spheres[k][f[k] as usize]));
        if norm(m) < 1e-6 * k_in as f64 {
            return Err(Error::params(
                format!("features[{i}]"),
                "the feature's points sit at opposite sides of the sphere; no midpoint",
            ));
        }
        goals.push(normalize(m));
    }
    let gap = |spheres: &[Vec<Point3>]| -> f64 {
        features
            .iter()
            .zip(&goals)
            .flat_map(|(f, g)| (0..k_in).map(move |k| (f[k], *g, k)))
            .map(|(v, g, k)| dot(spheres[k][v as usize], g).clamp(-1.0, 1.0).acos())
            .fold(0.0, f64::max)
    };
    rep.max_feature_gap_before = gap(spheres);
    // 3. Stepwise warp of each sphere.
    for k in 0..k_in {
        progress.fraction(k as f64 / k_in as f64)?;
        let idx: Vec<usize> = features.iter().map(|f| f[k] as usize).collect();
        let start: Vec<Point3> = idx.iter().map(|&v| spheres[k][v]).collect();
        let mut steps_done = 0;
        // Fractions of the way still to go; a failing step is split in two.
        let mut todo: Vec<(f64, u32)> = (1..=s.steps).rev().map(|j| (j as f64 / s.steps as f64, 0)).collect();
        while let Some((t, depth)) = todo.pop() {
            progress.check()?;
            let centres: Vec<Point3> = idx.iter().map(|&v| spheres[k][v]).collect();
            let want: Vec<Point3> = start.iter().zip(&goals).map(|(&a, &g)| slerp(a, g, t)).collect();
            let disp: Vec<Point3> = want.iter().zip(&centres).map(|(&w, &c)| sub(w, c)).collect();
            let warp = RbfWarp::fit(&centres, &disp, s.support_radius)?;
            let moved: Vec<Point3> =
                spheres[k].iter().map(|&x| normalize(add(x, warp.displacement(x)))).collect();
            let (moved, held) = hold_folding_vertices(&spheres[k], moved, tris[k]);
            // A few held vertices are slivers of the map flipped by rounding alone (no step is
            // small enough for them); many, or a held feature, mean the step itself folds.
            let feature_held = idx.iter().any(|&v| held[v]);
            let n_held = held.iter().filter(|&&h| h).count();
            let small = n_held <= 8 + spheres[k].len() / 1000;
            if n_held == 0 || (small && (!feature_held || depth >= 8)) {
                spheres[k] = moved;
                steps_done += 1;
                rep.held_vertices += n_held;
            } else if depth < 8 {
                // Go half-way from where the features are now, then on to t.
                let cur_t = features_progress(&spheres[k], &idx, &start, &goals);
                todo.push((t, depth + 1));
                todo.push(((cur_t + t) / 2.0, depth + 1));
            } else {
                break;
            }
        }
        rep.warp_steps.push(steps_done);
    }
    rep.max_feature_gap_after = gap(spheres);
    rep.foldovers = (0..k_in).map(|k| count_foldovers(&spheres[k], tris[k])).sum();
    Ok(rep)
}

/// The moves of one warp step without the ones that fold: every vertex of a spherical triangle
/// the step would flip (exact orientation test) keeps its old position, repeated until no
/// triangle is flipped. Terminates: at worst every vertex is held, which is the old, valid map.
fn hold_folding_vertices(
    old: &[Point3],
    mut moved: Vec<Point3>,
    tris: &[[u32; 3]],
) -> (Vec<Point3>, Vec<bool>) {
    let mut held = vec![false; old.len()];
    loop {
        let mut changed = false;
        for t in tris {
            let [a, b, c] = t.map(|v| moved[v as usize]);
            if orient_sign(a, b, c) <= 0 {
                for &v in t {
                    if !held[v as usize] {
                        held[v as usize] = true;
                        moved[v as usize] = old[v as usize];
                        changed = true;
                    }
                }
            }
        }
        if !changed {
            return (moved, held);
        }
    }
}

/// How far (0..1) the features have come along their arcs, the smallest over features.
fn features_progress(sphere: &[Point3], idx: &[usize], start: &[Point3], goals: &[Point3]) -> f64 {
    let mut t: f64 = 1.0;
    for ((&v, &a), &g) in idx.iter().zip(start).zip(goals) {
        let total = dot(a, g).clamp(-1.0, 1.0).acos();
        if total < 1e-12 {
            continue;
        }
        let left = dot(sphere[v], g).clamp(-1.0, 1.0).acos();
        t = t.min(1.0 - left / total);
    }
    t.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ctps_c2a_vanishes_smoothly_at_the_support_boundary() {
        assert_eq!(ctps_c2a(0.0), 1.0);
        let h = 1e-4;
        let (f0, f1, f2) = (ctps_c2a(1.0 - 2.0 * h), ctps_c2a(1.0 - h), ctps_c2a(1.0));
        assert!(f2 == 0.0);
        assert!(f1.abs() < 1e-9, "{f1}");
        let d1 = (f2 - f1) / h;
        let d2 = (f2 - 2.0 * f1 + f0) / (h * h);
        assert!(d1.abs() < 1e-6 && d2.abs() < 1e-2, "{d1} {d2}");
    }

    #[test]
    fn rbf_interpolates_the_centres() {
        let c = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-0.6, -0.6, 0.52], [0.3, -0.9, 0.3]];
        let d: Vec<Point3> = (0..5).map(|i| [0.01 * i as f64, -0.02, 0.005 * (i * i) as f64]).collect();
        let w = RbfWarp::fit(&c, &d, 1.2).unwrap();
        for (ci, di) in c.iter().zip(&d) {
            let e = sub(w.displacement(*ci), *di);
            assert!(norm(e) < 1e-7, "{e:?}");
        }
    }
}
