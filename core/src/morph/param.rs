//! Spherical parameterisation of a closed genus-0 mesh (seed 002 §4.2), in three steps:
//!
//! 1. simplify with recorded half-edge collapses to a working size ([`super::simplify`]);
//! 2. embed the working mesh by curvature-driven flattening (eq. IV.61–IV.62: the vertex of largest
//!    |K_s| moves to its neighbours' barycentre, It = 5·V moves a round) until it is star-shaped
//!    about its centre (every face seen from the centre with positive orientation — the
//!    visibility check), then project radially (eq. IV.63). If flattening does not reach a
//!    star shape within `max_flatten_rounds`, simplify further down to a tetrahedron, which embeds
//!    trivially (Praun–Hoppe), and say so in the report;
//! 3. undo the collapses one by one (vertex splits), placing each returning vertex at the valid
//!    candidate of a lattice over its old 1-ring that maximises the worst triangle shape
//!    (seed 002 Fig. IV.29), so the map stays an embedding by construction.
//!
//! Between levels, and at the end, a relaxation pass moves each vertex towards the normalised
//! mean-value-weighted average of its neighbours (weights from the 3D mesh, which lowers angle
//! distortion), accepting only moves that flip no triangle.
//!
//! Orientation of a spherical triangle (a, b, c): sign of det(a, b, c) (seed 003 eq. 3.5); all
//! faces of an outward-oriented input must come out positive.

use std::collections::BinaryHeap;
use std::f64::consts::PI;

use crate::error::{Error, Result};
use crate::geometry::{add, corner_angle, cross, dot, norm, normalize, scale, sub, triangle_area};
use crate::job::Progress;
use crate::mesh::Point3;

use super::simplify::Hierarchy;
use super::trimesh::TriMesh;

/// f64 ordered for a max-heap.
#[derive(PartialEq)]
struct Key(f64);
impl PartialOrd for Key {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Eq for Key {}
impl Ord for Key {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0)
    }
}

/// det(a, b, c): positive for a counter-clockwise (outward) spherical triangle.
#[inline]
pub fn orient(a: Point3, b: Point3, c: Point3) -> f64 {
    dot(cross(a, b), c)
}

/// Which spherical parameterisation is used.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, utoipa::ToSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum SphereMethod {
    /// The progressive map (flattening + vertex splits); the Tutte fallback when it fails or
    /// leaves a flipped triangle (the report says so and why).
    #[default]
    Auto,
    /// Only the progressive map (fails with a numerical problem if it cannot embed).
    Progressive,
    /// Only the guaranteed fallback: Tutte embedding of the mesh minus one vertex, inverse
    /// stereographic projection, Möbius normalisation, fold-free relaxation
    /// ([`super::sphere_fallback`]).
    Tutte,
}

/// Settings of the parameterisation (a subset of the job parameters).
#[derive(Clone, Debug)]
pub struct ParamSettings {
    pub working_vertices: usize,
    pub max_flatten_rounds: usize,
    pub relax_sweeps: usize,
    pub final_relax_sweeps: usize,
    pub sphere_method: SphereMethod,
    /// Fold-free relaxation sweeps after the fallback's Tutte map.
    pub fallback_relax_sweeps: usize,
    /// Test hook: the progressive path reports a numerical failure without trying (to test the
    /// fallback's wiring on inputs where the progressive path works).
    #[doc(hidden)]
    pub inject_progressive_failure: bool,
}

impl Default for ParamSettings {
    fn default() -> Self {
        ParamSettings {
            working_vertices: 1000,
            max_flatten_rounds: 30,
            relax_sweeps: 3,
            final_relax_sweeps: 10,
            sphere_method: SphereMethod::Auto,
            fallback_relax_sweeps: super::sphere_fallback::FallbackSettings::default().relax_sweeps,
            inject_progressive_failure: false,
        }
    }
}

/// A spherical embedding of a mesh: one unit vector per vertex.
#[derive(Clone, Debug)]
pub struct SphereMap {
    pub sphere: Vec<Point3>,
    pub report: ParamReport,
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ParamReport {
    /// "progressive" (flattening or tetrahedron, then vertex splits) or "fallback_tutte" (the
    /// guaranteed construction of [`super::sphere_fallback`]).
    pub param_method: String,
    /// Why the Tutte fallback was used (the progressive path's failure, or that it was asked for).
    pub param_fallback_reason: Option<String>,
    /// When flattening failed and the progressive map was kept after comparing it with the Tutte
    /// map: both maps' AD/SD.
    pub param_comparison: Option<String>,
    /// What the Tutte fallback did, when it ran.
    pub tutte: Option<super::sphere_fallback::FallbackReport>,
    /// How the coarse map of the progressive path was made: "curvature_flattening" or
    /// "tetrahedron" (when flattening did not reach a star shape); "tutte" for the fallback.
    pub method: String,
    pub working_vertices: usize,
    pub flatten_rounds: usize,
    /// Why the fallback was used, if it was.
    pub fallback_reason: Option<String>,
    pub vertex_splits: usize,
    /// Vertex splits that found no valid position at first and succeeded after smoothing the
    /// neighbourhood of the split vertex.
    pub local_repairs: usize,
    /// Faces of the final map with det ≤ 0 (must be 0).
    pub foldovers: usize,
    /// AD, seed 002 eq. IV.64 (radians): mean |angle in 3D − angle of the spherical chord triangle|.
    pub angle_distortion: f64,
    /// SD, seed 002 eq. IV.65: Σ |relative 3D area − relative chord-triangle area|, in [0, 2].
    pub area_distortion: f64,
    /// Earlier attempts that failed (settings and reason), when the first did not succeed.
    pub retries: Vec<String>,
    /// Wall time of the sub-steps, in run order.
    pub timings_ms: Vec<(String, f64)>,
}

/// Parameterises by `s.sphere_method`: the progressive map, with the guaranteed Tutte fallback
/// when it fails or leaves a flipped triangle (`auto`), or one of the two alone. Every result's
/// `foldovers` is counted with the exact orientation test.
pub fn parameterise(mesh: &TriMesh, s: &ParamSettings, progress: &Progress) -> Result<SphereMap> {
    match s.sphere_method {
        SphereMethod::Progressive => progressive(mesh, s, progress),
        SphereMethod::Tutte => tutte_fallback(mesh, s, "sphere_method: tutte".into(), Vec::new(), progress),
        SphereMethod::Auto => match progressive(mesh, s, progress) {
            // Flattening failed: the coarse map came from the Tutte map of the working mesh or a
            // tetrahedron, and on shapes with long protrusions (the cow's legs) the vertex splits
            // from there end far from the full-resolution Tutte map (cow: AD 0.99/SD 1.67 against
            // 0.34/0.89). Compute that too and keep the lower AD + SD.
            Ok(m) if m.report.foldovers == 0 && m.report.fallback_reason.is_some() => {
                let mut why = m.report.fallback_reason.clone().unwrap_or_default();
                if !m.report.retries.is_empty() {
                    why = format!("{why} (a retry, after: {})", m.report.retries.join("; "));
                }
                match tutte_fallback(mesh, s, String::new(), m.report.retries.clone(), progress) {
                    Ok(mut t) if t.report.foldovers == 0 => {
                        let (pa, pd) = (m.report.angle_distortion, m.report.area_distortion);
                        let (ta, td) = (t.report.angle_distortion, t.report.area_distortion);
                        let cmp = format!(
                            "{why}; progressive map ({} start) AD {pa:.3} SD {pd:.3}, Tutte map AD {ta:.3} SD {td:.3}",
                            m.report.method
                        );
                        if ta + td < pa + pd {
                            t.report.param_fallback_reason = Some(format!("{cmp}: kept the Tutte map"));
                            Ok(t)
                        } else {
                            let mut m = m;
                            m.report.param_comparison = Some(format!("{cmp}: kept the progressive map"));
                            Ok(m)
                        }
                    }
                    Ok(_) | Err(Error::Numerical { .. }) => Ok(m),
                    Err(e) => Err(e),
                }
            }
            Ok(m) if m.report.foldovers == 0 => Ok(m),
            Ok(m) => tutte_fallback(
                mesh,
                s,
                format!("the progressive map left {} flipped triangles", m.report.foldovers),
                m.report.retries,
                progress,
            ),
            Err(Error::Numerical { message, .. }) => {
                let why = format!("the progressive map failed: {message}");
                tutte_fallback(mesh, s, why.clone(), Vec::new(), progress).map_err(|e| match e {
                    Error::Numerical { message: m, .. } => {
                        Error::numerical("parameterise", format!("{why}; the Tutte fallback failed too: {m}"))
                    }
                    e => e,
                })
            }
            Err(e) => Err(e),
        },
    }
}

/// The guaranteed map ([`super::sphere_fallback`]) with its report.
fn tutte_fallback(
    mesh: &TriMesh,
    s: &ParamSettings,
    reason: String,
    retries: Vec<String>,
    progress: &Progress,
) -> Result<SphereMap> {
    let clock = std::time::Instant::now();
    let fs = super::sphere_fallback::FallbackSettings {
        relax_sweeps: s.fallback_relax_sweeps,
        ..Default::default()
    };
    let (sphere, fr) = super::sphere_fallback::parameterise(mesh, &fs, progress)?;
    let (ad, sd) = distortion(&mesh.pos, &sphere, &mesh.tris);
    let rep = ParamReport {
        param_method: "fallback_tutte".into(),
        param_fallback_reason: Some(reason),
        tutte: Some(fr),
        method: "tutte".into(),
        working_vertices: mesh.pos.len(),
        foldovers: count_foldovers(&sphere, &mesh.tris),
        angle_distortion: ad,
        area_distortion: sd,
        retries,
        timings_ms: vec![("tutte_fallback".into(), (clock.elapsed().as_secs_f64() * 1e6).round() / 1e3)],
        ..Default::default()
    };
    Ok(SphereMap { sphere, report: rep })
}

/// The progressive map, retrying with other settings when a vertex split finds no valid position
/// (thin spherical triangles can leave a numerically empty kernel): first as asked, then from a
/// tetrahedron, then with half and double the working size. The report names the retries.
fn progressive(mesh: &TriMesh, s: &ParamSettings, progress: &Progress) -> Result<SphereMap> {
    if s.inject_progressive_failure {
        return Err(Error::numerical("parameterise", "failure injected by the test hook"));
    }
    let mut tries = vec![s.clone()];
    if s.max_flatten_rounds > 0 {
        tries.push(ParamSettings { working_vertices: 4, max_flatten_rounds: 0, ..s.clone() });
    }
    tries.push(ParamSettings { working_vertices: (s.working_vertices / 2).max(4), ..s.clone() });
    tries.push(ParamSettings { working_vertices: s.working_vertices * 2, ..s.clone() });
    let mut failures = Vec::new();
    for t in &tries {
        match parameterise_once(mesh, t, progress) {
            Ok(mut m) => {
                m.report.retries = failures;
                return Ok(m);
            }
            Err(Error::Numerical { message, .. }) => failures.push(format!(
                "working_vertices {}, flatten rounds {}: {message}",
                t.working_vertices, t.max_flatten_rounds
            )),
            Err(e) => return Err(e),
        }
    }
    Err(Error::numerical("parameterise", failures.join("; ")))
}

fn parameterise_once(mesh: &TriMesh, s: &ParamSettings, progress: &Progress) -> Result<SphereMap> {
    let n = mesh.pos.len();
    let mut rep = ParamReport { param_method: "progressive".into(), ..Default::default() };
    let mut h = Hierarchy::new(&mesh.pos, &mesh.tris);
    let clock = std::time::Instant::now();
    let lap = |t: &mut std::time::Instant| -> f64 {
        let ms = t.elapsed().as_secs_f64() * 1e3;
        *t = std::time::Instant::now();
        (ms * 1e3).round() / 1e3
    };
    let mut t = clock;
    h.simplify(s.working_vertices.min(n), true, progress)?;
    rep.timings_ms.push(("simplify".into(), lap(&mut t)));
    rep.working_vertices = h.alive_vertices;
    let mut sphere = vec![[0.0; 3]; n];
    let (map, tris) = h.current();
    match flatten_to_star(
        &map.iter().map(|&v| mesh.pos[v as usize]).collect::<Vec<_>>(),
        &tris,
        s.max_flatten_rounds,
        progress,
    )? {
        Ok((embedded, rounds)) => {
            rep.method = "curvature_flattening".into();
            rep.flatten_rounds = rounds;
            for (k, &v) in map.iter().enumerate() {
                sphere[v as usize] = embedded[k];
            }
        }
        Err(reason) => {
            rep.flatten_rounds = s.max_flatten_rounds;
            rep.fallback_reason = Some(reason);
            // Flattening cannot make thin protrusions (the cow's legs and horns) visible from
            // the centre. The guaranteed Tutte map of the *working* mesh is a far better start
            // than a tetrahedron (cow: AD 0.99 → see the report's tests), and it is cheap at
            // this size. The tetrahedron stays the explicit choice (`max_flatten_rounds: 0`) and
            // the last resort.
            let coarse =
                TriMesh { pos: map.iter().map(|&v| mesh.pos[v as usize]).collect(), tris: tris.clone() };
            let tutte = if s.max_flatten_rounds > 0 {
                match super::sphere_fallback::parameterise(
                    &coarse,
                    &super::sphere_fallback::FallbackSettings::default(),
                    progress,
                ) {
                    Ok((emb, _)) => Some(emb),
                    Err(Error::Numerical { .. }) => None,
                    Err(e) => return Err(e),
                }
            } else {
                None
            };
            match tutte {
                Some(emb) => {
                    rep.method = "tutte_coarse".into();
                    for (k, &v) in map.iter().enumerate() {
                        sphere[v as usize] = emb[k];
                    }
                }
                None => {
                    rep.method = "tetrahedron".into();
                    h.simplify(4, false, progress)?;
                    let (map, tris) = h.current();
                    embed_tetrahedron(&map, &tris, &mut sphere)?;
                }
            }
        }
    }
    rep.timings_ms.push(("embed".into(), lap(&mut t)));
    let mut relax_ms = 0.0;
    // Vertex splits, with relaxation every time the vertex count has grown by 30 %.
    let total = h.records.len();
    rep.vertex_splits = total;
    let mut next_relax = (h.alive_vertices as f64 * 1.3) as usize;
    let mut done = 0usize;
    relax(&h, &mesh.pos, &mut sphere, s.relax_sweeps, progress)?;
    while let Some(rec) = h.split_last() {
        if let Err(e) = place_split(&h, rec.vt, rec.vs, &mesh.pos, &mut sphere) {
            // No valid position (the kernel of vt's star is empty or too thin to hit): undo the
            // split, widen the triangles around vs by kernel-centred moves over a growing
            // neighbourhood, and split again.
            let mut placed = false;
            for radius in 1..=4 {
                h.redo(&rec);
                smooth_around(&h, rec.vs, radius, 2 + radius, &mesh.pos, &mut sphere);
                h.split_last();
                if place_split(&h, rec.vt, rec.vs, &mesh.pos, &mut sphere).is_ok() {
                    placed = true;
                    break;
                }
            }
            if !placed {
                return Err(e);
            }
            rep.local_repairs += 1;
        }
        done += 1;
        if done % 2048 == 0 {
            progress.fraction(done as f64 / total.max(1) as f64)?;
        }
        if h.alive_vertices >= next_relax {
            let r = std::time::Instant::now();
            relax(&h, &mesh.pos, &mut sphere, s.relax_sweeps, progress)?;
            relax_ms += r.elapsed().as_secs_f64() * 1e3;
            next_relax = (h.alive_vertices as f64 * 1.3) as usize;
        }
    }
    let splits = lap(&mut t);
    rep.timings_ms.push(("vertex_splits".into(), ((splits - relax_ms) * 1e3).round() / 1e3));
    rep.timings_ms.push(("relax_during_splits".into(), (relax_ms * 1e3).round() / 1e3));
    relax(&h, &mesh.pos, &mut sphere, s.final_relax_sweeps, progress)?;
    rep.timings_ms.push(("final_relax".into(), lap(&mut t)));
    rep.foldovers = count_foldovers(&sphere, &mesh.tris);
    let (ad, sd) = distortion(&mesh.pos, &sphere, &mesh.tris);
    rep.angle_distortion = ad;
    rep.area_distortion = sd;
    Ok(SphereMap { sphere, report: rep })
}

/// Faces whose chord triangle is not strictly positive, decided exactly.
pub fn count_foldovers(sphere: &[Point3], tris: &[[u32; 3]]) -> usize {
    super::sphere_fallback::count_foldovers_exact(sphere, tris)
}

/// AD and SD of seed 002 eq. IV.64–IV.65 between the 3D mesh and its spherical chord triangles.
pub fn distortion(pos: &[Point3], sphere: &[Point3], tris: &[[u32; 3]]) -> (f64, f64) {
    let mut ad = 0.0;
    let (mut a3, mut a2) = (0.0, 0.0);
    let areas: Vec<(f64, f64)> = tris
        .iter()
        .map(|t| {
            let p = t.map(|v| pos[v as usize]);
            let q = t.map(|v| sphere[v as usize]);
            for k in 0..3 {
                let a = corner_angle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                let b = corner_angle(q[k], q[(k + 1) % 3], q[(k + 2) % 3]);
                ad += (a - b).abs();
            }
            let x = (triangle_area(p[0], p[1], p[2]), triangle_area(q[0], q[1], q[2]));
            a3 += x.0;
            a2 += x.1;
            x
        })
        .collect();
    let sd = areas.iter().map(|&(x, y)| (x / a3.max(1e-300) - y / a2.max(1e-300)).abs()).sum();
    (ad / (3.0 * tris.len().max(1) as f64), sd)
}

/// Curvature-driven flattening of a small closed mesh until it is star-shaped about its centre.
/// Outer Err: cancelled; inner Err: the reason flattening failed.
#[allow(clippy::type_complexity)]
fn flatten_to_star(
    pos0: &[Point3],
    tris: &[[u32; 3]],
    max_rounds: usize,
    progress: &Progress,
) -> Result<std::result::Result<(Vec<Point3>, usize), String>> {
    let n = pos0.len();
    let mut p = pos0.to_vec();
    let mut vf = vec![Vec::new(); n];
    for (fi, t) in tris.iter().enumerate() {
        for &v in t {
            vf[v as usize].push(fi as u32);
        }
    }
    let nbrs: Vec<Vec<u32>> = (0..n)
        .map(|v| {
            let mut w: Vec<u32> =
                vf[v].iter().flat_map(|&f| tris[f as usize]).filter(|&w| w as usize != v).collect();
            w.sort_unstable();
            w.dedup();
            w
        })
        .collect();
    let mut worst = usize::MAX;
    for round in 1..=max_rounds {
        progress.fraction(round as f64 / max_rounds as f64)?;
        // χ_s: average triangle area (eq. IV.62), refreshed each round as the shape shrinks.
        let chi = tris
            .iter()
            .map(|t| triangle_area(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]))
            .sum::<f64>()
            / tris.len() as f64;
        let ks = |p: &[Point3], v: usize| -> f64 {
            let mut ang = 0.0;
            let mut area = 0.0;
            for &f in &vf[v] {
                let t = tris[f as usize];
                let k = t.iter().position(|&x| x as usize == v).unwrap_or(0);
                let (a, b, c) = (p[v], p[t[(k + 1) % 3] as usize], p[t[(k + 2) % 3] as usize]);
                ang += corner_angle(a, b, c);
                area += triangle_area(a, b, c);
            }
            (2.0 * PI - ang) / (chi + area / 3.0)
        };
        let bbox = crate::geometry::Aabb::of(&p).map(|b| b.diagonal()).unwrap_or(1.0);
        let min_move = 1e-6 * bbox;
        let mut stamp = vec![0u32; n];
        let mut heap: BinaryHeap<(Key, u32, u32)> = BinaryHeap::new();
        for v in 0..n {
            heap.push((Key(ks(&p, v).abs()), v as u32, 0));
        }
        // A vertex whose move would be too small is dropped from the heap: its curvature and
        // target depend only on its neighbours, and when one of them moves it is queued again
        // with a new stamp. (Re-queuing every parked vertex after each move made a round
        // quadratic in the working size.)
        for _ in 0..5 * n {
            let mut moved = false;
            while let Some((_, v, st)) = heap.pop() {
                if stamp[v as usize] != st {
                    continue;
                }
                let v = v as usize;
                let bary = scale(
                    nbrs[v].iter().fold([0.0; 3], |s, &w| add(s, p[w as usize])),
                    1.0 / nbrs[v].len() as f64,
                );
                if norm(sub(bary, p[v])) <= min_move {
                    continue;
                }
                p[v] = bary;
                for &w in nbrs[v].iter().chain(std::iter::once(&(v as u32))) {
                    stamp[w as usize] += 1;
                    heap.push((Key(ks(&p, w as usize).abs()), w, stamp[w as usize]));
                }
                moved = true;
                break;
            }
            if !moved {
                break;
            }
        }
        // Normalise: centre at the vertex centroid, farthest vertex at radius 1; then the
        // visibility check (every face positively oriented about the centre).
        let c = scale(p.iter().fold([0.0; 3], |s, &q| add(s, q)), 1.0 / n as f64);
        let r = p.iter().map(|&q| norm(sub(q, c))).fold(0.0, f64::max).max(1e-300);
        for q in &mut p {
            *q = scale(sub(*q, c), 1.0 / r);
        }
        let sph: Vec<Point3> = p.iter().map(|&q| normalize(q)).collect();
        let bad = count_foldovers(&sph, tris);
        worst = worst.min(bad);
        if bad == 0 && sph.iter().all(|q| norm(*q) > 0.5) {
            return Ok(Ok((sph, round)));
        }
    }
    Ok(Err(if max_rounds == 0 {
        "no flattening asked for (max_flatten_rounds 0)".to_string()
    } else {
        format!(
            "curvature flattening did not reach a star shape in {max_rounds} rounds ({worst} faces still not visible from the centre)"
        )
    }))
}

/// Places the 4 vertices of a tetrahedron on a regular tetrahedron, positively oriented.
fn embed_tetrahedron(map: &[u32], tris: &[[u32; 3]], sphere: &mut [Point3]) -> Result<()> {
    if map.len() != 4 || tris.len() != 4 {
        return Err(Error::Internal(format!(
            "tetrahedron expected, got {} vertices {} faces",
            map.len(),
            tris.len()
        )));
    }
    let s = 1.0 / 3f64.sqrt();
    let mut corners = [[s, s, s], [s, -s, -s], [-s, s, -s], [-s, -s, s]];
    let t = tris[0];
    if orient(corners[t[0] as usize], corners[t[1] as usize], corners[t[2] as usize]) < 0.0 {
        corners.swap(0, 1);
    }
    for (k, &v) in map.iter().enumerate() {
        sphere[v as usize] = corners[k];
    }
    for t in tris {
        let q = t.map(|k| corners[k as usize]);
        if orient(q[0], q[1], q[2]) <= 0.0 {
            return Err(Error::Internal("tetrahedron faces inconsistently oriented".into()));
        }
    }
    Ok(())
}

/// Shape quality of a triangle: 4√3·area / Σ edge², 1 for equilateral, 0 for degenerate.
#[inline]
fn quality(a: Point3, b: Point3, c: Point3) -> f64 {
    let n = norm(cross(sub(b, a), sub(c, a)));
    let l = dot(sub(b, a), sub(b, a)) + dot(sub(c, b), sub(c, b)) + dot(sub(a, c), sub(a, c));
    if l <= 0.0 {
        0.0
    } else {
        2.0 * 3f64.sqrt() * n / l
    }
}

/// The faces of `v` as (a, b) pairs with (v, a, b) counter-clockwise.
fn ring_pairs(h: &Hierarchy, v: u32) -> Vec<(u32, u32)> {
    h.vf[v as usize]
        .iter()
        .map(|&f| {
            let t = h.tris[f as usize];
            let k = t.iter().position(|&x| x == v).unwrap_or(0);
            (t[(k + 1) % 3], t[(k + 2) % 3])
        })
        .collect()
}

/// Worst shape quality of the faces around `x` if valid (all positively oriented), else None.
#[inline]
fn star_quality(x: Point3, ring: &[(Point3, Point3, Point3)]) -> Option<f64> {
    let mut q = f64::INFINITY;
    for &(a, b, n) in ring {
        if !(dot(x, n) > 0.0) {
            return None;
        }
        q = q.min(quality(x, a, b));
    }
    Some(q)
}

/// The stars of a vertex as (a, b, a×b) per face (v, a, b): the orientation test of a candidate
/// position x for every face is `dot(x, a×b) > 0`.
fn star(h: &Hierarchy, v: u32, sphere: &[Point3]) -> Vec<(Point3, Point3, Point3)> {
    ring_pairs(h, v)
        .iter()
        .map(|&(a, b)| {
            let (pa, pb) = (sphere[a as usize], sphere[b as usize]);
            (pa, pb, cross(pa, pb))
        })
        .collect()
}

/// Candidate positions inside the kernel of a star on the sphere (the region where every face
/// (x, a, b) is positively oriented), appended to `out`. The kernel is computed exactly as a
/// convex polygon: in the gnomonic (central) projection onto the plane tangent at the ring's
/// centre, great circles are straight lines, so each face contributes one half-plane and the
/// kernel is their intersection (clipping a large square, Sutherland–Hodgman). Candidates are
/// the polygon's area centroid and points from it towards `prefer` (the mean-value target).
/// Returns false when the ring does not fit in one hemisphere or the kernel is empty.
fn kernel_candidates(ring: &[(Point3, Point3, Point3)], prefer: Point3, out: &mut Vec<Point3>) -> bool {
    let c = normalize(ring.iter().fold([0.0; 3], |s, r| add(s, r.0)));
    if !ring.iter().all(|r| dot(r.0, c) > 0.05 && dot(r.1, c) > 0.05) {
        return false;
    }
    let e1 = normalize(if c[0].abs() < 0.9 { cross(c, [1.0, 0.0, 0.0]) } else { cross(c, [0.0, 1.0, 0.0]) });
    let e2 = cross(c, e1);
    const L: f64 = 25.0;
    let mut poly: Vec<[f64; 2]> = vec![[-L, -L], [L, -L], [L, L], [-L, L]];
    let mut next: Vec<[f64; 2]> = Vec::with_capacity(16);
    for r in ring {
        let len = norm(r.2);
        if !(len > 0.0) {
            return false;
        }
        let h = [dot(r.2, c) / len, dot(r.2, e1) / len, dot(r.2, e2) / len];
        let f = |p: [f64; 2]| h[0] + h[1] * p[0] + h[2] * p[1];
        next.clear();
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let (fp, fq) = (f(p), f(q));
            if fp >= 0.0 {
                next.push(p);
            }
            if (fp >= 0.0) != (fq >= 0.0) {
                let t = fp / (fp - fq);
                next.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
        std::mem::swap(&mut poly, &mut next);
        if poly.len() < 3 {
            return false;
        }
    }
    // Area centroid (shoelace).
    let (mut a2, mut gx, mut gy) = (0.0, 0.0, 0.0);
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let w = p[0] * q[1] - q[0] * p[1];
        a2 += w;
        gx += (p[0] + q[0]) * w;
        gy += (p[1] + q[1]) * w;
    }
    if !(a2 > 0.0) {
        return false;
    }
    let g = [gx / (3.0 * a2), gy / (3.0 * a2)];
    let lift = |p: [f64; 2]| normalize(add(c, add(scale(e1, p[0]), scale(e2, p[1]))));
    out.push(lift(g));
    let dc = dot(prefer, c);
    if dc > 0.05 {
        let pp = [dot(prefer, e1) / dc, dot(prefer, e2) / dc];
        for t in [0.25, 0.5, 0.75] {
            out.push(lift([g[0] + t * (pp[0] - g[0]), g[1] + t * (pp[1] - g[1])]));
        }
    }
    true
}

/// Moves `v` to the best of its mean-value target and its kernel candidates (best = highest
/// worst-face shape quality) when that beats its current position.
fn improve_vertex_kernel(h: &Hierarchy, v: u32, pos: &[Point3], sphere: &mut [Point3]) {
    let ring = star(h, v, sphere);
    let cur = star_quality(sphere[v as usize], &ring).unwrap_or(-1.0);
    let target = mvc_target(h, v, pos, sphere);
    let mut cands = vec![target];
    kernel_candidates(&ring, target, &mut cands);
    let mut best = (cur, sphere[v as usize]);
    for x in cands {
        if let Some(q) = star_quality(x, &ring) {
            if q > best.0 {
                best = (q, x);
            }
        }
    }
    sphere[v as usize] = best.1;
}

/// Gauss–Seidel sweeps of [`improve_vertex_kernel`] over the `radius`-ring of `v`: widens the thin
/// spherical triangles around a vertex before a split there is retried.
fn smooth_around(h: &Hierarchy, v: u32, radius: usize, sweeps: usize, pos: &[Point3], sphere: &mut [Point3]) {
    let mut set = vec![v];
    let mut frontier = vec![v];
    for _ in 0..radius {
        let mut nf = Vec::new();
        for &u in &frontier {
            for w in h.neighbours(u).iter().copied() {
                if !set.contains(&w) {
                    set.push(w);
                    nf.push(w);
                }
            }
        }
        frontier = nf;
    }
    for _ in 0..sweeps {
        // Outside in: the outer vertices make room first.
        for &u in set.iter().rev() {
            improve_vertex_kernel(h, u, pos, sphere);
        }
    }
}

/// Places the vertex `vt` just re-inserted by the split of `vs`.
fn place_split(h: &Hierarchy, vt: u32, vs: u32, pos: &[Point3], sphere: &mut [Point3]) -> Result<()> {
    let pairs = ring_pairs(h, vt);
    let ring: Vec<(Point3, Point3, Point3)> = pairs
        .iter()
        .map(|&(a, b)| {
            let (pa, pb) = (sphere[a as usize], sphere[b as usize]);
            (pa, pb, cross(pa, pb))
        })
        .collect();
    let mut best: Option<(f64, Point3)> = None;
    let consider = |best: &mut Option<(f64, Point3)>, x: Point3| {
        if let Some(q) = star_quality(x, &ring) {
            if best.is_none_or(|(bq, _)| q > bq) {
                *best = Some((q, x));
            }
        }
    };
    // The mean-value target first (it usually wins and lowers distortion), then points of the
    // exact kernel of vt's star; only when the kernel cannot be computed (a ring wider than a
    // hemisphere, near the tetrahedron) the lattice over the fan around vs that covered vt's
    // region before the split, then points ever closer to vs.
    let target = mvc_target(h, vt, pos, sphere);
    consider(&mut best, target);
    let mut cands = Vec::with_capacity(4);
    let ps = sphere[vs as usize];
    if kernel_candidates(&ring, target, &mut cands) {
        for x in cands {
            consider(&mut best, x);
        }
    } else {
        for &(a, b) in &pairs {
            if a == vs || b == vs {
                continue;
            }
            let (pa, pb) = (sphere[a as usize], sphere[b as usize]);
            const L: usize = 4;
            for i in 1..=L {
                for j in 0..=(L - i) {
                    let k = L - i - j;
                    let x = add(add(scale(ps, i as f64), scale(pa, j as f64)), scale(pb, k as f64));
                    consider(&mut best, normalize(x));
                }
            }
        }
    }
    // Last resort: every direction around vs at shrinking distances (the valid wedge at vs can be
    // narrow and lie across a thin fan triangle).
    let mut eps = 0.25;
    let e1 =
        normalize(if ps[0].abs() < 0.9 { cross(ps, [1.0, 0.0, 0.0]) } else { cross(ps, [0.0, 1.0, 0.0]) });
    let e2 = cross(ps, e1);
    while best.is_none() && eps > 1e-13 {
        for d in 0..256 {
            let th = d as f64 * (2.0 * PI / 256.0);
            consider(
                &mut best,
                normalize(add(ps, add(scale(e1, eps * th.cos()), scale(e2, eps * th.sin())))),
            );
        }
        eps *= 0.25;
    }
    let mut eps = 0.25;
    while best.is_none() && eps > 1e-12 {
        for &(a, b) in &pairs {
            if a == vs || b == vs {
                continue;
            }
            // Several directions across the fan triangle: the valid wedge at vs may be narrow.
            for w in 1..16 {
                let w = w as f64 / 16.0;
                let m = add(scale(sphere[a as usize], w), scale(sphere[b as usize], 1.0 - w));
                consider(&mut best, normalize(add(scale(ps, 1.0 - eps), scale(m, eps))));
            }
        }
        for &(a, b) in &pairs {
            let other = if a == vs {
                b
            } else if b == vs {
                a
            } else {
                continue;
            };
            consider(&mut best, normalize(add(scale(ps, 1.0 - eps), scale(sphere[other as usize], eps))));
        }
        eps *= 0.25;
    }
    match best {
        Some((_, x)) => {
            sphere[vt as usize] = x;
            // The split shrank vs's star: let vs move to its ring's centroid if that improves its
            // worst triangle (keeps 180° corners from building up).
            improve_vertex_kernel(h, vs, pos, sphere);
            Ok(())
        }
        None => {
            Err(Error::numerical("parameterise", format!("no valid position found to re-insert vertex {vt}")))
        }
    }
}

/// tan(θ/2) of the corner at `p` of the 3D triangle (p, a, b), divided by |a − p| and |b − p|:
/// the two mean-value weight contributions of that face (Floater). tan(θ/2) = |u×v| / (|u||v| + u·v)
/// needs no trigonometry (this is the inner loop of every relaxation sweep).
#[inline]
fn mvc_face_weights(p: Point3, a: Point3, b: Point3) -> (f64, f64) {
    let (u, v) = (sub(a, p), sub(b, p));
    let (la, lb) = (norm(u).max(1e-300), norm(v).max(1e-300));
    let th = norm(cross(u, v)) / (la * lb + dot(u, v)).max(1e-300);
    (th / la, th / lb)
}

/// normalize(Σ wᵢⱼ s_j) with Floater's mean-value weights from the 3D mesh.
fn mvc_target(h: &Hierarchy, v: u32, pos: &[Point3], sphere: &[Point3]) -> Point3 {
    let pv = pos[v as usize];
    let mut acc = [0.0; 3];
    for &f in &h.vf[v as usize] {
        let t = h.tris[f as usize];
        let k = t.iter().position(|&x| x == v).unwrap_or(0);
        let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
        let (wa, wb) = mvc_face_weights(pv, pos[a as usize], pos[b as usize]);
        acc = add(acc, scale(sphere[a as usize], wa));
        acc = add(acc, scale(sphere[b as usize], wb));
    }
    normalize(acc)
}

/// The alive vertices' stars in flat arrays (one relaxation call reuses them every sweep): for
/// vertex slot i, `ring[start[i]..start[i+1]]` are its faces as (a, b) with (v, a, b)
/// counter-clockwise and the mean-value weights of a and b.
struct Stars {
    verts: Vec<u32>,
    start: Vec<u32>,
    ring: Vec<(u32, u32, f64, f64)>,
}

impl Stars {
    fn new(h: &Hierarchy, pos: &[Point3]) -> Stars {
        let mut st = Stars { verts: Vec::new(), start: vec![0], ring: Vec::new() };
        for v in 0..h.vertex_alive.len() {
            if !h.vertex_alive[v] {
                continue;
            }
            let pv = pos[v];
            for &f in &h.vf[v] {
                let t = h.tris[f as usize];
                let k = t.iter().position(|&x| x as usize == v).unwrap_or(0);
                let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
                let (wa, wb) = mvc_face_weights(pv, pos[a as usize], pos[b as usize]);
                st.ring.push((a, b, wa, wb));
            }
            st.verts.push(v as u32);
            st.start.push(st.ring.len() as u32);
        }
        st
    }
}

/// Gauss–Seidel sweeps moving each alive vertex towards its mean-value target, only by moves
/// that keep every incident face positively oriented (halving the step up to 4 times).
pub(crate) fn relax(
    h: &Hierarchy,
    pos: &[Point3],
    sphere: &mut [Point3],
    sweeps: usize,
    progress: &Progress,
) -> Result<()> {
    if sweeps == 0 {
        return Ok(());
    }
    let stars = Stars::new(h, pos);
    let mut ring: Vec<(Point3, Point3, Point3)> = Vec::with_capacity(32);
    for _ in 0..sweeps {
        progress.check()?;
        for (i, &v) in stars.verts.iter().enumerate() {
            let star = &stars.ring[stars.start[i] as usize..stars.start[i + 1] as usize];
            let mut acc = [0.0; 3];
            ring.clear();
            for &(a, b, wa, wb) in star {
                let (pa, pb) = (sphere[a as usize], sphere[b as usize]);
                acc = add(acc, add(scale(pa, wa), scale(pb, wb)));
                ring.push((pa, pb, cross(pa, pb)));
            }
            let target = normalize(acc);
            let cur = sphere[v as usize];
            let mut x = target;
            for _ in 0..5 {
                if star_quality(x, &ring).is_some_and(|q| q > 1e-3) {
                    sphere[v as usize] = x;
                    break;
                }
                x = normalize(add(cur, x));
            }
        }
    }
    Ok(())
}
