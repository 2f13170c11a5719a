//! Automatic initial alignment when the user gives no correspondence pairs: PCA of the template
//! vertices against the curve points for a start, then similarity ICP (rotation, translation,
//! uniform scale; Horn's quaternion method). PCA axes have sign ambiguities, so the four proper
//! sign choices are each refined by ICP and the best fit wins; the template as placed is a start
//! too when the curves already lie on it. Symmetric templates can still
//! align in more than one way: pairs are the reliable route (the seed always uses them).

use crate::error::Result;
use crate::geometry::{add, dot, norm2, scale, sub, Aabb};
use crate::job::Progress;
use crate::mesh::Point3;

use super::kdtree::KdTree;

mod warp;
pub use warp::{warp_icp, RimEnds, WarpMap, WarpReport};

/// Eigen-decomposition of a small symmetric matrix (row-major `n×n`), as
/// [`crate::register::symmetric_eigen`] computes it, with the eigenvectors laid out as columns
/// (`vecs[i * n + k]` is component `i` of vector `k`), the layout the fit code indexes.
pub fn sym_eigen(a: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let (vals, vecs) = crate::register::symmetric_eigen(a, n);
    let mut cols = vec![0.0; n * n];
    for (k, v) in vecs.iter().enumerate() {
        for (i, &c) in v.iter().enumerate() {
            cols[i * n + k] = c;
        }
    }
    (vals, cols)
}

/// x ↦ s·R·x + t.
#[derive(Debug, Clone, Copy)]
pub struct Similarity {
    pub r: [[f64; 3]; 3],
    pub s: f64,
    pub t: Point3,
}

impl Similarity {
    /// The template where it is: x ↦ x.
    pub const PLACED: Similarity = Similarity { r: IDENTITY, s: 1.0, t: [0.0; 3] };

    pub fn apply(&self, p: Point3) -> Point3 {
        let r = &self.r;
        let q = [dot(r[0], p), dot(r[1], p), dot(r[2], p)];
        add(scale(q, self.s), self.t)
    }

    /// The Jacobian s·R.
    pub fn jacobian(&self) -> [[f64; 3]; 3] {
        self.r.map(|row| row.map(|x| x * self.s))
    }

    pub fn inverse_apply(&self, p: Point3) -> Point3 {
        let d = scale(sub(p, self.t), 1.0 / self.s);
        let r = &self.r;
        [
            r[0][0] * d[0] + r[1][0] * d[1] + r[2][0] * d[2],
            r[0][1] * d[0] + r[1][1] * d[1] + r[2][1] * d[2],
            r[0][2] * d[0] + r[1][2] * d[1] + r[2][2] * d[2],
        ]
    }
}

fn mean(p: &[Point3]) -> Point3 {
    let mut m = [0.0; 3];
    for q in p {
        m = add(m, *q);
    }
    scale(m, 1.0 / p.len().max(1) as f64)
}

/// Principal axes (columns, largest spread first) and the spreads.
fn pca(p: &[Point3]) -> ([[f64; 3]; 3], [f64; 3]) {
    let m = mean(p);
    let mut c = vec![0.0; 9];
    for q in p {
        let d = sub(*q, m);
        for i in 0..3 {
            for j in 0..3 {
                c[i * 3 + j] += d[i] * d[j];
            }
        }
    }
    let (vals, vecs) = sym_eigen(&c, 3);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| vals[b].total_cmp(&vals[a]));
    let mut axes = [[0.0; 3]; 3];
    let mut spread = [0.0; 3];
    for (k, &o) in order.iter().enumerate() {
        for i in 0..3 {
            axes[i][k] = vecs[i * 3 + o];
        }
        spread[k] = vals[o].max(0.0);
    }
    (axes, spread)
}

/// Best similarity taking `from[i]` to `to[i]` (Horn 1987, with scale).
pub fn fit_similarity(from: &[Point3], to: &[Point3]) -> Similarity {
    let (mf, mt) = (mean(from), mean(to));
    let mut s = [[0.0; 3]; 3];
    let mut var = 0.0;
    for (a, b) in from.iter().zip(to) {
        let (a, b) = (sub(*a, mf), sub(*b, mt));
        var += norm2(a);
        for i in 0..3 {
            for j in 0..3 {
                s[i][j] += a[i] * b[j];
            }
        }
    }
    let (sxx, sxy, sxz, syx, syy, syz, szx, szy, szz) =
        (s[0][0], s[0][1], s[0][2], s[1][0], s[1][1], s[1][2], s[2][0], s[2][1], s[2][2]);
    let nmat = [
        sxx + syy + szz,
        syz - szy,
        szx - sxz,
        sxy - syx,
        syz - szy,
        sxx - syy - szz,
        sxy + syx,
        szx + sxz,
        szx - sxz,
        sxy + syx,
        -sxx + syy - szz,
        syz + szy,
        sxy - syx,
        szx + sxz,
        syz + szy,
        -sxx - syy + szz,
    ];
    let (vals, vecs) = sym_eigen(&nmat, 4);
    let k = (0..4).max_by(|&a, &b| vals[a].total_cmp(&vals[b])).unwrap_or(0);
    let (w, x, y, z) = (vecs[k], vecs[4 + k], vecs[8 + k], vecs[12 + k]);
    let r = [
        [w * w + x * x - y * y - z * z, 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), w * w - x * x + y * y - z * z, 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), w * w - x * x - y * y + z * z],
    ];
    let mut num = 0.0;
    for (a, b) in from.iter().zip(to) {
        let a = sub(*a, mf);
        let ra = [dot(r[0], a), dot(r[1], a), dot(r[2], a)];
        num += dot(ra, sub(*b, mt));
    }
    let sc = if var > 0.0 && num > 0.0 { num / var } else { 1.0 };
    let rm = [dot(r[0], mf), dot(r[1], mf), dot(r[2], mf)];
    Similarity { r, s: sc, t: sub(mt, scale(rm, sc)) }
}

const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Similarity ICP from `start`: each curve point is matched to its nearest template vertex (under
/// the current map). Not trimmed: the curves are meant to lie on the template, and trimming let
/// wrong poses of flat or near-symmetric templates score better than the right one (measured on
/// alligator and homer of the fit sweep) by discarding exactly the matches that tell them apart.
/// `anchors` (template point, target) are added to every fit
/// `anchor_copies` times each (user pairs keep their weight against thousands of matches).
/// Returns the map and its score: the RMS distance of the matches.
fn icp(
    template: &[Point3],
    tree: &KdTree,
    curve: &[Point3],
    start: Similarity,
    iterations: u32,
    anchors: &[(Point3, Point3)],
    anchor_copies: usize,
    progress: &Progress,
) -> Result<(Similarity, f64)> {
    let mut m = start;
    let mut score = f64::INFINITY;
    for it in 0..=iterations {
        progress.check()?;
        let last = score;
        let mut matches: Vec<(f64, Point3, Point3)> = Vec::with_capacity(curve.len());
        for &c in curve {
            if let Some((i, _)) = tree.nearest(m.inverse_apply(c)) {
                let p = template[i as usize];
                matches.push((norm2(sub(m.apply(p), c)), p, c));
            }
        }
        if matches.is_empty() {
            break;
        }
        score = (matches.iter().map(|x| x.0).sum::<f64>() / matches.len() as f64).sqrt();
        // Converged (the score never rises: every step minimises the same sum over the matches).
        if it == iterations || score >= last * (1.0 - 1e-7) {
            break;
        }
        let (mut from, mut to): (Vec<Point3>, Vec<Point3>) = matches.iter().map(|&(_, p, c)| (p, c)).unzip();
        for &(p, c) in anchors {
            for _ in 0..anchor_copies {
                from.push(p);
                to.push(c);
            }
        }
        if from.len() < 3 {
            break;
        }
        m = fit_similarity(&from, &to);
    }
    Ok((m, score))
}

/// A spread subset of at most `k` points (every n/k-th).
fn subsample(p: &[Point3], k: usize) -> Vec<Point3> {
    let step = p.len().div_ceil(k.max(1)).max(1);
    p.iter().step_by(step).copied().collect()
}

/// A pose found by the PCA + ICP search: the map template → curve space and its ICP score (RMS
/// distance of the curve points to their nearest template vertices).
#[derive(Debug, Clone, Copy)]
pub struct Candidate {
    pub sim: Similarity,
    pub icp_rms: f64,
    /// Refined on the whole template (`icp_rms` is then against all template vertices; otherwise
    /// against the subset, larger).
    pub contender: bool,
}

/// Poses whose rotations differ by less than this are the same pose (ICP from two nearby starts).
const SAME_POSE_DEG: f64 = 20.0;

/// Template vertices used to score the 24 PCA starts (a spread subset: the starts only need
/// ranking, and a query from a wrong pose, far from the surface, visits much of a large tree).
const SCORING_TEMPLATE_POINTS: usize = 4000;

/// Angle in degrees of the rotation taking `b` to `a` (from the trace of a·bᵀ).
pub fn rotation_angle_deg(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> f64 {
    let tr: f64 = (0..3).map(|i| dot(a[i], b[i])).sum();
    ((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees()
}

/// PCA start + similarity ICP: the best pose (see [`pca_icp_candidates`]).
pub fn pca_icp(
    template: &[Point3],
    curve: &[Point3],
    iterations: u32,
    progress: &Progress,
) -> Result<(Similarity, f64)> {
    let c = pca_icp_candidates(template, curve, iterations, 3, progress)?.candidates;
    Ok(c.first().map_or((Similarity::PLACED, f64::INFINITY), |c| (c.sim, c.icp_rms)))
}

/// What [`pca_icp_candidates`] found.
pub struct Search {
    /// The distinct poses (rotations more than [`SAME_POSE_DEG`] apart), contenders first, best
    /// ICP score first.
    pub candidates: Vec<Candidate>,
    /// RMS distance of the curve points to the template's nearest vertices as placed, over its
    /// bounding-box diagonal (compared with [`PLACED_NEAR`]).
    pub placed_rms_relative: f64,
}

/// PCA starts + similarity ICP. Returns up to three *distinct* poses (rotations more than
/// [`SAME_POSE_DEG`] apart), best ICP score first.
///
/// Candidates: every proper rotation taking the template's principal axes onto the curves'
/// (6 axis orders × 4 sign choices = 24), and the template as placed when the curves already lie
/// on it ([`PLACED_NEAR`]). The axis *order* matters as much as the signs: the
/// curves sample the surface unevenly (sections along one axis only, a partial network), so
/// their spreads need not rank like the template's, and templates with two similar spreads
/// (a flat figure, a round body) swap axes under any small change. Each candidate gets a short
/// ICP on a subset of the curve points against a subset of the template; the best three distinct
/// results are refined on all of them. Several are returned because a nearly symmetric template
/// fits its mirror pose (a flat figure turned over is a proper rotation) almost as well: the
/// caller breaks the tie with the smooth warp's residual and reports a tie it cannot break.
pub fn pca_icp_candidates(
    template: &[Point3],
    curve: &[Point3],
    iterations: u32,
    keep: usize,
    progress: &Progress,
) -> Result<Search> {
    let (at, st) = pca(template);
    let (ac, sc) = pca(curve);
    let (mt, mc) = (mean(template), mean(curve));
    let s0 =
        ((sc[0] + sc[1] + sc[2]) / curve.len() as f64 / ((st[0] + st[1] + st[2]) / template.len() as f64))
            .sqrt();
    let s0 = if s0.is_finite() && s0 > 0.0 { s0 } else { 1.0 };
    let few = subsample(curve, 300);
    let coarse_template = subsample(template, SCORING_TEMPLATE_POINTS);
    let coarse_tree = KdTree::new(&coarse_template);
    let short_icp = |start: Similarity| {
        icp(&coarse_template, &coarse_tree, &few, start, iterations.min(10), &[], 0, progress)
    };
    let mut scored: Vec<(f64, Similarity)> = Vec::new();
    for r in axis_assignments(&ac, &at) {
        let rm = [dot(r[0], mt), dot(r[1], mt), dot(r[2], mt)];
        let (m, score) = short_icp(Similarity { r, s: s0, t: sub(mc, scale(rm, s0)) })?;
        scored.push((score, m));
    }
    // The template as placed, when the curves already lie on it: a user who drew the curves on the
    // template expects that pose, and curves that sample the surface unevenly (feature lines, a
    // partial network) have principal axes unlike the template's, so no PCA start need come near
    // it. A template placed elsewhere is no start: ICP from there ends wherever the nearest
    // vertices pull it (a sphere at the origin against a thin shape at (0.5, 0.5, 0.5) shrank
    // into a pose no PCA start gives, and the fit then cut 10 of 20 regions).
    let diag = Aabb::of(template).map_or(0.0, |b| b.diagonal()).max(f64::MIN_POSITIVE);
    let placed_rms_relative = rms_to_nearest(&coarse_template, &coarse_tree, &few) / diag;
    if placed_rms_relative <= PLACED_NEAR {
        let (m, score) = short_icp(Similarity::PLACED)?;
        scored.push((score, m));
    }
    // The same 24 axis assignments in the world frame, bounding boxes matched (centre and
    // diagonal): curves that sample the surface unevenly (feature lines crowding at rims and
    // bores) have principal axes, centroids and spreads unlike the template's, so no PCA start
    // need come near the pose, while their bounding box is nearly the part's; CAD parts are drawn
    // along the world axes. Kept only where they beat every PCA start (and the placed one) clearly
    // ([`WORLD_START_GAIN`]): where the PCA starts work, their poses are the candidates, as before
    // (kept whenever they were new, a flat figure's turned-over pose entered and won: alligator
    // twisted, 6,628 faces against the truth).
    let boxes = Aabb::of(template).zip(Aabb::of(curve));
    let box_scale = boxes.map_or(0.0, |(bt, bc)| bc.diagonal() / bt.diagonal().max(f64::MIN_POSITIVE));
    if let Some((bt, bc)) = boxes.filter(|_| box_scale.is_finite() && box_scale > 0.0) {
        let (s, ct, cc) = (box_scale, bt.center(), bc.center());
        let mut world: Vec<(f64, Similarity)> = Vec::new();
        for r in axis_assignments(&IDENTITY, &IDENTITY) {
            let rc = [dot(r[0], ct), dot(r[1], ct), dot(r[2], ct)];
            let (m, score) = short_icp(Similarity { r, s, t: sub(cc, scale(rc, s)) })?;
            world.push((score, m));
        }
        let best_so_far = scored.iter().map(|x| x.0).fold(f64::INFINITY, f64::min);
        let new_poses: Vec<(f64, Similarity)> =
            world.into_iter().filter(|(ws, _)| *ws < WORLD_START_GAIN * best_so_far).collect();
        scored.extend(new_poses);
    }
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    let starts =
        distinct(scored.into_iter().map(|(s, m)| Candidate { sim: m, icp_rms: s, contender: false }), keep);
    // Every start on all curve points against the subset, then the contenders on the whole
    // template (a wrong pose, far from the surface, is slow to query in a large tree).
    let mut refined = Vec::with_capacity(starts.len());
    for c in starts {
        let (m, score) = icp(&coarse_template, &coarse_tree, curve, c.sim, iterations, &[], 0, progress)?;
        refined.push(Candidate { sim: m, icp_rms: score, contender: false });
    }
    refined.sort_by(|a, b| a.icp_rms.total_cmp(&b.icp_rms));
    let best = refined.first().map_or(f64::INFINITY, |c| c.icp_rms);
    let tree = KdTree::new(template);
    for c in refined.iter_mut() {
        if c.icp_rms <= CONTENDER_RATIO * best {
            let (m, score) = icp(template, &tree, curve, c.sim, iterations, &[], 0, progress)?;
            *c = Candidate { sim: m, icp_rms: score, contender: true };
        }
    }
    refined.sort_by(|a, b| b.contender.cmp(&a.contender).then(a.icp_rms.total_cmp(&b.icp_rms)));
    Ok(Search { candidates: distinct(refined.into_iter(), usize::MAX), placed_rms_relative })
}

/// A world-frame start's pose enters the search only when its short-ICP score is below this
/// fraction of the best of the PCA starts' and the placed start's. Rocker-arm moved off its own
/// feature lines: 0.0065 against 0.020. The placed start is in the comparison because, without
/// it, woody on its curves got the world frame's turned-over pose 2 % behind the placed one, and
/// the choice became ambiguous.
const WORLD_START_GAIN: f64 = 0.8;

/// The 24 proper rotations taking the columns of `from` (an orthonormal frame, e.g. the template's
/// principal axes) onto those of `to`, each axis to an axis with a sign: R = To · P · Fromᵀ (6 axis
/// orders × 4 sign choices; a choice giving a reflection is negated, so the 24 are distinct).
fn axis_assignments(to: &[[f64; 3]; 3], from: &[[f64; 3]; 3]) -> Vec<[[f64; 3]; 3]> {
    let mut out = Vec::with_capacity(24);
    for perm in [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]] {
        for signs in [[1.0, 1.0, 1.0], [-1.0, -1.0, 1.0], [-1.0, 1.0, -1.0], [1.0, -1.0, -1.0]] {
            let mut r = [[0.0; 3]; 3];
            for (i, row) in r.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = (0..3).map(|k| to[i][perm[k]] * signs[k] * from[j][k]).sum();
                }
            }
            if dot(r[0], crate::geometry::cross(r[1], r[2])) < 0.0 {
                for row in r.iter_mut() {
                    for v in row.iter_mut() {
                        *v = -*v;
                    }
                }
            }
            out.push(r);
        }
    }
    out
}

/// The template as placed is an ICP start when the curve points' RMS distance to its nearest
/// vertices is at most this fraction of its bounding-box diagonal.
pub const PLACED_NEAR: f64 = 0.1;

/// RMS distance of `curve` to the nearest of `template`'s points (`tree` over them).
fn rms_to_nearest(template: &[Point3], tree: &KdTree, curve: &[Point3]) -> f64 {
    let d2: Vec<f64> = curve
        .iter()
        .filter_map(|&c| tree.nearest(c).map(|(i, _)| norm2(sub(template[i as usize], c))))
        .collect();
    if d2.is_empty() {
        return f64::INFINITY;
    }
    (d2.iter().sum::<f64>() / d2.len() as f64).sqrt()
}

/// Poses whose ICP score (against the template subset) is within this factor of the best are
/// contenders: refined on the whole template and, in the fit, warped (the warp's residual
/// chooses among them).
pub const CONTENDER_RATIO: f64 = 1.5;

/// The first `k` of `sorted` whose rotations are more than [`SAME_POSE_DEG`] from every one kept.
fn distinct(sorted: impl Iterator<Item = Candidate>, k: usize) -> Vec<Candidate> {
    let mut kept: Vec<Candidate> = Vec::new();
    for c in sorted {
        if kept.len() < k && kept.iter().all(|q| rotation_angle_deg(&q.sim.r, &c.sim.r) > SAME_POSE_DEG) {
            kept.push(c);
        }
    }
    kept
}

/// Similarity ICP started from the user's pairs, for pairs too degenerate for the coarse RBF
/// (all on one line, or on one plane of a flat template). The pairs' similarity (Horn) is the
/// start; when the pairs are (nearly) on one line, the rotation about that line is free, so 8
/// starts turned about it are tried. The pairs stay in every ICP fit with a weight of a quarter
/// of the curve points, so the curves decide only what the pairs leave open.
pub fn pairs_icp(
    template: &[Point3],
    curve: &[Point3],
    pairs: &[(Point3, Point3)],
    iterations: u32,
    progress: &Progress,
) -> Result<(Similarity, f64)> {
    let tree = KdTree::new(template);
    let (from, to): (Vec<Point3>, Vec<Point3>) = pairs.iter().copied().unzip();
    let horn = fit_similarity(&from, &to);
    let mut starts = vec![horn];
    let [_, thin] = super::rbf::spread_ratios(&to);
    if pairs.len() < 3 || thin < 0.05 {
        let (axes, _) = pca(&to);
        let axis = [axes[0][0], axes[1][0], axes[2][0]];
        let centre = mean(&to);
        for k in 1..8 {
            let rot = axis_rotation(axis, k as f64 * std::f64::consts::FRAC_PI_4);
            // x ↦ centre + rot·(horn(x) − centre)
            let mut r = [[0.0; 3]; 3];
            for (i, row) in r.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = (0..3).map(|l| rot[i][l] * horn.r[l][j]).sum();
                }
            }
            let rt = [
                dot(rot[0], sub(horn.t, centre)),
                dot(rot[1], sub(horn.t, centre)),
                dot(rot[2], sub(horn.t, centre)),
            ];
            starts.push(Similarity { r, s: horn.s, t: add(centre, rt) });
        }
    }
    let copies = (curve.len() / 4 / pairs.len().max(1)).max(1);
    let mut best: Option<(Similarity, f64)> = None;
    for start in starts {
        let (m, score) = icp(template, &tree, curve, start, iterations, pairs, copies, progress)?;
        if best.as_ref().is_none_or(|b| score < b.1) {
            best = Some((m, score));
        }
    }
    Ok(best.unwrap_or((horn, f64::INFINITY)))
}

/// Rotation by `angle` about the unit `axis` (Rodrigues).
fn axis_rotation(axis: Point3, angle: f64) -> [[f64; 3]; 3] {
    let (s, c) = angle.sin_cos();
    let [x, y, z] = axis;
    let t = 1.0 - c;
    [
        [c + x * x * t, x * y * t - z * s, x * z * t + y * s],
        [y * x * t + z * s, c + y * y * t, y * z * t - x * s],
        [z * x * t - y * s, z * y * t + x * s, c + z * z * t],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_finds_known_eigenvalues() {
        // [[2,1],[1,2]] has eigenvalues 1 and 3.
        let (mut v, _) = sym_eigen(&[2.0, 1.0, 1.0, 2.0], 2);
        v.sort_by(f64::total_cmp);
        assert!((v[0] - 1.0).abs() < 1e-12 && (v[1] - 3.0).abs() < 1e-12);
    }

    #[test]
    fn horn_recovers_a_similarity() {
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let truth =
            Similarity { r: [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], s: 1.7, t: [1.0, -2.0, 3.0] };
        let from: Vec<Point3> =
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0], [1.0, 1.0, 1.0]];
        let to: Vec<Point3> = from.iter().map(|&p| truth.apply(p)).collect();
        let m = fit_similarity(&from, &to);
        for p in [[5.0, 1.0, -2.0], [0.1, 0.2, 0.3]] {
            let (a, b) = (m.apply(p), truth.apply(p));
            assert!(crate::geometry::dist(a, b) < 1e-9, "{a:?} {b:?}");
            assert!(crate::geometry::dist(m.inverse_apply(b), p) < 1e-9);
        }
    }
}
