//! Sliver clean-up after re-triangulation: inserting curve points and turning segments into
//! edges leaves needles (a very short edge) and caps (an angle near 180°, typically a vertex
//! lying almost on a curve edge). Smoothing cannot fix them (curve vertices are fixed and a
//! tangential step only moves one free corner), so they are removed by local connectivity edits:
//!
//! 1. **Edge flips** first (they keep the face and vertex count): for a bad face, the flip of one
//!    of its edges that most raises the smaller of the two faces' smallest angles.
//! 2. **Half-edge collapses** where no flip helps: a free vertex `y` is merged into a neighbour
//!    `x` that stays where it is (so no position, curve vertex or UV changes; `y` disappears).
//!
//! Every edit is checked before it is made:
//! - curve edges are never flipped and curve (and boundary) vertices never removed;
//! - both faces of a flipped edge, and all faces of a removed vertex, carry the same label (the
//!   caller's region × template group), so regions are never merged and groups never mixed;
//! - no resulting face is degenerate or turned against its reference ([`Reference::face`]: in
//!   the fit, still the fine surface's vertex normals, see [`super::reference`]), or against the
//!   face it replaces;
//! - the edit strictly raises the worst smallest angle among the faces it changes (so the
//!   process terminates) and keeps the shape: a flip sweeps a small volume relative to the two
//!   faces, and a removed vertex lies close to the faces that replace its star;
//! - a collapse keeps the mesh manifold (link condition: x and y share exactly the two
//!   neighbours opposite their edge).

use rayon::prelude::*;
use serde::Serialize;

use crate::error::Result;
use crate::geometry::{add, cross, dot, norm, norm2, sub, triangle_cross};
use crate::job::Progress;
use crate::mesh::Point3;

use super::reference::Reference;
use super::smooth::min_angle_quality;
use super::trimesh::{IntMap, TriMesh};

pub use super::trimesh::EdgeSet;

/// Largest swept volume of a flip, relative to (area of the two faces)^1.5: 0.05 allows
/// a dihedral angle up to about 19° between two equilateral faces (any flip touching a sliver,
/// whose own area is tiny, passes).
const FLIP_VOLUME_TOLERANCE: f64 = 0.05;
/// Largest distance of a removed vertex from the faces replacing its star, relative to the mean
/// length of its edges.
const COLLAPSE_DISTANCE_TOLERANCE: f64 = 0.1;
/// A thin face is the template's own (inherited) unless it is this much thinner (in sin² of the
/// smallest angle, about half the angle) than the thinnest template face at its corners. A
/// template vertex is collapsed only when a face of its star is thinner than that (the fit's
/// doing): without this a template made of needles (a UV sphere's rings, a CAD fan) was
/// decimated 8× (5,120 faces to 640) by collapses that each "improved" a needle. Flips, which keep
/// the face count, still treat every thin face.
const INHERITED_QUALITY_FRACTION: f64 = 0.25;

#[derive(Debug, Clone, Copy)]
pub struct CleanupSettings {
    /// Faces with a smallest angle below this (degrees) are treated.
    pub min_angle_deg: f64,
    /// Passes over the bad faces (each pass treats every bad face once).
    pub max_passes: u32,
}

#[derive(Debug, Clone, Default, Serialize)]
pub struct CleanupStats {
    pub flips: usize,
    pub collapses: usize,
    pub passes: u32,
    /// Faces below the angle threshold before and after.
    pub bad_faces_before: usize,
    pub bad_faces_after: usize,
    /// Of `bad_faces_before`, those the template's own faces at their corners are about as thin
    /// as (less than 4× thinner in sin² of the smallest angle): the template's design, which
    /// flips may improve but collapses of template vertices do not remove.
    pub inherited_thin_faces: usize,
    pub min_angle_deg_before: f64,
    pub min_angle_deg_after: f64,
    /// For the faces left below the threshold: why their edges could not be flipped and their
    /// ends not removed (one count per edge / per end and reason).
    pub blocked_flips: std::collections::BTreeMap<&'static str, usize>,
    pub blocked_collapses: std::collections::BTreeMap<&'static str, usize>,
    /// Vertices removed by collapses (no live face uses them any more), numbered as before the
    /// clean-up (template vertices, then the vertices the fine stage added).
    pub removed_vertices: Vec<u32>,
}

/// The constraints of the clean-up.
pub struct Constraints<'a> {
    /// Vertices that must not move or disappear (curve vertices, boundary vertices), except
    /// those in `chain`.
    pub fixed: &'a [bool],
    /// Curve edges (min, max): never flipped. Updated when a chain vertex is removed.
    pub locked: EdgeSet,
    /// Chain vertices that are not curve points (mesh vertices the re-triangulation snapped or
    /// pulled onto a segment) → their two chain neighbours. Such a vertex may be removed into a
    /// chain neighbour: the three are on one segment, so the chain stays a chain of edges on it.
    pub chain: IntMap<u32, [u32; 2]>,
    /// What each face should face (the fit passes the fine surface's vertex normals).
    pub reference: &'a dyn Reference,
    /// Per template vertex, the quality (sin² of the smallest angle) of the thinnest template
    /// face at it ([`template_floor`]); vertices past its end (added by the fit) have none.
    pub template_floor: &'a [f64],
}

/// Per vertex of a template, the quality (sin² of the smallest angle) of its thinnest face
/// (1 for a vertex in no face).
pub fn template_floor(pos: &[Point3], tris: &[[u32; 3]]) -> Vec<f64> {
    let mut floor = vec![1.0f64; pos.len()];
    for t in tris {
        let q = min_angle_quality(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
        for &v in t {
            if let Some(f) = floor.get_mut(v as usize) {
                *f = f.min(q);
            }
        }
    }
    floor
}

/// The quality below which face `t` is the fit's doing: `q_bad`, or less where the template's own
/// faces at its corners are thin (the minimum over its template corners; none for a face of
/// vertices the fit added).
fn threshold(c: &Constraints, t: [u32; 3], q_bad: f64) -> f64 {
    let inherited =
        t.iter().filter_map(|&v| c.template_floor.get(v as usize)).fold(f64::INFINITY, |a, &b| a.min(b));
    q_bad.min(INHERITED_QUALITY_FRACTION * inherited)
}

impl<'a> Constraints<'a> {
    /// Removable chain vertices of `chains` (vertex chains of the segments): inner vertices that
    /// are not curve points (`curve_point[v]` false) and not fixed for another reason
    /// (`boundary[v]`); a vertex found in two chains is kept fixed.
    pub fn chain_vertices(
        chains: &[Vec<u32>],
        curve_point: &[bool],
        boundary: &[bool],
    ) -> IntMap<u32, [u32; 2]> {
        let mut out: IntMap<u32, [u32; 2]> = IntMap::default();
        let mut twice: Vec<u32> = Vec::new();
        for c in chains {
            for k in 1..c.len().saturating_sub(1) {
                let v = c[k];
                if curve_point[v as usize] || boundary[v as usize] {
                    continue;
                }
                if out.insert(v, [c[k - 1], c[k + 1]]).is_some() {
                    twice.push(v);
                }
            }
        }
        for v in twice {
            out.remove(&v);
        }
        out
    }
}

fn face_q(mesh: &TriMesh, t: [u32; 3]) -> f64 {
    min_angle_quality(mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize])
}

fn tri_normal(mesh: &TriMesh, t: [u32; 3]) -> Point3 {
    triangle_cross(mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize])
}

/// A face would be acceptable: not degenerate, and facing the way the surface does.
fn well_oriented(mesh: &TriMesh, c: &Constraints, t: [u32; 3]) -> bool {
    let n = tri_normal(mesh, t);
    norm2(n) > 0.0 && dot(n, c.reference.face(t)) > 0.0
}

fn min_angle_deg(q: f64) -> f64 {
    q.clamp(0.0, 1.0).sqrt().asin().to_degrees()
}

/// Removes slivers from `mesh`. `labels[f]` is the label of face id `f` (grown for new faces).
pub fn clean(
    mesh: &mut TriMesh,
    labels: &mut Vec<u64>,
    c: &mut Constraints,
    s: &CleanupSettings,
    progress: &Progress,
) -> Result<CleanupStats> {
    let q_bad = s.min_angle_deg.to_radians().sin().powi(2);
    let mut stats = CleanupStats::default();
    let (n_bad, qmin) = census(mesh, q_bad, progress)?;
    stats.bad_faces_before = n_bad;
    let cr: &Constraints = c;
    stats.inherited_thin_faces = scan_faces(mesh, progress, |f| {
        let t = mesh.tris[f as usize];
        let q = face_q(mesh, t);
        (q < q_bad && q >= threshold(cr, t, q_bad)).then_some(())
    })?
    .len();
    stats.min_angle_deg_before = min_angle_deg(qmin);
    let mut removed = vec![false; mesh.pos.len()];
    for pass in 0..s.max_passes {
        let mut bad: Vec<(f64, u32)> = scan_faces(mesh, progress, |f| {
            let q = face_q(mesh, mesh.tris[f as usize]);
            (q < q_bad).then_some((q, f))
        })?;
        if bad.is_empty() {
            break;
        }
        stats.passes = pass + 1;
        bad.sort_by(|a, b| a.0.total_cmp(&b.0)); // worst first
        let mut changed = false;
        for (i, &(_, f)) in bad.iter().enumerate() {
            progress.check_every(i, POLL_BAD_FACES)?;
            if !mesh.alive[f as usize] || face_q(mesh, mesh.tris[f as usize]) >= q_bad {
                continue;
            }
            if let Some((a, b)) = best_flip(mesh, labels, c, f) {
                flip(mesh, labels, a, b);
                stats.flips += 1;
                changed = true;
            } else if let Some((x, y)) = best_collapse(mesh, labels, c, f, q_bad) {
                if collapse(mesh, labels, x, y) {
                    follow_chain(c, x, y);
                    removed[y as usize] = true;
                    stats.collapses += 1;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let (n_bad, qmin) = census(mesh, q_bad, progress)?;
    for f in 0..mesh.tris.len() as u32 {
        progress.check_every(f as usize, POLL_FACES)?;
        let t = mesh.tris[f as usize];
        if !mesh.alive[f as usize] || face_q(mesh, t) >= q_bad {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if let Err(r) = flip_gain(mesh, labels, c, a, b) {
                *stats.blocked_flips.entry(r).or_default() += 1;
            }
            for (x, y) in [(a, b), (b, a)] {
                if let Err(r) = collapse_gain(mesh, labels, c, x, y, q_bad) {
                    *stats.blocked_collapses.entry(r).or_default() += 1;
                }
            }
        }
    }
    stats.bad_faces_after = n_bad;
    stats.min_angle_deg_after = min_angle_deg(qmin);
    stats.removed_vertices = (0..removed.len() as u32).filter(|&v| removed[v as usize]).collect();
    Ok(stats)
}

/// Face ids scanned between two polls: ~2–4 ms of work in release on the headline's 200k faces
/// (the stage polled once per pass before: 100 ms of CPU between two polls at load 7, session 10).
const POLL_FACES: usize = 16_384;

/// Faces below the threshold tried (a flip or a collapse each) between two polls.
const POLL_BAD_FACES: usize = 256;

/// `visit` of every live face id, the `Some`s in face order: [`POLL_FACES`] ids at a time, polling
/// before each block, the ids of a block in parallel (the stage's ~12 scans of the headline's 200k
/// faces were ~45 ms of serial CPU).
fn scan_faces<T: Send>(
    mesh: &TriMesh,
    progress: &Progress,
    visit: impl Fn(u32) -> Option<T> + Sync,
) -> Result<Vec<T>> {
    let mut out = Vec::new();
    for start in (0..mesh.tris.len()).step_by(POLL_FACES) {
        progress.check()?;
        let end = (start + POLL_FACES).min(mesh.tris.len());
        let block: Vec<T> = (start..end)
            .into_par_iter()
            .with_min_len(1024)
            .filter(|&f| mesh.alive[f])
            .filter_map(|f| visit(f as u32))
            .collect();
        out.extend(block);
    }
    Ok(out)
}

/// (faces below the threshold, worst quality).
fn census(mesh: &TriMesh, q_bad: f64, progress: &Progress) -> Result<(usize, f64)> {
    let q = scan_faces(mesh, progress, |f| Some(face_q(mesh, mesh.tris[f as usize])))?;
    let n = q.iter().filter(|&&q| q < q_bad).count();
    let qmin = q.iter().copied().fold(f64::INFINITY, f64::min);
    Ok((n, if qmin.is_finite() { qmin } else { 1.0 }))
}

/// The two faces of edge (a, b) as ([a, b, c], [b, a, d]) with their third vertices, when the
/// edge is interior.
fn edge_faces(mesh: &TriMesh, a: u32, b: u32) -> Option<(u32, u32, u32, u32)> {
    let f = mesh.face_with_edge(a, b)?;
    let g = mesh.face_with_edge(b, a)?;
    let third = |f: u32| mesh.tris[f as usize].iter().copied().find(|&v| v != a && v != b);
    Some((f, g, third(f)?, third(g)?))
}

/// The quality after flipping edge (a, b) (`a → b` in face [a, b, c]), if the flip is allowed
/// and improves the worse of the two faces.
fn flip_gain(
    mesh: &TriMesh,
    labels: &[u64],
    c: &Constraints,
    a: u32,
    b: u32,
) -> std::result::Result<f64, &'static str> {
    if c.locked.contains(&(a.min(b), a.max(b))) {
        return Err("curve_edge");
    }
    let (f, g, x, y) = edge_faces(mesh, a, b).ok_or("boundary")?;
    if labels[f as usize] != labels[g as usize] {
        return Err("label");
    }
    if x == y || mesh.has_edge(x, y) {
        return Err("topology");
    }
    let (t1, t2) = ([a, y, x], [y, b, x]);
    if !well_oriented(mesh, c, t1) || !well_oriented(mesh, c, t2) {
        return Err("orientation");
    }
    let (n1, n2) = (tri_normal(mesh, t1), tri_normal(mesh, t2));
    let old_n = add(mesh.face_normal(f), mesh.face_normal(g));
    if dot(n1, n2) <= 0.0 || dot(n1, old_n) <= 0.0 || dot(n2, old_n) <= 0.0 {
        return Err("not_convex"); // the new faces would fold over each other
    }
    // Shape: the volume of the tetrahedron (a, b, x, y) is what the flip sweeps.
    let p = |v: u32| mesh.pos[v as usize];
    let vol = dot(cross(sub(p(b), p(a)), sub(p(x), p(a))), sub(p(y), p(a))).abs() / 6.0;
    let area = 0.5 * (norm(n1) + norm(n2));
    if vol > FLIP_VOLUME_TOLERANCE * area * area.sqrt() {
        return Err("shape");
    }
    let before = face_q(mesh, mesh.tris[f as usize]).min(face_q(mesh, mesh.tris[g as usize]));
    let after = face_q(mesh, t1).min(face_q(mesh, t2));
    if after > before {
        Ok(after)
    } else {
        Err("no_gain")
    }
}

/// The best improving flip among the edges of face `f`.
fn best_flip(mesh: &TriMesh, labels: &[u64], c: &Constraints, f: u32) -> Option<(u32, u32)> {
    let t = mesh.tris[f as usize];
    let mut best: Option<((u32, u32), f64)> = None;
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        if let Ok(q) = flip_gain(mesh, labels, c, a, b) {
            if best.is_none_or(|x| q > x.1) {
                best = Some(((a, b), q));
            }
        }
    }
    best.map(|x| x.0)
}

fn flip(mesh: &mut TriMesh, labels: &mut Vec<u64>, a: u32, b: u32) {
    let Some((f, g, x, y)) = edge_faces(mesh, a, b) else { return };
    let label = labels[f as usize];
    mesh.remove_face(f);
    mesh.remove_face(g);
    for t in [[a, y, x], [y, b, x]] {
        // Cannot fail: the checks ensured x–y is not an edge, and the other four edges were freed.
        if mesh.add_face(t).is_ok() {
            labels.push(label);
        }
    }
}

/// Distinct neighbours of `v`.
fn neighbours(mesh: &TriMesh, v: u32) -> Vec<u32> {
    let mut out = Vec::with_capacity(8);
    for &f in mesh.faces_of(v) {
        for &w in &mesh.tris[f as usize] {
            if w != v && !out.contains(&w) {
                out.push(w);
            }
        }
    }
    out
}

/// The worst quality after removing `y` into `x`, if the collapse is allowed and improves the
/// worst face of y's star.
fn collapse_gain(
    mesh: &TriMesh,
    labels: &[u64],
    c: &Constraints,
    x: u32,
    y: u32,
    q_bad: f64,
) -> std::result::Result<f64, &'static str> {
    let on_chain = c.chain.get(&y);
    match on_chain {
        Some(nb) if !nb.contains(&x) => return Err("off_chain"),
        None if c.fixed[y as usize] => return Err("fixed"),
        _ => {}
    }
    let (_, _, p, q) = edge_faces(mesh, x, y).ok_or("boundary")?;
    let star = mesh.faces_of(y);
    // A template vertex goes only to repair a face the fit made thin (below its own threshold),
    // not for the template's own thin faces: once a collapse has widened a needle, its
    // neighbours would otherwise follow one by one (a decimation of the template).
    let made_thin = |f: &u32| {
        let t = mesh.tris[*f as usize];
        face_q(mesh, t) < threshold(c, t, q_bad)
    };
    if (y as usize) < c.template_floor.len() && !star.iter().any(made_thin) {
        return Err("inherited");
    }
    // A free vertex lies inside one region (and template group); a chain vertex separates two,
    // and each face keeps its own label.
    let label = labels[star[0] as usize];
    if on_chain.is_none() && star.iter().any(|&f| labels[f as usize] != label) {
        return Err("label");
    }
    // Link condition.
    let (nx, ny) = (neighbours(mesh, x), neighbours(mesh, y));
    if ny.iter().filter(|w| nx.contains(w)).any(|&w| w != p && w != q) || ny.len() < 3 || nx.len() < 3 {
        return Err("topology");
    }
    let mut worst_before = f64::INFINITY;
    let mut worst_after = f64::INFINITY;
    let mut closest = f64::INFINITY;
    let py = mesh.pos[y as usize];
    for &f in star {
        let t = mesh.tris[f as usize];
        worst_before = worst_before.min(face_q(mesh, t));
        if t.contains(&x) {
            continue; // one of the two faces that disappear
        }
        let nt = t.map(|v| if v == y { x } else { v });
        if !well_oriented(mesh, c, nt) || dot(tri_normal(mesh, nt), mesh.face_normal(f)) <= 0.0 {
            return Err("orientation");
        }
        // A new face must not already exist the other way round (a fold through the link).
        if mesh.face_with_edge(nt[1], nt[0]).is_some_and(|g| mesh.tris[g as usize].contains(&nt[2])) {
            return Err("topology");
        }
        worst_after = worst_after.min(face_q(mesh, nt));
        let tp = [mesh.pos[nt[0] as usize], mesh.pos[nt[1] as usize], mesh.pos[nt[2] as usize]];
        closest = closest.min(crate::geometry::dist(py, crate::spatial::closest_on_triangle(py, &tp)));
    }
    let mean_edge = ny.iter().map(|&w| mesh.len(y, w)).sum::<f64>() / ny.len() as f64;
    if closest > COLLAPSE_DISTANCE_TOLERANCE * mean_edge {
        return Err("shape");
    }
    if worst_after > worst_before && worst_after.is_finite() {
        Ok(worst_after)
    } else {
        Err("no_gain")
    }
}

/// The best improving collapse of an edge of face `f` (removing either end).
fn best_collapse(mesh: &TriMesh, labels: &[u64], c: &Constraints, f: u32, q_bad: f64) -> Option<(u32, u32)> {
    let t = mesh.tris[f as usize];
    let mut best: Option<((u32, u32), f64)> = None;
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        for (x, y) in [(a, b), (b, a)] {
            if let Ok(q) = collapse_gain(mesh, labels, c, x, y, q_bad) {
                if best.is_none_or(|z| q > z.1) {
                    best = Some(((x, y), q));
                }
            }
        }
    }
    best.map(|z| z.0)
}

/// After removing chain vertex `y` into `x`: the chain edge y–w becomes x–w.
fn follow_chain(c: &mut Constraints, x: u32, y: u32) {
    let Some(nb) = c.chain.remove(&y) else { return };
    let w = if nb[0] == x { nb[1] } else { nb[0] };
    c.locked.remove(&(x.min(y), x.max(y)));
    c.locked.remove(&(y.min(w), y.max(w)));
    c.locked.insert((x.min(w), x.max(w)));
    for (v, other) in [(x, w), (w, x)] {
        if let Some(e) = c.chain.get_mut(&v) {
            for z in e.iter_mut() {
                if *z == y {
                    *z = other;
                }
            }
        }
    }
}

/// Removes `y` into `x` (x does not move); every face keeps its label. On a failed insertion
/// the star is restored.
fn collapse(mesh: &mut TriMesh, labels: &mut Vec<u64>, x: u32, y: u32) -> bool {
    let star: Vec<u32> = mesh.faces_of(y).to_vec();
    let old: Vec<([u32; 3], u64)> =
        star.iter().map(|&f| (mesh.tris[f as usize], labels[f as usize])).collect();
    for &f in &star {
        mesh.remove_face(f);
    }
    let mut added = Vec::new();
    let mut ok = true;
    for &(t, label) in &old {
        if t.contains(&x) {
            continue;
        }
        match mesh.add_face(t.map(|v| if v == y { x } else { v })) {
            Ok(f) => {
                added.push(f);
                labels.push(label);
            }
            Err(()) => {
                ok = false;
                break;
            }
        }
    }
    if !ok {
        for f in added {
            mesh.remove_face(f);
        }
        for (t, label) in old {
            if mesh.add_face(t).is_ok() {
                labels.push(label);
            }
        }
    }
    ok
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constraints<'a>(fixed: &'a [bool], locked: &EdgeSet, n: &'a Vec<Point3>) -> Constraints<'a> {
        Constraints {
            fixed,
            locked: locked.clone(),
            chain: IntMap::default(),
            reference: n,
            template_floor: &[],
        }
    }

    #[test]
    fn the_clean_up_polls_per_16384_faces_of_each_scan_and_stops_at_a_cancel() {
        // An equilateral grid of 257 × 161 vertices: 81,920 faces, none thin. Five scans of all
        // faces (census, inherited-thin count, the first pass's thin faces, census after,
        // blocked-fix count), each polled at face ids 0, 16384, …, 65536: 5 × 5 = 25 polls (the
        // code before polled once per pass: 1).
        let grid = crate::shapes::triangle_grid(257, 161, 1.0);
        let tris = grid.faces.triangles();
        assert_eq!(tris.len(), 81_920);
        let n = vec![[0.0, 0.0, 1.0]; grid.positions.len()];
        let fixed = vec![false; grid.positions.len()];
        let locked = EdgeSet::default();
        let s = CleanupSettings { min_angle_deg: 20.0, max_passes: 8 };
        let run = |p: &Progress| {
            let mut mesh = TriMesh::new(grid.positions.clone(), tris.clone()).unwrap();
            let mut labels = vec![0u64; tris.len()];
            clean(&mut mesh, &mut labels, &mut constraints(&fixed, &locked, &n), &s, p)
        };
        let p = Progress::new();
        let st = run(&p).unwrap();
        assert_eq!((st.bad_faces_before, st.flips, st.collapses), (0, 0, 0));
        assert_eq!(p.checks(), 25);
        let p = Progress::new();
        p.cancel_at_check(12);
        assert!(matches!(run(&p), Err(crate::error::Error::Cancelled)));
        assert_eq!(p.checks(), 12, "stopped at the cancel, not after the scan");
    }

    #[test]
    fn a_cap_is_flipped_away_and_a_locked_edge_is_kept() {
        // Square a(0,0) b(1,0) c(1,1) d(0,1) split by the diagonal a–c, with an extra vertex e
        // very close to the diagonal's midpoint on the b side: faces (a,b,e), (b,c,e), (c,a,e)...
        // simpler: a quad a, b, c, d split by a–c where d sits almost on a–c: face (a, c, d) is a
        // cap; flipping a–c to b–d removes it.
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.45, 0.55, 0.0]];
        let tris = vec![[0, 1, 2], [0, 2, 3]];
        let n = vec![[0.0, 0.0, 1.0]; 4];
        let fixed = vec![true; 4];
        let mut mesh = TriMesh::new(pos.clone(), tris.clone()).unwrap();
        let mut labels = vec![0u64; 2];
        let locked = EdgeSet::default();
        let s = CleanupSettings { min_angle_deg: 10.0, max_passes: 4 };
        let st = clean(&mut mesh, &mut labels, &mut constraints(&fixed, &locked, &n), &s, &Progress::new())
            .unwrap();
        assert_eq!(st.flips, 1);
        assert!(mesh.has_edge(1, 3) && !mesh.has_edge(0, 2));
        // Same mesh with a–c a curve edge: nothing may change.
        let mut mesh = TriMesh::new(pos, tris).unwrap();
        let mut labels = vec![0u64; 2];
        let mut locked = EdgeSet::default();
        locked.insert((0, 2));
        let st = clean(&mut mesh, &mut labels, &mut constraints(&fixed, &locked, &n), &s, &Progress::new())
            .unwrap();
        assert_eq!((st.flips, st.collapses), (0, 0));
        assert!(mesh.has_edge(0, 2));
    }

    #[test]
    fn different_labels_block_a_flip() {
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.45, 0.55, 0.0]];
        let n = vec![[0.0, 0.0, 1.0]; 4];
        let fixed = vec![true; 4];
        let mut mesh = TriMesh::new(pos, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
        let mut labels = vec![0u64, 1];
        let locked = EdgeSet::default();
        let s = CleanupSettings { min_angle_deg: 10.0, max_passes: 4 };
        let st = clean(&mut mesh, &mut labels, &mut constraints(&fixed, &locked, &n), &s, &Progress::new())
            .unwrap();
        assert_eq!(st.flips, 0);
    }

    /// A template of needles (a UV sphere of 128 segments and 6 rings, smallest angles ≤ 5°), all
    /// vertices free: without a template floor the clean-up "improves" the needles by collapsing
    /// vertices (a decimation of the template); with the template's own floor no vertex goes.
    #[test]
    fn needles_of_the_template_itself_are_left_alone() {
        let sphere = crate::fit::testdata::needle_sphere(128, 6, 1.0);
        let tris = sphere.faces.triangles();
        let pos = sphere.positions.clone();
        let n: Vec<Point3> = pos.clone(); // unit sphere: the position is the normal
        let fixed = vec![false; pos.len()];
        let locked = EdgeSet::default();
        let s = CleanupSettings { min_angle_deg: 15.0, max_passes: 8 };
        let run = |floor: &[f64]| {
            let mut mesh = TriMesh::new(pos.clone(), tris.clone()).unwrap();
            let mut labels = vec![0u64; tris.len()];
            let mut c = constraints(&fixed, &locked, &n);
            c.template_floor = floor;
            let st = clean(&mut mesh, &mut labels, &mut c, &s, &Progress::new()).unwrap();
            (st, mesh.alive_faces().count())
        };
        let (st, faces) = run(&[]);
        assert!(st.collapses > 0 && faces < tris.len(), "{st:?}");
        let floor = template_floor(&pos, &tris);
        // Every face is a needle: each vertex's floor is below sin²(15°).
        assert!(floor.iter().all(|&f| f < 15f64.to_radians().sin().powi(2)), "{floor:?}");
        let (st, faces) = run(&floor);
        assert_eq!((st.collapses, faces), (0, tris.len()), "{st:?}");
        assert_eq!(st.inherited_thin_faces, tris.len());
    }
}
