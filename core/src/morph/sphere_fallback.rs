//! The guaranteed spherical parameterisation: used when the progressive one (flattening + vertex
//! splits, [`super::param`]) fails or leaves a flipped triangle, or when asked for directly
//! (`sphere_method: tutte`).
//!
//! 1. Remove one vertex `v0` (near the graph centre, so no part of the mesh lies "deep" inside the
//!    disk: Tutte maps shrink exponentially with depth). What remains is a disk whose boundary is
//!    the link of `v0`.
//! 2. Tutte/Floater embedding of that disk: the link on a circle (angles by 3D edge length,
//!    a strictly convex polygon), every interior vertex the weighted average of its neighbours
//!    with positive symmetrised mean-value weights. Tutte's theorem (Floater 2003 for any positive
//!    weights) makes this an embedding of the disk into the convex polygon.
//! 3. Inverse stereographic projection from the north pole N; `v0` goes to N. A planar triangle
//!    lifts to a positively oriented chord triangle iff its circumdisk lifts to a cap smaller than
//!    a hemisphere (r² < 1 + |c|² for circumradius r and centre c); the fan of `v0` is positive iff
//!    the origin lies inside the boundary polygon. Shrinking the layout (s → 0) satisfies the
//!    first for every non-degenerate triangle, so a valid lift always exists.
//! 4. Möbius normalisation. Every Möbius map of the sphere is a rotation after a similarity of the
//!    stereographic plane (Iwasawa: K·A·N), and a plane similarity keeps the planar embedding, so
//!    normalising over (scale s, translation t) of the layout explores all of them while only the
//!    lift conditions of step 3 can fail. Nelder–Mead over (ln s, tₓ, t_y) minimises the area
//!    distortion SD; a candidate with any non-positive chord triangle is rejected.
//! 5. Optional relaxation (the progressive path's fold-free mean-value relaxation), in batches;
//!    a batch after which the exact test finds a flipped triangle is undone and relaxation stops.
//!
//! Every face is then checked with an exact orientation test ([`orient_sign`]). In exact
//! arithmetic steps 2–4 cannot produce a foldover; in floating point a Tutte layout of a very
//! elongated shape can squeeze triangles below the resolution of f64, which the check reports
//! (with uniform weights tried as a second chance).

use crate::error::{Error, Result};
use crate::geometry::{corner_angle, dist, triangle_area};
use crate::job::Progress;
use crate::mesh::Point3;

use super::param::{self, distortion};
use super::simplify::Hierarchy;
use super::trimesh::TriMesh;

// ---------------------------------------------------------------------------------------------
// Exact orientation on the sphere: sign of det(a, b, c).

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    (x, a.mul_add(b, -x))
}

/// Shewchuk's Grow-Expansion with zero elimination: adds `b` to the non-overlapping expansion `e`
/// (increasing magnitude), exactly.
fn grow(e: &mut Vec<f64>, b: f64) {
    let mut q = b;
    let mut out = Vec::with_capacity(e.len() + 1);
    for &x in e.iter() {
        let (s, h) = two_sum(q, x);
        q = s;
        if h != 0.0 {
            out.push(h);
        }
    }
    if q != 0.0 {
        out.push(q);
    }
    *e = out;
}

/// Exact sign (−1, 0, 1) of det(a, b, c) = a · (b × c): a floating-point filter, then an exact
/// expansion sum of the six triple products (each split exactly into four floats by FMA) when
/// the filter cannot decide. Exact unless a product underflows (coordinates here are in [−1, 1]
/// and not tiny).
pub fn orient_sign(a: Point3, b: Point3, c: Point3) -> i8 {
    let d = param::orient(a, b, c);
    let perm = a[0].abs() * ((b[1] * c[2]).abs() + (b[2] * c[1]).abs())
        + a[1].abs() * ((b[2] * c[0]).abs() + (b[0] * c[2]).abs())
        + a[2].abs() * ((b[0] * c[1]).abs() + (b[1] * c[0]).abs());
    // Each product has relative error ≤ ε, each of the 5 sums ≤ ε: 8ε·permanent is safe.
    let bound = 8.0 * f64::EPSILON * perm;
    if d > bound {
        return 1;
    }
    if d < -bound {
        return -1;
    }
    let terms = [
        (a[0], b[1], c[2], 1.0),
        (a[0], b[2], c[1], -1.0),
        (a[1], b[2], c[0], 1.0),
        (a[1], b[0], c[2], -1.0),
        (a[2], b[0], c[1], 1.0),
        (a[2], b[1], c[0], -1.0),
    ];
    let mut e: Vec<f64> = Vec::with_capacity(24);
    for (x, y, z, s) in terms {
        let (p, pe) = two_product(x, y);
        for w in [p, pe] {
            let (q, qe) = two_product(w, z);
            grow(&mut e, s * q);
            grow(&mut e, s * qe);
        }
    }
    match e.last() {
        Some(&v) if v > 0.0 => 1,
        Some(&v) if v < 0.0 => -1,
        _ => 0,
    }
}

/// Faces whose spherical chord triangle is not strictly positive, by the exact test.
pub fn count_foldovers_exact(sphere: &[Point3], tris: &[[u32; 3]]) -> usize {
    tris.iter()
        .filter(|t| orient_sign(sphere[t[0] as usize], sphere[t[1] as usize], sphere[t[2] as usize]) <= 0)
        .count()
}

// ---------------------------------------------------------------------------------------------

/// Weights of the disk embedding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TutteWeights {
    /// Floater's mean-value weights, symmetrised (positive; lower angle distortion).
    MeanValue,
    /// Uniform weights (Tutte 1963): the second chance when the first layout is not numerically
    /// an embedding.
    Uniform,
}

/// What the fallback did, for the report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FallbackReport {
    /// The vertex sent to the north pole (its link is the disk's boundary).
    pub removed_vertex: u32,
    pub weights: TutteWeights,
    /// Earlier layouts that were not numerically embeddings (their weights and flip count).
    pub rejected_layouts: Vec<String>,
    /// Möbius normalisation: stereographic scale and translation of the layout, SD before/after.
    pub mobius_scale: f64,
    pub mobius_translation: [f64; 2],
    pub area_distortion_before_normalisation: f64,
    pub area_distortion_after_normalisation: f64,
    /// AD/SD after normalisation, before relaxation.
    pub angle_distortion_tutte: f64,
    pub area_distortion_tutte: f64,
    /// Relaxation sweeps kept / sweeps undone because the exact test found a flip.
    pub relax_sweeps_kept: usize,
    pub relax_sweeps_undone: usize,
    /// Wall time of the steps (ms): layout (weights + Cholesky), normalisation, relaxation.
    pub timings_ms: Vec<(String, f64)>,
}

/// Settings of the fallback.
#[derive(Clone, Debug)]
pub struct FallbackSettings {
    /// Fold-free relaxation sweeps after the normalisation (0 = the bare Tutte map).
    pub relax_sweeps: usize,
    /// Sweeps per batch between exact checks.
    pub relax_batch: usize,
}

impl Default for FallbackSettings {
    fn default() -> Self {
        FallbackSettings { relax_sweeps: 40, relax_batch: 5 }
    }
}

/// The spherical map of a closed, outward-oriented genus-0 mesh by the guaranteed construction.
/// Returns the sphere positions and the report; Err(Numerical) only when even the uniform-weight
/// layout is not an embedding in floating point.
pub fn parameterise(
    mesh: &TriMesh,
    s: &FallbackSettings,
    progress: &Progress,
) -> Result<(Vec<Point3>, FallbackReport)> {
    let n = mesh.pos.len();
    if n < 4 || mesh.tris.len() < 4 {
        return Err(Error::numerical("sphere fallback", format!("{n} vertices: not a closed surface")));
    }
    let v0 = central_vertex(mesh);
    let link = link_loop(mesh, v0)?;
    let mut rejected = Vec::new();
    let mut clock = std::time::Instant::now();
    let mut timings = Vec::new();
    let mut lap = |name: &str, timings: &mut Vec<(String, f64)>| {
        timings.push((name.to_string(), (clock.elapsed().as_secs_f64() * 1e6).round() / 1e3));
        clock = std::time::Instant::now();
    };
    for weights in [TutteWeights::MeanValue, TutteWeights::Uniform] {
        progress.check()?;
        let plane = tutte_layout(mesh, v0, &link, weights)?;
        lap("layout", &mut timings);
        let flips = planar_flips(&plane, &mesh.tris, v0);
        if flips > 0 {
            rejected.push(format!("{weights:?} weights: {flips} faces not clockwise in the plane"));
            continue;
        }
        let (mut sphere, norm) = normalise(mesh, &plane, v0, progress)?;
        let bad = count_foldovers_exact(&sphere, &mesh.tris);
        lap("normalise", &mut timings);
        if bad > 0 {
            rejected.push(format!("{weights:?} weights: {bad} flipped chord triangles after the lift"));
            continue;
        }
        let (ad0, sd0) = distortion(&mesh.pos, &sphere, &mesh.tris);
        let (kept, undone) = relax_checked(mesh, &mut sphere, s, progress)?;
        lap("relax", &mut timings);
        return Ok((
            sphere,
            FallbackReport {
                removed_vertex: v0,
                weights,
                rejected_layouts: rejected,
                mobius_scale: norm.scale,
                mobius_translation: norm.translation,
                area_distortion_before_normalisation: norm.sd_before,
                area_distortion_after_normalisation: norm.sd_after,
                angle_distortion_tutte: ad0,
                area_distortion_tutte: sd0,
                relax_sweeps_kept: kept,
                relax_sweeps_undone: undone,
                timings_ms: timings,
            },
        ));
    }
    Err(Error::numerical(
        "sphere fallback",
        format!("no layout is an embedding in floating point: {}", rejected.join("; ")),
    ))
}

/// A vertex near the centre of the mesh graph: the middle of a long shortest path found by a
/// double BFS sweep (an approximate graph centre), so the Tutte layout's depth is halved.
fn central_vertex(mesh: &TriMesh) -> u32 {
    let adj = adjacency(mesh);
    let bfs = |src: u32| -> (Vec<u32>, u32) {
        let mut parent = vec![u32::MAX; adj.len()];
        parent[src as usize] = src;
        let mut queue = std::collections::VecDeque::from([src]);
        let mut last = src;
        while let Some(v) = queue.pop_front() {
            last = v;
            for &w in &adj[v as usize] {
                if parent[w as usize] == u32::MAX {
                    parent[w as usize] = v;
                    queue.push_back(w);
                }
            }
        }
        (parent, last)
    };
    let (_, u) = bfs(0);
    let (parent, w) = bfs(u);
    let mut path = vec![w];
    while let Some(&v) = path.last() {
        let p = parent[v as usize];
        if p == v || p == u32::MAX {
            break;
        }
        path.push(p);
    }
    path[path.len() / 2]
}

fn adjacency(mesh: &TriMesh) -> Vec<Vec<u32>> {
    let mut adj = vec![Vec::new(); mesh.pos.len()];
    for &(a, b) in &mesh.edges() {
        adj[a as usize].push(b);
        adj[b as usize].push(a);
    }
    adj
}

/// The link of `v0` in order: a → b for every face (v0, a, b).
fn link_loop(mesh: &TriMesh, v0: u32) -> Result<Vec<u32>> {
    let mut next = std::collections::HashMap::new();
    for t in &mesh.tris {
        if let Some(k) = t.iter().position(|&x| x == v0) {
            next.insert(t[(k + 1) % 3], t[(k + 2) % 3]);
        }
    }
    let start = *next.keys().min().ok_or_else(|| Error::Internal("removed vertex has no faces".into()))?;
    let mut lp = vec![start];
    let mut v = start;
    loop {
        v = *next.get(&v).ok_or_else(|| {
            Error::Topology(format!("the faces around vertex {v0} do not form a closed fan (at vertex {v})"))
        })?;
        if v == start {
            break;
        }
        lp.push(v);
        if lp.len() > next.len() {
            return Err(Error::Topology(format!("the faces around vertex {v0} do not form one fan")));
        }
    }
    if lp.len() != next.len() || lp.len() < 3 {
        return Err(Error::Topology(format!("the link of vertex {v0} is not a single cycle")));
    }
    Ok(lp)
}

/// Tutte/Floater layout of the mesh without `v0`: the link counter-clockwise on the unit circle
/// (which makes every other face clockwise in the plane: the inverse stereographic projection
/// reverses orientation), interior vertices by the weighted-average system. Entry `v0` is unused.
fn tutte_layout(mesh: &TriMesh, v0: u32, link: &[u32], weights: TutteWeights) -> Result<Vec<[f64; 2]>> {
    let n = mesh.pos.len();
    let mut plane = vec![[0.0; 2]; n];
    // Boundary angles ∝ 3D edge length (with a floor, so no two corners coincide).
    let lens: Vec<f64> = (0..link.len())
        .map(|i| dist(mesh.pos[link[i] as usize], mesh.pos[link[(i + 1) % link.len()] as usize]))
        .collect();
    let total: f64 = lens.iter().sum();
    let floor = 0.2 * total / link.len() as f64;
    let lens: Vec<f64> = lens.iter().map(|&l| l.max(floor).max(1e-300)).collect();
    let total: f64 = lens.iter().sum();
    let mut acc = 0.0;
    let mut fixed = vec![false; n];
    fixed[v0 as usize] = true;
    for (i, &v) in link.iter().enumerate() {
        let a = std::f64::consts::TAU * acc / total;
        plane[v as usize] = [a.cos(), a.sin()];
        fixed[v as usize] = true;
        acc += lens[i];
    }
    // Symmetric positive edge weights.
    let mut w: std::collections::HashMap<(u32, u32), f64> = std::collections::HashMap::new();
    let key = |a: u32, b: u32| if a < b { (a, b) } else { (b, a) };
    for t in &mesh.tris {
        if t.contains(&v0) {
            continue;
        }
        for k in 0..3 {
            let (i, j, l) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            match weights {
                TutteWeights::Uniform => {
                    w.insert(key(i, j), 1.0);
                }
                TutteWeights::MeanValue => {
                    let (pi, pj, pl) = (mesh.pos[i as usize], mesh.pos[j as usize], mesh.pos[l as usize]);
                    let th = corner_angle(pi, pj, pl);
                    let h = (0.5 * th).tan();
                    // Corner i contributes tan(θ/2)/|e| to both of its edges (half each side,
                    // averaged over the two endpoints: a symmetric weight).
                    *w.entry(key(i, j)).or_insert(0.0) += 0.5 * h / dist(pi, pj);
                    *w.entry(key(i, l)).or_insert(0.0) += 0.5 * h / dist(pi, pl);
                }
            }
        }
    }
    // Degenerate 3D triangles give zero or infinite weights: clamp to a positive finite band.
    let finite: Vec<f64> = w.values().copied().filter(|x| x.is_finite() && *x > 0.0).collect();
    let mean = if finite.is_empty() { 1.0 } else { finite.iter().sum::<f64>() / finite.len() as f64 };
    let clamp =
        |x: f64| if x.is_finite() && x > 0.0 { x.clamp(1e-6 * mean, 1e6 * mean) } else { 1e-6 * mean };

    let mut edges: Vec<((u32, u32), f64)> = w.into_iter().collect();
    edges.sort_unstable_by_key(|e| e.0);
    super::planar::solve_springs(&mut plane, &fixed, edges.into_iter().map(|((a, b), x)| (a, b, clamp(x))))?;
    Ok(plane)
}

/// Faces without `v0` that are not strictly clockwise in the plane (exact: the planar orientation
/// of (x, y) points is det of the lifted (x, y, 1) points, which [`orient_sign`] decides exactly).
fn planar_flips(plane: &[[f64; 2]], tris: &[[u32; 3]], v0: u32) -> usize {
    tris.iter()
        .filter(|t| !t.contains(&v0))
        .filter(|t| {
            let q = t.map(|v| {
                let p = plane[v as usize];
                [p[0], p[1], 1.0]
            });
            orient_sign(q[0], q[1], q[2]) >= 0
        })
        .count()
}

/// Inverse stereographic projection from N = (0, 0, 1) of s·(p − t).
#[inline]
fn lift(p: [f64; 2], s: f64, t: [f64; 2]) -> Point3 {
    let (x, y) = (s * (p[0] - t[0]), s * (p[1] - t[1]));
    let r2 = x * x + y * y;
    let d = 1.0 / (1.0 + r2);
    [2.0 * x * d, 2.0 * y * d, (r2 - 1.0) * d]
}

struct Normalisation {
    scale: f64,
    translation: [f64; 2],
    sd_before: f64,
    sd_after: f64,
}

fn lift_all(plane: &[[f64; 2]], v0: u32, s: f64, t: [f64; 2]) -> Vec<Point3> {
    plane
        .iter()
        .enumerate()
        .map(|(v, &p)| if v as u32 == v0 { [0.0, 0.0, 1.0] } else { lift(p, s, t) })
        .collect()
}

/// SD of the lifted map, or +∞ if any chord triangle is not positive. The test is the exact one:
/// small lifted triangles have dets far below the rounding error of the naive formula (terms of
/// order h cancel to h²), which would reject valid layouts.
fn lifted_sd(mesh: &TriMesh, area3: &[f64], total3: f64, sphere: &[Point3]) -> f64 {
    let mut a2 = Vec::with_capacity(mesh.tris.len());
    let mut total2 = 0.0;
    for t in &mesh.tris {
        let q = t.map(|v| sphere[v as usize]);
        if orient_sign(q[0], q[1], q[2]) <= 0 {
            return f64::INFINITY;
        }
        let a = triangle_area(q[0], q[1], q[2]);
        total2 += a;
        a2.push(a);
    }
    area3.iter().zip(&a2).map(|(&x, &y)| (x / total3 - y / total2).abs()).sum()
}

/// Step 4: Nelder–Mead over (ln s, tₓ, t_y) minimising SD among valid lifts.
fn normalise(
    mesh: &TriMesh,
    plane: &[[f64; 2]],
    v0: u32,
    progress: &Progress,
) -> Result<(Vec<Point3>, Normalisation)> {
    let area3: Vec<f64> = mesh
        .tris
        .iter()
        .map(|t| triangle_area(mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize]))
        .collect();
    let total3: f64 = area3.iter().sum::<f64>().max(1e-300);
    // Start: the cap of v0's fan gets its 3D area share: a disk of radius ρ lifts to the share
    // ρ²/(1 + ρ²) of the sphere, the unit-circle boundary is scaled to ρ.
    let fan: f64 = mesh.tris.iter().zip(&area3).filter(|(t, _)| t.contains(&v0)).map(|(_, &a)| a).sum();
    let f = (fan / total3).clamp(1e-6, 0.5);
    let rho = (1.0 / f - 1.0).sqrt();
    let eval = |x: [f64; 3]| -> f64 {
        let sph = lift_all(plane, v0, x[0].exp(), [x[1], x[2]]);
        lifted_sd(mesh, &area3, total3, &sph)
    };
    let mut start = [rho.ln(), 0.0, 0.0];
    let mut f0 = eval(start);
    // If the start is not a valid lift (a near-degenerate triangle with a huge circumcircle),
    // shrink the layout until it is (s → 0 makes every non-degenerate triangle valid).
    let mut shrink = 0;
    while !f0.is_finite() && shrink < 200 {
        start[0] -= 0.5;
        f0 = eval(start);
        shrink += 1;
    }
    if !f0.is_finite() {
        return Err(Error::numerical("sphere fallback", "no scale of the Tutte layout lifts without flips"));
    }
    let sd_before = f0;
    // Nelder–Mead (standard coefficients), fixed budget.
    let mut simplex: Vec<([f64; 3], f64)> = vec![(start, f0)];
    for (k, step) in [0.7, 0.15, 0.15].into_iter().enumerate() {
        let mut x = start;
        x[k] += step;
        simplex.push((x, eval(x)));
    }
    for it in 0..80 {
        if it % 10 == 0 {
            progress.check()?;
        }
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (simplex[3].1 - simplex[0].1).abs() <= 1e-4 * simplex[0].1.abs() {
            break;
        }
        let mut c = [0.0; 3];
        for (x, _) in &simplex[..3] {
            for k in 0..3 {
                c[k] += x[k] / 3.0;
            }
        }
        let worst = simplex[3];
        let along = |t: f64| -> [f64; 3] {
            let mut y = [0.0; 3];
            for k in 0..3 {
                y[k] = c[k] + t * (worst.0[k] - c[k]);
            }
            y
        };
        let xr = along(-1.0);
        let fr = eval(xr);
        if fr < simplex[0].1 {
            let xe = along(-2.0);
            let fe = eval(xe);
            simplex[3] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[2].1 {
            simplex[3] = (xr, fr);
        } else {
            let xc = if fr < worst.1 { along(-0.5) } else { along(0.5) };
            let fc = eval(xc);
            if fc < worst.1.min(fr) {
                simplex[3] = (xc, fc);
            } else {
                let best = simplex[0].0;
                for e in simplex.iter_mut().skip(1) {
                    for (x, b) in e.0.iter_mut().zip(best) {
                        *x = b + 0.5 * (*x - b);
                    }
                    e.1 = eval(e.0);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (x, fx) = simplex[0];
    let sphere = lift_all(plane, v0, x[0].exp(), [x[1], x[2]]);
    Ok((sphere, Normalisation { scale: x[0].exp(), translation: [x[1], x[2]], sd_before, sd_after: fx }))
}

/// Step 5: the fold-free mean-value relaxation in batches, each verified exactly. A batch that
/// flips a triangle, or raises AD + SD (the relaxation is there to lower distortion; on tiny
/// meshes such as a tetrahedron the mean-value target of a vertex is near its antipode and the
/// sweeps only squash the triangles), is undone and ends the relaxation.
/// Returns (sweeps kept, sweeps undone).
fn relax_checked(
    mesh: &TriMesh,
    sphere: &mut [Point3],
    s: &FallbackSettings,
    progress: &Progress,
) -> Result<(usize, usize)> {
    if s.relax_sweeps == 0 {
        return Ok((0, 0));
    }
    let h = Hierarchy::new(&mesh.pos, &mesh.tris);
    let batch = s.relax_batch.max(1);
    let mut kept = 0;
    let mut undone = 0;
    let score = |sphere: &[Point3]| {
        let (ad, sd) = distortion(&mesh.pos, sphere, &mesh.tris);
        ad + sd
    };
    let mut current = score(sphere);
    while kept < s.relax_sweeps {
        let k = batch.min(s.relax_sweeps - kept);
        let before = sphere.to_vec();
        param::relax(&h, &mesh.pos, sphere, k, progress)?;
        let next = score(sphere);
        if count_foldovers_exact(sphere, &mesh.tris) > 0 || next.is_nan() || next > current {
            sphere.copy_from_slice(&before);
            undone += k;
            break;
        }
        current = next;
        kept += k;
    }
    Ok((kept, undone))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_orientation_decides_what_the_filter_cannot() {
        let a = [1.0, 0.0, 0.0];
        let b = [0.0, 1.0, 0.0];
        assert_eq!(orient_sign(a, b, [0.0, 0.0, 1.0]), 1);
        assert_eq!(orient_sign(b, a, [0.0, 0.0, 1.0]), -1);
        // Three points on one great circle: exactly 0.
        assert_eq!(orient_sign(a, b, [0.6, 0.8, 0.0]), 0);
        // c just off the great circle through a and b by one ulp of z: det = z exactly.
        let tiny = f64::MIN_POSITIVE * 1e10;
        assert_eq!(orient_sign(a, b, [0.6, 0.8, tiny]), 1);
        assert_eq!(orient_sign(a, b, [0.6, 0.8, -tiny]), -1);
        // Nearly coplanar rows where the naive product cancels: (1+e, 1, 1), (1, 1+e, 1), (1, 1, 1+e)
        // has det = 3e² + e³ > 0.
        let e = 2f64.powi(-30);
        assert_eq!(orient_sign([1.0 + e, 1.0, 1.0], [1.0, 1.0 + e, 1.0], [1.0, 1.0, 1.0 + e]), 1);
        assert_eq!(orient_sign([1.0, 1.0 + e, 1.0], [1.0 + e, 1.0, 1.0], [1.0, 1.0, 1.0 + e]), -1);
    }

    #[test]
    fn lift_is_on_the_unit_sphere_and_reverses_orientation() {
        let p = [[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]]; // counter-clockwise in the plane
        let q = p.map(|x| lift(x, 1.0, [0.0, 0.0]));
        for x in q {
            assert!((crate::geometry::norm(x) - 1.0).abs() < 1e-15);
        }
        assert_eq!(orient_sign(q[0], q[1], q[2]), -1);
    }
}
