//! The non-rigid part of the automatic alignment: after the similarity ICP, an affine then a
//! quadratic warp of the template fitted by trimmed ICP to the curve points, each stage cut back
//! to its last step that folds no face.

use crate::error::{Error, Result};
use crate::geometry::{add, closest_on_segment, dist, dot, norm2, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;

use super::super::kdtree::KdTree;
use super::mean;

/// What the smooth warp of [`warp_icp`] did (serialised into the report).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct WarpReport {
    /// Iterations run per degree (affine, then quadratic).
    pub iterations: [u32; 2],
    /// Trimmed RMS distance of the curve points to the surface before and after the warp.
    pub rms_before: f64,
    pub rms_after: f64,
    /// RMS distance of all those curve points to the surface after the warp, none trimmed: the
    /// points the trimming leaves out (curves running off the template) are what tells two poses apart.
    pub rms_all_after: f64,
    /// Iterations whose step was halved because the full step folded faces.
    pub damped: u32,
    /// The warp itself, for its Jacobian (not serialised).
    #[serde(skip)]
    pub map: WarpMap,
}

/// The kept steps of a warp: per degree stage, each step x ↦ x + Σ cₖ mₖ((x − centre)/radius)
/// applied to the result of the ones before ([`LazyWarp`]).
#[derive(Debug, Clone, Default)]
pub struct WarpMap {
    centre: Point3,
    radius: f64,
    steps: Vec<Vec<[f64; 3]>>,
}

impl WarpMap {
    /// The Jacobian of the whole warp at `p` (the steps' Jacobians multiplied along the way).
    pub fn jacobian(&self, p: Point3) -> [[f64; 3]; 3] {
        let mut j = super::super::orientation::IDENTITY;
        let mut x = p;
        for coef in &self.steps {
            let u = scale(sub(x, self.centre), 1.0 / self.radius);
            let degree = if coef.len() > 4 { 2 } else { 1 };
            let grads = monomial_gradients(u);
            let mut step = super::super::orientation::IDENTITY;
            for (c, g) in coef.iter().zip(grads) {
                for r in 0..3 {
                    for k in 0..3 {
                        step[r][k] += c[r] * g[k] / self.radius;
                    }
                }
            }
            j = super::super::orientation::mat_mul(&step, &j);
            let (m, _) = monomials(u, degree);
            for (c, mj) in coef.iter().zip(m) {
                x = add(x, scale(*c, mj));
            }
        }
        j
    }
}

/// Gradients (in u) of the monomials of [`monomials`], in the same order.
fn monomial_gradients(u: Point3) -> [Point3; 10] {
    [
        [0.0; 3],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [2.0 * u[0], 0.0, 0.0],
        [0.0, 2.0 * u[1], 0.0],
        [0.0, 0.0, 2.0 * u[2]],
        [u[1], u[0], 0.0],
        [0.0, u[2], u[1]],
        [u[2], 0.0, u[0]],
    ]
}

/// The template's rim (its boundary edges) and the curve ends (network degree 1) within `cap` of
/// it, for the warp: sections of an open surface end on its boundary, and on a flat template
/// those ends are all that fixes the template's place *in* its plane. Every curve point inside the
/// outline lies on the surface wherever the template sits, so its trimmed match (distance ~0)
/// only holds the warp still; measured on woody and alligator as read (raw, flat) under their
/// own sections: the right pose's warp kept the similarity's wrong scale (0.90 and 1.23), its
/// ends stayed 0.018–0.024 off the rim, and the mirror pose won (session 12, fit-raw).
pub struct RimEnds<'a> {
    pub edges: &'a [(u32, u32)],
    pub ends: &'a [Point3],
    pub cap: f64,
}

impl RimEnds<'_> {
    /// (closest rim point, end) for every end within `cap` of the rim, the template's vertices
    /// placed by `at`.
    fn matches(&self, mut at: impl FnMut(u32) -> Point3) -> Vec<(Point3, Point3)> {
        if self.edges.is_empty() {
            return Vec::new();
        }
        let segs: Vec<(Point3, Point3)> = self.edges.iter().map(|&(a, b)| (at(a), at(b))).collect();
        self.ends
            .iter()
            .filter_map(|&e| {
                let best = segs
                    .iter()
                    .map(|&(a, b)| closest_on_segment(e, a, b))
                    .min_by(|x, y| norm2(sub(*x, e)).total_cmp(&norm2(sub(*y, e))))?;
                (norm2(sub(best, e)) <= self.cap * self.cap).then_some((best, e))
            })
            .collect()
    }
}

/// The curve ends' matches to the rim weigh this share of the kept curve points' in all. Measured
/// (session 12, fit-raw; the woody and alligator raw rows of `sweep_unseen`, the flat rows of
/// `sweep_fit`): 1/8 to 1/3 fit both raw meshes without flips; at 1/12 or 1 the alligator keeps
/// flips; sweep_fit's woody row, which no weight brings out of its mirror pose, moves by a region,
/// a flip or a segment either way across the whole range (1/8 leaves it as it was).
const END_WEIGHT: f64 = 0.125;

/// Matches within this many curve segments (the median) of the surface are never trimmed.
///
/// Why: the trim is for curves running off the template, and its cut (2.5 × the median distance)
/// shrinks with the fit. Where the template fits most curves closely, the cut fell below the
/// distances that still carry the pose: on a flattened ellipsoid 1 × 0.6 × 0.04 (sweep_unseen) the
/// sheets fit to ~3e-5, the cut was ~7.5e-5, and the curve points at the tips, 0.0025–0.003 off,
/// were dropped; the template stayed 0.0037 too far along its long axis, its rim beyond the curves'
/// rim by 5 × the rim's radius of curvature, and the fit folded the rim (14 flipped faces in the
/// report, 100 against the analytic normal; with this floor 0 and 0). Measured there, floors of
/// 1 / 1.25 / 1.5 / 2 / 3 segments: 5 / 0 / 0 / 3 / 3 flipped faces. Feet on faces touching an
/// open boundary keep the plain cut: with the floor there, "curves past an open template's rim"
/// (sweep_unseen) stretched the template over the curves instead of reporting them
/// (docs/benchmarks.md, fit-thin, session 11).
const TRIM_FLOOR_SEGMENTS: f64 = 1.25;

/// The floor keeps a match only when it is farther than this many times the sag of its foot's
/// face ([`face_sags`]): a distance the template's faceting explains says nothing about the pose.
///
/// Why: on a faceted template whose faces are long against the curves' curvature, the curve points
/// between two rings of vertices lie up to a sag off the faces, and the floor (1.25 median
/// segments: 0.38 on a sparse network) kept all of them. The warp then chased the faceting: the
/// needle UV sphere (512 × 6, sag 0.034–0.048) affinely placed exactly on the ellipsoid of its
/// curves (every vertex on it) was moved by up to 0.070 and its poles by 0.030–0.042 off the
/// curves' crossings; in the fit (fit_unseen9, `a_template_of_needles_is_not_decimated`) the
/// crossings were then inserted next to the poles, their segments crossed tens of the pole fans'
/// spokes, the re-triangulation's flips left fans of slivers along the first rings and the
/// clean-up removed 80 vertices (5,076 faces out of 5,120). With this factor the rescued matches
/// of the thin ellipsoid, 3–20 sags off at first, are kept, and the needle sphere's are not
/// (0.5–1.9 sags). Measured on those two, factors 1 / 1.25 / 1.5 / 3 / 4: thin 1 / 0 / 0 / 1 / 24
/// flipped faces (report), needles 5,194 / 5,194 / 5,194 / 5,196 / 5,196 faces
/// (docs/benchmarks.md, fit-thin, session 12).
const TRIM_FLOOR_SAGS: f64 = 1.5;

/// Monomials of degree ≤ 2 of `u` (1, u, v, w, u², v², w², uv, vw, wu); `degree` 1 keeps 4.
fn monomials(u: Point3, degree: usize) -> ([f64; 10], usize) {
    let m =
        [1.0, u[0], u[1], u[2], u[0] * u[0], u[1] * u[1], u[2] * u[2], u[0] * u[1], u[1] * u[2], u[2] * u[0]];
    (m, if degree >= 2 { 10 } else { 4 })
}

/// Solves the symmetric positive definite `n×n` system `a x = b` (3 right-hand sides) by
/// Cholesky; `None` when it is not positive definite.
fn solve_spd(a: &[f64], b: &[[f64; 3]], n: usize) -> Option<Vec<[f64; 3]>> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = a[i * n + j] - (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
            if i == j {
                if s <= 0.0 || !s.is_finite() {
                    return None;
                }
                l[i * n + i] = s.sqrt();
            } else {
                l[i * n + j] = s / l[j * n + j];
            }
        }
    }
    let mut y = vec![[0.0; 3]; n];
    for i in 0..n {
        for c in 0..3 {
            y[i][c] = (b[i][c] - (0..i).map(|k| l[i * n + k] * y[k][c]).sum::<f64>()) / l[i * n + i];
        }
    }
    let mut x = vec![[0.0; 3]; n];
    for i in (0..n).rev() {
        for c in 0..3 {
            x[i][c] = (y[i][c] - (i + 1..n).map(|k| l[k * n + i] * x[k][c]).sum::<f64>()) / l[i * n + i];
        }
    }
    Some(x)
}

/// Smooth non-rigid alignment after the similarity ICP: ICP with an affine, then a quadratic
/// polynomial warp of the whole template (x ↦ x + Σ cₖ mₖ((x − centre)/radius)).
///
/// Why: a similarity cannot follow a target that is a stretched or bent copy of the template, and
/// the closest-point steps after it (approach levels, fine fit) only correct the *normal* distance
/// of each curve point to the surface: the tangential error a similarity leaves (measured on the
/// bent sweep meshes: 3–4× the error left by a coarse RBF through 12 user pairs) stays, and the
/// fine displacements are then large compared with the edges, which folds faces. A global warp
/// with few parameters is stiff, so iterating closest points moves it tangentially too (the shape
/// of the curve network pins it), which a sparse interpolating RBF cannot do.
///
/// Guards: matches farther than 2.5× the median distance are trimmed, unless within
/// [`TRIM_FLOOR_SEGMENTS`] × `spacing` (the curves' median segment; 0 for no floor) on a face away
/// from the template's open boundary and farther than [`TRIM_FLOOR_SAGS`] × that face's sag (its
/// faceting, measured once on the template as given to the warp); every coefficient is pulled towards
/// zero by a ridge term, the quadratic ones harder, so directions the curves do not determine
/// (all curves on one plane) stay put; a step that would fold faces is halved (then stops).
/// `rim`: the template's rim and the curve ends near it, matched to it in every iteration
/// ([`RimEnds`]; `None` leaves them out).
pub fn warp_icp(
    pos: &mut [Point3],
    tris: &[[u32; 3]],
    points: &[Point3],
    spacing: f64,
    rim: Option<&RimEnds>,
    iterations: u32,
    progress: &Progress,
) -> Result<WarpReport> {
    let mut report = WarpReport::default();
    if points.len() < 10 || tris.is_empty() {
        return Ok(report);
    }
    // A spread subset keeps each iteration cheap on dense networks.
    let stride = (points.len() / 1500).max(1);
    let which: Vec<u32> = (0..points.len() as u32).step_by(stride).collect();
    let centre = mean(points);
    let radius = (points.iter().map(|p| norm2(sub(*p, centre))).sum::<f64>() / points.len() as f64).sqrt();
    if !(radius > 0.0) {
        return Ok(report);
    }
    report.map = WarpMap { centre, radius, steps: Vec::new() };
    let mut tracked = TrackedFeet::new(pos, tris, points, &which, progress)?;
    // Faces touching the template's open boundary: a foot there may be a curve running off the
    // template, which the trim is for, so the floor does not keep it.
    let on_rim: Vec<bool> = {
        let rim = super::super::trimesh::boundary_vertices(pos.len(), tris);
        tris.iter().map(|t| t.iter().any(|&v| rim[v as usize])).collect()
    };
    let sag = face_sags(pos, tris);
    let trimmed = |feet: &[(u32, Point3, f64)]| -> (Vec<usize>, f64) {
        let mut d: Vec<f64> = feet.iter().map(|f| f.2).collect();
        d.sort_by(f64::total_cmp);
        let cut = 2.5 * d[d.len() / 2];
        let floor = TRIM_FLOOR_SEGMENTS * spacing;
        let keep: Vec<usize> = (0..feet.len())
            .filter(|&i| {
                let f = feet[i];
                let face = f.0 as usize;
                f.2 <= cut.max(1e-300) || (f.2 <= floor && !on_rim[face] && f.2 > TRIM_FLOOR_SAGS * sag[face])
            })
            .collect();
        let rms =
            (keep.iter().map(|&i| feet[i].2 * feet[i].2).sum::<f64>() / keep.len().max(1) as f64).sqrt();
        (keep, rms)
    };
    let mut first = true;
    for (stage, degree) in [1usize, 2].into_iter().enumerate() {
        let mut warp = LazyWarp::new(pos, centre, radius);
        let mut last_rms = f64::INFINITY;
        for _ in 0..iterations {
            progress.check()?;
            let feet = tracked.feet(&mut warp, tris, points, &which)?;
            let (keep, rms) = trimmed(&feet);
            if first {
                report.rms_before = rms;
                first = false;
            }
            // Curve ends near the rim, matched to it, weighing [`END_WEIGHT`] of the kept curve
            // points in all ([`RimEnds`]); none on a closed template or a network without ends.
            let ends = rim.map_or_else(Vec::new, |r| r.matches(|v| warp.at(v)));
            let end_weight =
                if ends.is_empty() { 0.0 } else { END_WEIGHT * keep.len() as f64 / ends.len() as f64 };
            let objective = if ends.is_empty() {
                rms
            } else {
                let e2: f64 = ends.iter().map(|(f, e)| norm2(sub(*e, *f))).sum();
                // The weighted RMS of both kinds of matches.
                let n = keep.len() as f64 + end_weight * ends.len() as f64;
                ((rms * rms * keep.len() as f64 + end_weight * e2) / n).sqrt()
            };
            if objective > 0.999 * last_rms || keep.len() < 10 {
                break;
            }
            last_rms = objective;
            let n = monomials([0.0; 3], degree).1;
            let mut a = vec![0.0; n * n];
            let mut b = vec![[0.0; 3]; n];
            let rows = keep
                .iter()
                .map(|&i| (feet[i].1, points[which[i] as usize], 1.0))
                .chain(ends.iter().map(|&(f, e)| (f, e, end_weight)));
            for (foot, target, weight) in rows {
                let (m, _) = monomials(warp.u(foot), degree);
                let r = sub(target, foot);
                for j in 0..n {
                    for k in 0..n {
                        a[j * n + k] += weight * m[j] * m[k];
                    }
                    for c in 0..3 {
                        b[j][c] += weight * m[j] * r[c];
                    }
                }
            }
            // Ridge: light on the affine part, 10× on the quadratic part (relative to the count).
            let w = keep.len() as f64;
            for j in 0..n {
                a[j * n + j] += if j < 4 { 1e-3 * w } else { 1e-2 * w };
            }
            let Some(coef) = solve_spd(&a, &b, n) else { break };
            warp.steps.push(coef);
        }
        // The steps are applied to the whole template once per stage, and checked for folds
        // against the stage's start: when the composed warp folds a face, the longest run of
        // first steps that does not is kept (found by bisection; folds are rare).
        let mut moved = warp.apply_first(warp.steps.len(), progress)?;
        progress.check()?;
        if super::super::approach::folds(pos, &moved, tris) > 0 {
            report.damped += 1;
            let (mut ok, mut bad) = (0, warp.steps.len());
            while bad - ok > 1 {
                let mid = (ok + bad) / 2;
                if super::super::approach::folds(pos, &warp.apply_first(mid, progress)?, tris) > 0 {
                    bad = mid;
                } else {
                    ok = mid;
                }
            }
            moved = warp.apply_first(ok, progress)?;
            warp.steps.truncate(ok);
        }
        report.iterations[stage] = warp.steps.len() as u32;
        report.map.steps.extend(warp.steps.iter().cloned());
        pos.copy_from_slice(&moved);
        tracked.rebase(pos);
    }
    let mut warp = LazyWarp::new(pos, centre, radius);
    let feet = tracked.feet(&mut warp, tris, points, &which)?;
    report.rms_after = trimmed(&feet).1;
    report.rms_all_after = (feet.iter().map(|f| f.2 * f.2).sum::<f64>() / feet.len().max(1) as f64).sqrt();
    Ok(report)
}

/// Per face, how far its flat triangle may lie from the smooth surface it stands for: the largest,
/// over its edges, of the sag of the circular arc through the edge's ends with the ends' vertex
/// normals, (length / 2) · tan(θ / 4) for normals θ apart (0 on a flat part, ~0.034 on a unit
/// sphere's faces spanning 30° of latitude).
fn face_sags(pos: &[Point3], tris: &[[u32; 3]]) -> Vec<f64> {
    let normals = super::super::report::vertex_normals(pos, tris);
    tris.iter()
        .map(|t| {
            (0..3)
                .map(|k| {
                    let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                    let theta = dot(normals[a], normals[b]).clamp(-1.0, 1.0).acos();
                    0.5 * dist(pos[a], pos[b]) * (theta / 4.0).tan()
                })
                .fold(0.0, f64::max)
        })
        .collect()
}

/// Faces or vertices handled between two polls while [`TrackedFeet`] builds its adjacency.
const POLL_ITEMS: usize = 16_384;

/// The warp of one stage as a list of polynomial steps (x ↦ x + Σ cₖ mₖ((x − centre)/radius),
/// each applied to the result of the ones before), evaluated only at the vertices asked for:
/// the closest-point search touches a few hundred vertices per curve point, so moving the whole
/// template every iteration (and rebuilding its search structure) was almost all of the warp's
/// time on large templates. `cur[v]` is `base[v]` moved by the first `done[v]` steps.
struct LazyWarp<'a> {
    base: &'a [Point3],
    cur: Vec<Point3>,
    done: Vec<u32>,
    steps: Vec<Vec<[f64; 3]>>,
    centre: Point3,
    radius: f64,
}

impl<'a> LazyWarp<'a> {
    fn new(base: &'a [Point3], centre: Point3, radius: f64) -> Self {
        LazyWarp { base, cur: base.to_vec(), done: vec![0; base.len()], steps: Vec::new(), centre, radius }
    }

    fn u(&self, p: Point3) -> Point3 {
        scale(sub(p, self.centre), 1.0 / self.radius)
    }

    fn step(&self, k: usize, p: Point3) -> Point3 {
        let coef = &self.steps[k];
        let (m, _) = monomials(self.u(p), if coef.len() > 4 { 2 } else { 1 });
        let mut d = p;
        for (c, mj) in coef.iter().zip(m) {
            d = add(d, scale(*c, mj));
        }
        d
    }

    /// Current position of vertex `v`.
    fn at(&mut self, v: u32) -> Point3 {
        let v = v as usize;
        while (self.done[v] as usize) < self.steps.len() {
            self.cur[v] = self.step(self.done[v] as usize, self.cur[v]);
            self.done[v] += 1;
        }
        self.cur[v]
    }

    /// Every vertex moved by the first `k` steps.
    fn apply_first(&self, k: usize, progress: &Progress) -> Result<Vec<Point3>> {
        use rayon::prelude::*;
        progress.check()?;
        Ok(self
            .base
            .par_iter()
            .map(|&p| {
                let mut q = p;
                for s in 0..k {
                    q = self.step(s, q);
                }
                q
            })
            .collect())
    }
}

/// Closest surface points of the curve points on a template that the warp moves by small smooth
/// steps. The nearest vertex of each point is found once with a k-d tree, then followed from one
/// iteration to the next by a greedy walk over the vertex graph (a step moves it by a few edges
/// at most), so no search structure is rebuilt per iteration. The foot is the closest point of
/// the faces around that vertex and its neighbours.
struct TrackedFeet {
    vf: Vec<Vec<u32>>,
    vv: Vec<Vec<u32>>,
    near: Vec<u32>,
    /// Faces around `near[k]` and its neighbours, kept while `near[k]` stays.
    faces: Vec<(u32, Vec<u32>)>,
}

impl TrackedFeet {
    /// Polls every [`POLL_ITEMS`] faces and vertices (on the 96k-vertex template of
    /// `cancel_latency`, the adjacency and the k-d tree were ~100 ms of CPU without a poll).
    fn new(
        pos: &[Point3],
        tris: &[[u32; 3]],
        points: &[Point3],
        which: &[u32],
        progress: &Progress,
    ) -> Result<Self> {
        let mut vf: Vec<Vec<u32>> = vec![Vec::new(); pos.len()];
        let mut vv: Vec<Vec<u32>> = vec![Vec::new(); pos.len()];
        for (f, t) in tris.iter().enumerate() {
            progress.check_every(f, POLL_ITEMS)?;
            for k in 0..3 {
                vf[t[k] as usize].push(f as u32);
                vv[t[k] as usize].push(t[(k + 1) % 3]);
                vv[t[(k + 1) % 3] as usize].push(t[k]);
            }
        }
        for (v, n) in vv.iter_mut().enumerate() {
            progress.check_every(v, POLL_ITEMS)?;
            n.sort_unstable();
            n.dedup();
        }
        progress.check()?;
        let mut t =
            TrackedFeet { vf, vv, near: Vec::new(), faces: vec![(u32::MAX, Vec::new()); which.len()] };
        t.near = which.iter().map(|_| u32::MAX).collect();
        t.rebase_with(pos, points, which);
        Ok(t)
    }

    fn rebase_with(&mut self, pos: &[Point3], points: &[Point3], which: &[u32]) {
        let tree = KdTree::new(pos);
        self.near =
            which.iter().map(|&i| tree.nearest(points[i as usize]).map_or(u32::MAX, |(v, _)| v)).collect();
    }

    /// The template was moved as a whole: the walks go on from the same vertices.
    fn rebase(&mut self, _pos: &[Point3]) {}

    /// (face, foot, distance) per point of `which`.
    fn feet(
        &mut self,
        warp: &mut LazyWarp,
        tris: &[[u32; 3]],
        points: &[Point3],
        which: &[u32],
    ) -> Result<Vec<(u32, Point3, f64)>> {
        let mut out = Vec::with_capacity(which.len());
        for (k, &i) in which.iter().enumerate() {
            let p = points[i as usize];
            let mut v = self.near[k];
            if v == u32::MAX {
                return Err(Error::Internal("empty template".into()));
            }
            let mut d = norm2(sub(warp.at(v), p));
            loop {
                let mut next = v;
                for &w in &self.vv[v as usize] {
                    let dw = norm2(sub(warp.at(w), p));
                    if dw < d {
                        (next, d) = (w, dw);
                    }
                }
                if next == v {
                    break;
                }
                v = next;
            }
            self.near[k] = v;
            if self.faces[k].0 != v {
                let cand = &mut self.faces[k].1;
                cand.clear();
                for &f in &self.vf[v as usize] {
                    for &w in &tris[f as usize] {
                        cand.extend_from_slice(&self.vf[w as usize]);
                    }
                }
                cand.sort_unstable();
                cand.dedup();
                self.faces[k].0 = v;
            }
            let mut best: Option<(u32, Point3, f64)> = None;
            for &f in &self.faces[k].1 {
                let t = tris[f as usize];
                let q =
                    crate::spatial::closest_on_triangle(p, &[warp.at(t[0]), warp.at(t[1]), warp.at(t[2])]);
                let d = crate::geometry::dist(p, q);
                if best.is_none_or(|b| d < b.2) {
                    best = Some((f, q, d));
                }
            }
            out.push(best.ok_or_else(|| {
                Error::params(
                    "template",
                    format!("template vertex {v} (nearest to curve point {i}) has no face"),
                )
            })?);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The warp's Jacobian (its steps' Jacobians multiplied) against central differences of the
    /// warp applied step by step, for an affine step followed by a quadratic one.
    #[test]
    fn the_warp_jacobian_matches_finite_differences() {
        let affine = vec![[0.1, -0.2, 0.05], [0.3, 0.1, 0.0], [-0.1, 0.2, 0.1], [0.0, 0.05, -0.3]];
        let quadratic: Vec<[f64; 3]> = (0..10)
            .map(|i| [0.05 * (i as f64).sin(), 0.04 * (i as f64 * 0.7).cos(), -0.03 * i as f64 * 0.1])
            .collect();
        let map = WarpMap { centre: [0.2, -0.1, 0.3], radius: 1.7, steps: vec![affine, quadratic] };
        let apply = |p: Point3| {
            let mut x = p;
            for coef in &map.steps {
                let u = scale(sub(x, map.centre), 1.0 / map.radius);
                let (m, _) = monomials(u, if coef.len() > 4 { 2 } else { 1 });
                for (c, mj) in coef.iter().zip(m) {
                    x = add(x, scale(*c, mj));
                }
            }
            x
        };
        for p in [[0.0, 0.0, 0.0], [1.0, -0.5, 0.25], [-2.0, 1.5, 0.7]] {
            let j = map.jacobian(p);
            let h = 1e-6;
            for col in 0..3 {
                let (mut a, mut b) = (p, p);
                a[col] += h;
                b[col] -= h;
                let (ea, eb) = (apply(a), apply(b));
                for row in 0..3 {
                    let fd = (ea[row] - eb[row]) / (2.0 * h);
                    assert!((j[row][col] - fd).abs() < 1e-7 * (1.0 + fd.abs()), "{j:?} at {p:?}");
                }
            }
        }
    }
}
