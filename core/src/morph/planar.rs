//! The planar domain for disk-like inputs (one boundary loop, genus 0): seed 002 §3.4 ELRP.
//!
//! - Boundary on the unit circle by arc length (eq. IV.41–IV.43: α_{i+1} − α_i ∝ 3D edge length).
//! - Interior: the spring system Σ_j w_ij (φ_j − φ_i) = 0 with ELRP weights w_ij = l_ij (the 3D edge
//!   length, *proportional* to length as printed in eq. IV.44–IV.46; symmetric, so one sparse
//!   Cholesky factorisation serves both coordinates), or uniform (Tutte) weights.
//!   Every weight is positive and the boundary is strictly convex, so Tutte/Floater's theorem says
//!   the map is an embedding; we still count flipped triangles (floating point can flip slivers)
//!   and fall back to Tutte weights if ELRP's map has any, saying so in the report.
//! - Points of the plane are carried *lifted* as (x, y, 1): then the sphere code's predicates
//!   (`orient` = det(a, b, c), `bary_on_chord`, the walking `Locator`, AD/SD) compute exactly
//!   the planar quantities (det of lifted points = twice the signed area; the ray from the origin
//!   through a lifted point meets the plane z = 1 at the point itself).
//! - Boundary correspondence: each disk is rotated so its boundary matches input 0's (least squares
//!   over the normalised 3D boundary curves; with feature pairs, the mean angle between them).
//! - Feature alignment: the same stepwise CTPS C²a warp as on the sphere, in the plane, with the
//!   boundary vertices projected back onto the circle after every step and a fold-over check.
//! - Common boundary: the union of all inputs' boundary angles is inserted into every disk's
//!   boundary edges (splitting the boundary triangles; the new vertex lies on the 3D boundary edge,
//!   so the surface is unchanged). All disks then cover the *same* convex polygon, which is what a
//!   2-D overlay of two triangulations needs.

use std::f64::consts::TAU;

use crate::error::{Error, Result};
use crate::geometry::{add, dist, sub};
use crate::job::Progress;
use crate::laplacian::Csr;
use crate::mesh::Point3;
use crate::solve::Cholesky;

use super::align::ctps_c2a;
use super::param::{count_foldovers, orient};
use super::trimesh::{TopologyInfo, TriMesh};

/// Lifts a plane point to (x, y, 1).
#[inline]
pub fn lift(x: f64, y: f64) -> Point3 {
    [x, y, 1.0]
}

/// Whether the topology is a disk: connected, manifold, one boundary loop, V − E + F = 1.
pub fn is_disk(info: &TopologyInfo) -> bool {
    info.faces >= 1
        && info.components == 1
        && info.boundary_loops == 1
        && info.non_manifold_edges == 0
        && info.non_manifold_vertices == 0
        && info.euler_characteristic == 1
}

/// Genus of a connected manifold surface with `b` boundary loops: χ = 2 − 2g − b.
pub fn genus_of(info: &TopologyInfo) -> Option<i64> {
    (info.components == 1 && info.non_manifold_edges == 0 && info.non_manifold_vertices == 0)
        .then(|| 2 - info.boundary_loops as i64 - info.euler_characteristic)
        .filter(|x| x % 2 == 0)
        .map(|x| x / 2)
}

/// The refusal for an input that is neither a closed genus-0 surface nor a disk.
pub fn describe(info: &TopologyInfo) -> String {
    let mut s = Vec::new();
    if info.components != 1 {
        s.push(format!("{} connected components", info.components));
    }
    if info.non_manifold_edges > 0 {
        s.push(format!("{} non-manifold edges", info.non_manifold_edges));
    }
    if info.non_manifold_vertices > 0 {
        s.push(format!("{} non-manifold vertices", info.non_manifold_vertices));
    }
    match genus_of(info) {
        Some(g) => s.push(format!("genus {g} with {} boundary loops", info.boundary_loops)),
        None => s.push(format!(
            "{} boundary loops, Euler characteristic {}",
            info.boundary_loops, info.euler_characteristic
        )),
    }
    s.join(", ")
}

/// The boundary loop, ordered along the boundary half-edges (a → b where a face lists a → b):
/// with counter-clockwise faces this runs counter-clockwise around the disk.
pub fn boundary_loop(m: &TriMesh) -> Result<Vec<u32>> {
    use std::collections::HashMap;
    let mut half: HashMap<(u32, u32), ()> = HashMap::with_capacity(m.tris.len() * 3);
    for t in &m.tris {
        for k in 0..3 {
            half.insert((t[k], t[(k + 1) % 3]), ());
        }
    }
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in half.keys() {
        if !half.contains_key(&(b, a)) && next.insert(a, b).is_some() {
            return Err(Error::Topology(format!("vertex {a} has two outgoing boundary edges")));
        }
    }
    let start = *next.keys().min().ok_or_else(|| Error::Topology("no boundary".into()))?;
    let mut lp = vec![start];
    let mut v = start;
    loop {
        v = *next.get(&v).ok_or_else(|| Error::Topology("boundary does not close".into()))?;
        if v == start {
            break;
        }
        lp.push(v);
        if lp.len() > next.len() {
            return Err(Error::Topology("boundary loop does not close".into()));
        }
    }
    if lp.len() != next.len() {
        return Err(Error::Topology(format!(
            "more than one boundary loop ({} of {} boundary edges in the first)",
            lp.len(),
            next.len()
        )));
    }
    Ok(lp)
}

/// Interior weights of the spring system.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize, utoipa::ToSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum PlanarMethod {
    /// Seed 002's ELRP: w_ij = 3D edge length (eq. IV.44, as printed), boundary by arc length.
    #[default]
    Elrp,
    /// Tutte's uniform weights (w_ij = 1), boundary by arc length.
    Tutte,
    /// Inverse edge length (w_ij = 1/l_ij: Greiner–Hormann r = 1, the reading of eq. IV.44 with
    /// the proportionality inverted), boundary by arc length.
    InverseLength,
}

/// A disk map: lifted plane positions, the boundary loop and each boundary vertex's angle.
#[derive(Clone, Debug)]
pub struct DiskMap {
    pub plane: Vec<Point3>,
    pub boundary: Vec<u32>,
    pub angles: Vec<f64>,
    pub report: PlanarReport,
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct PlanarReport {
    pub method: String,
    pub fallback_reason: Option<String>,
    pub boundary_vertices: usize,
    /// Flipped (non-positive) plane triangles of the final map: must be 0.
    pub foldovers: usize,
    /// AD (eq. IV.64, radians) and SD (eq. IV.65) between the 3D mesh and its plane triangles.
    pub angle_distortion: f64,
    pub area_distortion: f64,
}

/// Boundary angles by arc length (eq. IV.42 = α_{i+1} = α_i + 2π ℓ_i / Σℓ), starting at 0.
pub fn arc_length_angles(pos: &[Point3], lp: &[u32]) -> Vec<f64> {
    let n = lp.len();
    let len: Vec<f64> = (0..n).map(|i| dist(pos[lp[i] as usize], pos[lp[(i + 1) % n] as usize])).collect();
    let total: f64 = len.iter().sum();
    let mut a = Vec::with_capacity(n);
    let mut acc = 0.0;
    for (i, l) in len.iter().enumerate() {
        // Degenerate (zero-length) boundary: equal spacing.
        a.push(if total > 0.0 { TAU * acc / total } else { TAU * i as f64 / n as f64 });
        acc += l;
    }
    a
}

/// Solves the interior of the spring system with the boundary fixed at `angles`.
fn solve_interior(m: &TriMesh, lp: &[u32], angles: &[f64], method: PlanarMethod) -> Result<Vec<Point3>> {
    let n = m.pos.len();
    let mut at = vec![[0.0; 2]; n];
    let mut fixed = vec![false; n];
    for (&v, &a) in lp.iter().zip(angles) {
        fixed[v as usize] = true;
        at[v as usize] = [a.cos(), a.sin()];
    }
    let edges = m.edges();
    let mean_len = edges.iter().map(|&(a, b)| dist(m.pos[a as usize], m.pos[b as usize])).sum::<f64>()
        / edges.len().max(1) as f64;
    let weight = |a: u32, b: u32| -> f64 {
        match method {
            PlanarMethod::Tutte => 1.0,
            // A zero-length edge would give a zero weight (and possibly a singular row).
            PlanarMethod::Elrp => dist(m.pos[a as usize], m.pos[b as usize]).max(1e-9 * mean_len.max(1e-300)),
            PlanarMethod::InverseLength => {
                1.0 / dist(m.pos[a as usize], m.pos[b as usize]).max(1e-9 * mean_len.max(1e-300))
            }
        }
    };
    solve_springs(&mut at, &fixed, edges.iter().map(|&(a, b)| (a, b, weight(a, b))))?;
    Ok(at.iter().map(|p| lift(p[0], p[1])).collect())
}

/// The weighted spring (Dirichlet) system of a planar layout: every vertex with `fixed[v]` stays
/// at `at[v]`, every other lands at the weighted mean of its neighbours. `edges` lists each
/// undirected edge once with its weight (> 0). Both coordinates from one Cholesky factorisation;
/// shared by the disk maps here and the sphere fallback's Tutte layout.
pub(super) fn solve_springs(
    at: &mut [[f64; 2]],
    fixed: &[bool],
    edges: impl IntoIterator<Item = (u32, u32, f64)>,
) -> Result<()> {
    let n = at.len();
    let mut free = vec![u32::MAX; n];
    let mut nf = 0usize;
    for v in 0..n {
        if !fixed[v] {
            free[v] = nf as u32;
            nf += 1;
        }
    }
    if nf == 0 {
        return Ok(());
    }
    let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); nf];
    let mut diag = vec![0.0; nf];
    let mut rhs = vec![0.0; 2 * nf];
    for (a, b, w) in edges {
        for (i, j) in [(a, b), (b, a)] {
            let fi = free[i as usize];
            if fi == u32::MAX {
                continue;
            }
            diag[fi as usize] += w;
            let fj = free[j as usize];
            if fj == u32::MAX {
                let p = at[j as usize];
                rhs[fi as usize] += w * p[0];
                rhs[nf + fi as usize] += w * p[1];
            } else {
                rows[fi as usize].push((fj, -w));
            }
        }
    }
    let mut row_ptr = Vec::with_capacity(nf + 1);
    let mut col = Vec::new();
    let mut val = Vec::new();
    row_ptr.push(0u32);
    for (i, row) in rows.iter_mut().enumerate() {
        row.push((i as u32, diag[i]));
        row.sort_unstable_by_key(|e| e.0);
        for &(j, w) in row.iter() {
            col.push(j);
            val.push(w);
        }
        row_ptr.push(col.len() as u32);
    }
    let a = Csr { n: nf, row_ptr, col, val };
    let mut chol = Cholesky::analyze(&a)?;
    chol.factor(&a)?;
    chol.solve_in_place(&mut rhs, 2)?;
    for v in 0..n {
        let f = free[v];
        if f != u32::MAX {
            at[v] = [rhs[f as usize], rhs[nf + f as usize]];
        }
    }
    Ok(())
}

/// The disk map of a disk-topology mesh (counter-clockwise faces), with the embedding check and
/// the Tutte fallback.
pub fn parameterise(m: &TriMesh, method: PlanarMethod) -> Result<DiskMap> {
    let lp = boundary_loop(m)?;
    let angles = arc_length_angles(&m.pos, &lp);
    let mut rep = PlanarReport {
        method: match method {
            PlanarMethod::Elrp => "elrp",
            PlanarMethod::Tutte => "tutte",
            PlanarMethod::InverseLength => "inverse_length",
        }
        .into(),
        boundary_vertices: lp.len(),
        ..Default::default()
    };
    let mut plane = solve_interior(m, &lp, &angles, method)?;
    let mut folds = count_foldovers(&plane, &m.tris);
    if folds > 0 && method != PlanarMethod::Tutte {
        rep.fallback_reason = Some(format!(
            "{folds} flipped triangles in the {} map (floating point on slivers); used Tutte weights",
            rep.method
        ));
        rep.method = "tutte".into();
        plane = solve_interior(m, &lp, &angles, PlanarMethod::Tutte)?;
        folds = count_foldovers(&plane, &m.tris);
    }
    rep.foldovers = folds;
    let (ad, sd) = super::param::distortion(&m.pos, &plane, &m.tris);
    rep.angle_distortion = ad;
    rep.area_distortion = sd;
    Ok(DiskMap { plane, boundary: lp, angles, report: rep })
}

/// The 3D boundary point at angle `t` (radians, any value) of a disk whose boundary vertices
/// `lp` sit at increasing `angles` in [0, 2π).
fn boundary_point(pos: &[Point3], lp: &[u32], angles: &[f64], t: f64) -> Point3 {
    let n = lp.len();
    let t = t.rem_euclid(TAU);
    // First index with angle > t, cyclically.
    let i1 = angles.partition_point(|&a| a <= t);
    let i0 = (i1 + n - 1) % n;
    let i1 = i1 % n;
    let (a0, mut a1) = (angles[i0], angles[i1]);
    let mut tt = t;
    if a1 <= a0 {
        a1 += TAU;
        if tt < a0 {
            tt += TAU;
        }
    }
    let f = if a1 > a0 { ((tt - a0) / (a1 - a0)).clamp(0.0, 1.0) } else { 0.0 };
    let (p, q) = (pos[lp[i0] as usize], pos[lp[i1] as usize]);
    add(p, crate::geometry::scale(sub(q, p), f))
}

/// The rotation φ of disk B (its angle θ_B ↦ θ_B − φ) that best matches B's normalised 3D boundary
/// to A's at equal angles: least squares over 256 samples, 720 trial angles, then refined.
#[allow(clippy::too_many_arguments)]
pub fn boundary_rotation(
    pos_a: &[Point3],
    lp_a: &[u32],
    ang_a: &[f64],
    pos_b: &[Point3],
    lp_b: &[u32],
    ang_b: &[f64],
) -> f64 {
    const S: usize = 256;
    let pa: Vec<Point3> =
        (0..S).map(|s| boundary_point(pos_a, lp_a, ang_a, TAU * s as f64 / S as f64)).collect();
    let cost = |phi: f64| -> f64 {
        pa.iter()
            .enumerate()
            .map(|(s, &p)| {
                let q = boundary_point(pos_b, lp_b, ang_b, TAU * s as f64 / S as f64 + phi);
                crate::geometry::norm2(sub(p, q))
            })
            .sum()
    };
    let mut best = (f64::INFINITY, 0.0);
    for k in 0..720 {
        let phi = TAU * k as f64 / 720.0;
        let c = cost(phi);
        if c < best.0 {
            best = (c, phi);
        }
    }
    // Refine around the best coarse angle (golden-section-free: two finer scans).
    let mut step = TAU / 720.0;
    for _ in 0..2 {
        let centre = best.1;
        for k in -10..=10 {
            let phi = centre + step * k as f64 / 10.0;
            let c = cost(phi);
            if c < best.0 {
                best = (c, phi);
            }
        }
        step /= 10.0;
    }
    best.1.rem_euclid(TAU)
}

/// The mean angular offset of B's feature points from A's (weighted by their radii).
pub fn feature_rotation(plane_a: &[Point3], fa: &[u32], plane_b: &[Point3], fb: &[u32]) -> Option<f64> {
    let (mut s, mut c) = (0.0, 0.0);
    for (&va, &vb) in fa.iter().zip(fb) {
        let (p, q) = (plane_a[va as usize], plane_b[vb as usize]);
        // Angle of q relative to p, times |p||q|: Im and Re of conj(p)·q.
        c += p[0] * q[0] + p[1] * q[1];
        s += p[0] * q[1] - p[1] * q[0];
    }
    (s.hypot(c) > 1e-12).then(|| s.atan2(c).rem_euclid(TAU))
}

/// Rotates a disk map by −φ (so B's angle θ + φ lands on θ); boundary angles stay in [0, 2π) and
/// the loop is re-started at its smallest angle so the angles increase along it.
pub fn rotate(map: &mut DiskMap, phi: f64) {
    let (s, c) = (-phi).sin_cos();
    for p in &mut map.plane {
        *p = lift(c * p[0] - s * p[1], s * p[0] + c * p[1]);
    }
    for a in &mut map.angles {
        *a = (*a - phi).rem_euclid(TAU);
    }
    restart_at_min(map);
}

fn restart_at_min(map: &mut DiskMap) {
    let k = (0..map.angles.len()).min_by(|&i, &j| map.angles[i].total_cmp(&map.angles[j])).unwrap_or(0);
    map.angles.rotate_left(k);
    map.boundary.rotate_left(k);
}

/// A plane warp s(x) = Σ αᵢ φ(|x − cᵢ|/r), interpolating displacements at the centres, with no
/// polynomial part. (With one: two features leave the affine part fully determined by them, so
/// the "warp" is a global affine map that drags the whole rim and folds triangles there; without
/// it the warp is local, which is what the planar domain needs. CTPS C²a is positive definite.)
struct PlaneWarp {
    centres: Vec<[f64; 2]>,
    alpha: Vec<[f64; 2]>,
    radius: f64,
}

impl PlaneWarp {
    fn fit(centres: &[[f64; 2]], disp: &[[f64; 2]], radius: f64) -> Result<PlaneWarp> {
        let n = centres.len();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let d = (centres[i][0] - centres[j][0]).hypot(centres[i][1] - centres[j][1]);
                a[i * n + j] = ctps_c2a(d / radius);
            }
        }
        let mut alpha = vec![[0.0; 2]; n];
        for c in 0..2 {
            let b: Vec<f64> = disp.iter().map(|d| d[c]).collect();
            let x = crate::register::solve_dense(&a, &b, n).ok_or_else(|| {
                Error::params("features", "feature points coincide in the plane; the warp is singular")
            })?;
            for i in 0..n {
                alpha[i][c] = x[i];
            }
        }
        Ok(PlaneWarp { centres: centres.to_vec(), alpha, radius })
    }

    fn displacement(&self, x: f64, y: f64) -> [f64; 2] {
        let mut d = [0.0; 2];
        for (c, a) in self.centres.iter().zip(&self.alpha) {
            let r = (x - c[0]).hypot(y - c[1]);
            if r < self.radius {
                let f = ctps_c2a(r / self.radius);
                d[0] += a[0] * f;
                d[1] += a[1] * f;
            }
        }
        d
    }
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct PlaneAlignReport {
    pub feature_points: usize,
    /// Rotation (radians) applied to each disk to match input 0's boundary.
    pub boundary_rotation: Vec<f64>,
    /// "boundary_shape" (least squares over the 3D boundary curves) or "features".
    pub rotation_rule: String,
    pub warp_steps: Vec<usize>,
    /// Largest plane distance between a feature point and its goal before and after the warp.
    pub max_feature_gap_before: f64,
    pub max_feature_gap_after: f64,
    pub foldovers: usize,
}

/// Whether the boundary loop still runs strictly counter-clockwise once around the circle.
fn boundary_is_monotone(plane: &[Point3], lp: &[u32]) -> bool {
    let n = lp.len();
    let mut turn = 0.0;
    for i in 0..n {
        let (p, q) = (plane[lp[i] as usize], plane[lp[(i + 1) % n] as usize]);
        let d = (p[0] * q[1] - p[1] * q[0]).atan2(p[0] * q[0] + p[1] * q[1]);
        if d <= 0.0 {
            return false;
        }
        turn += d;
    }
    (turn - TAU).abs() < 1e-6
}

/// Moves each feature's points (`features[i][k]`, vertex of feature i in disk k) to their mean by
/// the stepwise CTPS C²a warp of the plane; boundary points are projected back onto the circle
/// after each step; a step that flips a triangle or breaks the boundary order is halved.
pub fn align_features(
    maps: &mut [DiskMap],
    tris: &[&[[u32; 3]]],
    features: &[Vec<u32>],
    steps: usize,
    support_radius: f64,
    progress: &Progress,
) -> Result<(usize, Vec<usize>, f64, f64)> {
    let k_in = maps.len();
    let goals: Vec<Point3> = features
        .iter()
        .map(|f| {
            let s = (0..k_in).fold([0.0; 3], |s, k| add(s, maps[k].plane[f[k] as usize]));
            let mut g = crate::geometry::scale(s, 1.0 / k_in as f64);
            // The mean of points of the closed disk is in the disk; keep a boundary feature on it.
            let r = g[0].hypot(g[1]);
            if r > 1.0 {
                g = lift(g[0] / r, g[1] / r);
            }
            lift(g[0], g[1])
        })
        .collect();
    let gap = |maps: &[DiskMap]| -> f64 {
        features
            .iter()
            .zip(&goals)
            .flat_map(|(f, g)| (0..k_in).map(move |k| (k, f[k], *g)))
            .map(|(k, v, g)| dist(maps[k].plane[v as usize], g))
            .fold(0.0, f64::max)
    };
    let before = gap(maps);
    let mut steps_done = Vec::new();
    for k in 0..k_in {
        progress.fraction(k as f64 / k_in as f64)?;
        let idx: Vec<usize> = features.iter().map(|f| f[k] as usize).collect();
        let start: Vec<Point3> = idx.iter().map(|&v| maps[k].plane[v]).collect();
        let mut on_bnd = vec![false; maps[k].plane.len()];
        for &v in &maps[k].boundary {
            on_bnd[v as usize] = true;
        }
        let mut done = 0;
        let mut todo: Vec<(f64, u32)> = (1..=steps).rev().map(|j| (j as f64 / steps as f64, 0)).collect();
        let mut reached = 0.0;
        while let Some((t, depth)) = todo.pop() {
            progress.check()?;
            let centres: Vec<[f64; 2]> =
                idx.iter().map(|&v| [maps[k].plane[v][0], maps[k].plane[v][1]]).collect();
            let disp: Vec<[f64; 2]> = start
                .iter()
                .zip(&goals)
                .zip(&centres)
                .map(|((&a, &g), &c)| [a[0] + t * (g[0] - a[0]) - c[0], a[1] + t * (g[1] - a[1]) - c[1]])
                .collect();
            let warp = PlaneWarp::fit(&centres, &disp, support_radius)?;
            let moved: Vec<Point3> = maps[k]
                .plane
                .iter()
                .enumerate()
                .map(|(v, &p)| {
                    let d = warp.displacement(p[0], p[1]);
                    let (x, y) = (p[0] + d[0], p[1] + d[1]);
                    if on_bnd[v] {
                        let r = x.hypot(y).max(1e-300);
                        lift(x / r, y / r)
                    } else {
                        lift(x, y)
                    }
                })
                .collect();
            if count_foldovers(&moved, tris[k]) == 0 && boundary_is_monotone(&moved, &maps[k].boundary) {
                maps[k].plane = moved;
                reached = t;
                done += 1;
            } else if depth < 8 {
                todo.push((t, depth + 1));
                todo.push(((reached + t) / 2.0, depth + 1));
            } else {
                break;
            }
        }
        // Boundary angles follow the moved boundary vertices.
        let m = &mut maps[k];
        for (a, &v) in m.angles.iter_mut().zip(&m.boundary) {
            let p = m.plane[v as usize];
            *a = p[1].atan2(p[0]).rem_euclid(TAU);
        }
        restart_at_min(m);
        steps_done.push(done);
    }
    let after = gap(maps);
    let folds = (0..k_in).map(|k| count_foldovers(&maps[k].plane, tris[k])).sum();
    Ok((folds, steps_done, before, after))
}

/// Angles closer than this are one boundary vertex of the common boundary.
const ANGLE_MERGE: f64 = 1e-9;

/// The sorted union of all disks' boundary angles (near-equal angles merged).
pub fn union_angles(maps: &[DiskMap]) -> Vec<f64> {
    let mut all: Vec<f64> = maps.iter().flat_map(|m| m.angles.iter().copied()).collect();
    all.sort_by(f64::total_cmp);
    let mut out: Vec<f64> = Vec::with_capacity(all.len());
    for a in all {
        if out.last().is_none_or(|&l| a - l > ANGLE_MERGE) {
            out.push(a);
        }
    }
    // The wrap-around pair (last near 2π, first near 0).
    if out.len() > 1 && out[0] + TAU - out[out.len() - 1] <= ANGLE_MERGE {
        out.pop();
    }
    out
}

/// A disk with the common boundary: lifted positions, 3D positions, triangles, and for each
/// vertex its index in the common boundary (`u32::MAX` inside).
#[derive(Clone, Debug)]
pub struct CommonDisk {
    pub plane: Vec<Point3>,
    pub pos: Vec<Point3>,
    pub tris: Vec<[u32; 3]>,
    pub bnd: Vec<u32>,
    pub inserted: usize,
}

/// Index in `union` of the angle nearest to `a` (cyclic).
fn nearest(union: &[f64], a: f64) -> usize {
    let i = union.partition_point(|&u| u < a);
    let cands = [i % union.len(), (i + union.len() - 1) % union.len()];
    let d = |j: usize| {
        let x = (union[j] - a).rem_euclid(TAU);
        x.min(TAU - x)
    };
    if d(cands[0]) <= d(cands[1]) {
        cands[0]
    } else {
        cands[1]
    }
}

/// Inserts the common boundary angles into one disk (see the module docs). Boundary vertices
/// are snapped to their common angle (they are within [`ANGLE_MERGE`] of it).
pub fn with_common_boundary(m: &TriMesh, map: &DiskMap, union: &[f64]) -> Result<CommonDisk> {
    let nu = union.len();
    let on_circle = |j: usize| lift(union[j].cos(), union[j].sin());
    let mut plane = map.plane.clone();
    let mut pos = m.pos.clone();
    let mut bnd = vec![u32::MAX; pos.len()];
    let nb = map.boundary.len();
    let mut own: Vec<usize> = Vec::with_capacity(nb);
    for &v in &map.boundary {
        let p = plane[v as usize];
        let j = nearest(union, p[1].atan2(p[0]).rem_euclid(TAU));
        bnd[v as usize] = j as u32;
        plane[v as usize] = on_circle(j);
        own.push(j);
    }
    // Face of each boundary edge a → b, and the edge's corner in it.
    let mut edge_face = std::collections::HashMap::with_capacity(nb);
    for (fi, t) in m.tris.iter().enumerate() {
        for k in 0..3 {
            edge_face.insert((t[k], t[(k + 1) % 3]), (fi, k));
        }
    }
    // New vertices on each face's edges (a face can have two or three boundary edges).
    let mut on_edge: std::collections::HashMap<usize, [Vec<u32>; 3]> = std::collections::HashMap::new();
    let mut inserted = 0;
    for i in 0..nb {
        let (a, b) = (map.boundary[i], map.boundary[(i + 1) % nb]);
        let (ja, jb) = (own[i], own[(i + 1) % nb]);
        let gap = (jb + nu - ja) % nu;
        if gap == 0 {
            return Err(Error::numerical(
                "common boundary",
                format!("boundary vertices {a} and {b} fell on the same common angle"),
            ));
        }
        if gap == 1 {
            continue;
        }
        let &(fi, k) = edge_face
            .get(&(a, b))
            .ok_or_else(|| Error::Internal(format!("boundary edge {a}→{b} has no face")))?;
        let (pa, pb) = (m.pos[a as usize], m.pos[b as usize]);
        let span = (union[jb] - union[ja]).rem_euclid(TAU);
        let list = &mut on_edge.entry(fi).or_default()[k];
        for s in 1..gap {
            let j = (ja + s) % nu;
            let f = (union[j] - union[ja]).rem_euclid(TAU) / span;
            list.push(pos.len() as u32);
            pos.push(add(pa, crate::geometry::scale(sub(pb, pa), f)));
            plane.push(on_circle(j));
            bnd.push(j as u32);
            inserted += 1;
        }
    }
    // Re-triangulate each touched face as a fan: from the corner opposite its one split edge
    // (that corner sees the whole edge, see the module docs), or, with two or three split
    // (boundary) edges, from corner 0: then all corners lie on the circle, so the polygon is
    // convex and any fan is valid.
    let mut tris = m.tris.clone();
    let mut extra: Vec<[u32; 3]> = Vec::new();
    let mut faces: Vec<usize> = on_edge.keys().copied().collect();
    faces.sort_unstable();
    for fi in faces {
        let t = m.tris[fi];
        let lists = &on_edge[&fi];
        let split: Vec<usize> = (0..3).filter(|&k| !lists[k].is_empty()).collect();
        let start = if split.len() == 1 { (split[0] + 2) % 3 } else { 0 };
        let mut poly: Vec<u32> = Vec::new();
        for s in 0..3 {
            let k = (start + s) % 3;
            poly.push(t[k]);
            poly.extend_from_slice(&lists[k]);
        }
        tris[fi] = [poly[0], poly[1], poly[2]];
        for q in 2..poly.len() - 1 {
            extra.push([poly[0], poly[q], poly[q + 1]]);
        }
    }
    tris.extend(extra);
    Ok(CommonDisk { plane, pos, tris, bnd, inserted })
}

/// Moves every interior vertex of a disk by 10⁻⁷ of its shortest plane edge in a fixed
/// pseudo-random direction (`salt` varies it per input). Symmetric inputs (a grid disk and a
/// polar hemisphere both map their centre to the origin, and share radial edge directions) would
/// otherwise put vertices of two disks on each other or on each other's edges, which the overlay's
/// predicates cannot order consistently; shared boundary vertices are handled by labels and stay.
/// Undone if it flipped anything. Returns whether it was applied.
pub fn jitter_interior(d: &mut CommonDisk, salt: u64) -> bool {
    let n = d.plane.len();
    let mut shortest = vec![f64::INFINITY; n];
    for t in &d.tris {
        for k in 0..3 {
            let (u, v) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let l = dist(d.plane[u], d.plane[v]);
            shortest[u] = shortest[u].min(l);
            shortest[v] = shortest[v].min(l);
        }
    }
    let before = d.plane.clone();
    for v in 0..n {
        if d.bnd[v] != u32::MAX || !shortest[v].is_finite() {
            continue;
        }
        // SplitMix64 of (vertex, salt) → an angle.
        let mut z = (v as u64)
            .wrapping_add(salt.wrapping_mul(0x9E37_79B9_7F4A_7C15))
            .wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        let a = TAU * (z >> 11) as f64 / (1u64 << 53) as f64;
        let e = 1e-7 * shortest[v];
        let p = d.plane[v];
        d.plane[v] = lift(p[0] + e * a.cos(), p[1] + e * a.sin());
    }
    if foldovers(&d.plane, &d.tris) > 0 {
        d.plane = before;
        return false;
    }
    true
}

/// Signed area test used by the job's checks: flipped triangles of a lifted map.
pub fn foldovers(plane: &[Point3], tris: &[[u32; 3]]) -> usize {
    tris.iter()
        .filter(|t| !(orient(plane[t[0] as usize], plane[t[1] as usize], plane[t[2] as usize]) > 0.0))
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    fn disk(n: usize) -> TriMesh {
        // A grid in a circle: the square grid's points pushed radially onto the disk (the
        // "concentric" square→disk map), so the boundary is a circle and the interior is uneven.
        let (mut g, _, _) = TriMesh::from_mesh(&shapes::grid(n, n, 2.0 / n as f64, false));
        for p in &mut g.pos {
            let (x, y) = (p[0] - 1.0, p[1] - 1.0);
            let r = x.abs().max(y.abs());
            let l = x.hypot(y);
            let f = if l > 0.0 { r / l } else { 0.0 };
            p[0] = x * f;
            p[1] = y * f;
        }
        g
    }

    #[test]
    fn a_flat_disk_maps_without_flips_and_with_its_boundary_on_the_circle() {
        let g = disk(8);
        for method in [PlanarMethod::Elrp, PlanarMethod::Tutte, PlanarMethod::InverseLength] {
            let m = parameterise(&g, method).unwrap();
            assert_eq!(m.report.foldovers, 0);
            assert_eq!(m.report.fallback_reason, None);
            for &v in &m.boundary {
                let p = m.plane[v as usize];
                assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-12);
            }
            // Each interior vertex is the weighted mean of its neighbours (the system's equation).
            let mut nb = vec![Vec::new(); g.pos.len()];
            for (a, b) in g.edges() {
                nb[a as usize].push(b);
                nb[b as usize].push(a);
            }
            let is_b: std::collections::HashSet<u32> = m.boundary.iter().copied().collect();
            for v in 0..g.pos.len() {
                if is_b.contains(&(v as u32)) {
                    continue;
                }
                let w = |u: u32| match method {
                    PlanarMethod::Tutte => 1.0,
                    PlanarMethod::Elrp => dist(g.pos[v], g.pos[u as usize]),
                    PlanarMethod::InverseLength => 1.0 / dist(g.pos[v], g.pos[u as usize]),
                };
                let ws: f64 = nb[v].iter().map(|&u| w(u)).sum();
                for c in 0..2 {
                    let mean: f64 = nb[v].iter().map(|&u| w(u) * m.plane[u as usize][c]).sum::<f64>() / ws;
                    assert!((mean - m.plane[v][c]).abs() < 1e-10);
                }
            }
        }
    }

    #[test]
    fn arc_length_angles_follow_edge_lengths() {
        // A square boundary with sides 1, 1, 1, 1 split at one extra point on side 0 (0.25/0.75).
        let pos = vec![[0.0, 0.0, 0.0], [0.25, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let a = arc_length_angles(&pos, &[0, 1, 2, 3, 4]);
        let want = [0.0, 0.25, 1.0, 2.0, 3.0].map(|x| TAU * x / 4.0);
        for (x, y) in a.iter().zip(want) {
            assert!((x - y).abs() < 1e-12, "{a:?}");
        }
    }

    #[test]
    fn rotation_of_a_shifted_parameterisation_is_recovered() {
        let g = disk(6);
        let m = parameterise(&g, PlanarMethod::Elrp).unwrap();
        // B is the same surface with every boundary angle advanced by 0.3 (and re-sorted): B's
        // point at θ + 0.3 is A's at θ, so the best rotation is 0.3.
        let mut mb = m.clone();
        for a in &mut mb.angles {
            *a = (*a + 0.3).rem_euclid(TAU);
        }
        restart_at_min(&mut mb);
        let phi = boundary_rotation(&g.pos, &m.boundary, &m.angles, &g.pos, &mb.boundary, &mb.angles);
        assert!((phi - 0.3).abs() < 1e-3, "{phi}");
        // Rotating B by it brings its angles back onto A's.
        rotate(&mut mb, phi);
        let want: std::collections::HashMap<u32, f64> =
            m.boundary.iter().copied().zip(m.angles.clone()).collect();
        for (v, a) in mb.boundary.iter().zip(&mb.angles) {
            let d = (a - want[v]).rem_euclid(TAU);
            assert!(d.min(TAU - d) < 1e-3, "vertex {v}: {a} vs {}", want[v]);
        }
    }

    #[test]
    fn common_boundary_keeps_the_surface_and_the_embedding() {
        let g = disk(6);
        let h = disk(9);
        let mg = parameterise(&g, PlanarMethod::Elrp).unwrap();
        let mut mh = parameterise(&h, PlanarMethod::Elrp).unwrap();
        rotate(&mut mh, 0.1234);
        assert!(foldovers(&mh.plane, &h.tris) == 0);
        let u = union_angles(&[mg.clone(), mh.clone()]);
        assert_eq!(u.len(), mg.boundary.len() + mh.boundary.len());
        for (m, map) in [(&g, &mg), (&h, &mh)] {
            let cd = with_common_boundary(m, map, &u).unwrap();
            assert_eq!(foldovers(&cd.plane, &cd.tris), 0);
            assert_eq!(cd.bnd.iter().filter(|&&b| b != u32::MAX).count(), u.len());
            // 3D area unchanged (the new vertices lie on the boundary edges).
            let area = |p: &[Point3], t: &[[u32; 3]]| {
                t.iter()
                    .map(|t| {
                        crate::geometry::triangle_area(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize])
                    })
                    .sum::<f64>()
            };
            assert!((area(&cd.pos, &cd.tris) - area(&m.pos, &m.tris)).abs() < 1e-12);
            // Plane area is the common polygon's.
            let poly: f64 =
                (0..u.len()).map(|j| 0.5 * (u[(j + 1) % u.len()] - u[j]).rem_euclid(TAU).sin()).sum();
            assert!((area(&cd.plane, &cd.tris) - poly).abs() < 1e-9);
        }
    }
}
