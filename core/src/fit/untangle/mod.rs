//! Untangling folded faces: a face is *folded* when its normal opposes (or is perpendicular to,
//! within [`MIN_COS`]) its reference ([`Reference::face`]: in the fit, still the vertex normals
//! of the surface before the stage, not the report's carried reference, see
//! [`super::reference`]). Used three times: after the fine deformation (curve vertices fixed), after the
//! re-triangulation (chain vertices fixed, curve edges locked) and after smoothing.
//!
//! Fixes are local and only accepted when they leave no folded face among the faces they touch
//! and strictly reduce the folded count there:
//! 1. flip a non-curve edge of the folded face (its two faces become two others of the same quad);
//!    this is the only fix when all three corners are fixed curve vertices;
//! 2. move a free corner (or a free vertex one ring further out) to the mean of its ring, first
//!    tangentially (keeps the surface), then fully.
//!
//! Positions of fixed vertices never change, so curve vertices stay exact.

use serde::Serialize;

use crate::error::Result;
use crate::geometry::{add, dot, scale, sub, triangle_cross};
use crate::job::Progress;
use crate::mesh::Point3;

use super::reference::{Reference, SplitReference};
use super::trimesh::TriMesh;
use super::uvs::{self, UvMove};

mod energy;
pub(crate) mod flip_search;
mod folds;
mod kernel;
mod patch;
mod planar;
mod steep;

pub use folds::{fold_stats, folded_pair, FoldStats, FOLD_ANGLE_DEG};
pub(crate) use kernel::{kernel_centre, RingFrame};

/// A face counts as folded when its normal is within this cosine of perpendicular to the reference
/// (or beyond): a face standing on its edge, e.g. three consecutive vertices of one planar curve,
/// is as wrong as a flipped one and one round-off away from it.
pub(crate) const MIN_COS: f64 = 0.05;

pub use super::trimesh::EdgeSet;

#[derive(Debug, Clone, Default, Serialize)]
pub struct UntangleStats {
    pub folded_before: usize,
    pub edge_flips: usize,
    pub vertex_moves: usize,
    /// Folded regions untangled by moving all their free vertices at once ([`patch`]).
    pub patches_solved: usize,
    pub patch_vertex_moves: usize,
    /// Neighbourhoods of folds among fixed vertices replaced by a flip sequence
    /// ([`flip_search`]), and the flips in those sequences (not in `edge_flips`).
    pub flip_sequences: usize,
    pub sequence_flips: usize,
    pub folded_after: usize,
    /// Edges split to give a fold with fixed corners a free vertex ([`untangle_with_splits`]).
    pub edge_splits: usize,
    /// The vertices those splits added, in order (ids from the mesh's vertex count before the
    /// call): the two ends of the split edge with weight ½ each (third entry weight 0), for the
    /// caller's per-vertex arrays. Their UVs are also set by a move in `uv_batches`.
    #[serde(skip)]
    pub added: Vec<[(u32, f64); 3]>,
    /// Where the moved vertices went, as batches of simultaneous moves located on the mesh before
    /// each batch (in order): their UVs follow ([`uvs::apply_batches`]).
    #[serde(skip)]
    pub uv_batches: Vec<Vec<UvMove>>,
}

pub(crate) struct Ctx<'a> {
    reference: &'a dyn Reference,
    fixed: &'a [bool],
    locked: &'a EdgeSet,
}

impl Ctx<'_> {
    /// Cosine between triangle `t`'s normal (corner positions from `p`) and its reference; 0 for
    /// a degenerate triangle or reference.
    fn score(&self, t: [u32; 3], p: impl Fn(u32) -> Point3) -> f64 {
        self.score_against(t, self.reference.face(t), p)
    }
    /// [`Ctx::score`] of live face `f` (its reference looked up by id, [`Reference::face_of`]).
    fn score_face(&self, mesh: &TriMesh, f: u32, p: impl Fn(u32) -> Point3) -> f64 {
        self.score_against(mesh.tris[f as usize], self.reference.face_of(mesh, f), p)
    }
    fn score_against(&self, t: [u32; 3], r: Point3, p: impl Fn(u32) -> Point3) -> f64 {
        let n = triangle_cross(p(t[0]), p(t[1]), p(t[2]));
        let d = (dot(n, n) * dot(r, r)).sqrt();
        if d > 0.0 {
            dot(n, r) / d
        } else {
            0.0
        }
    }
    /// A unit normal at `v` for per-vertex algorithms ([`Reference::vertex`]).
    fn normal_at(&self, mesh: &TriMesh, v: u32) -> Point3 {
        self.reference.vertex(mesh, v)
    }
    /// Whether live face `f` is folded.
    fn folded(&self, mesh: &TriMesh, f: u32) -> bool {
        self.score_face(mesh, f, |v| mesh.pos[v as usize]) <= MIN_COS
    }
    fn locked(&self, a: u32, b: u32) -> bool {
        self.locked.contains(&(a.min(b), a.max(b)))
    }
}

/// Faces of `tris` turned against their reference: the normal at `pos` opposes
/// [`Reference::face`]. With vertex normals of the fine surface: the report's measure before
/// session 13 (`flipped_faces_against_fine_surface`); the carried reference is counted by
/// [`super::orientation::Orientation::faces_against`].
pub fn count_flipped(pos: &[Point3], tris: &[[u32; 3]], reference: &impl Reference) -> usize {
    tris.iter()
        .filter(|&&t| {
            let r = reference.face(t);
            dot(triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]), r) < 0.0
        })
        .count()
}

/// Untangles `mesh` in place. `reference`: what each face should face; `fixed`: vertices that
/// must not move (len ≥ mesh vertices); `locked`: undirected edges that must stay.
pub fn untangle(
    mesh: &mut TriMesh,
    reference: &impl Reference,
    fixed: &[bool],
    locked: &EdgeSet,
    max_passes: usize,
) -> UntangleStats {
    Progress::unpolled(|p| untangle_polled(mesh, reference, fixed, locked, max_passes, p))
}

/// Face ids scanned between two polls by the scans for folded faces: ~3–5 ms of work in release
/// on the headline's 200k faces (each scan of all faces, unpolled, was one of the fit's longest
/// stretches without a poll: `untangle_retriangulated` 436 ms of CPU at load 7, session 10).
const POLL_FACES: usize = 8192;

/// Folded faces tried (a flip or moves each) between two polls in a local pass, and folded
/// groups between two polls in a patch pass (a group's solve can take milliseconds).
const POLL_FOLDED: usize = 64;

/// [`untangle`], polling `progress` every [`POLL_FACES`] face ids of every scan for folded faces
/// (one before the local passes, one after each pass, one per patch round) and every
/// [`POLL_FOLDED`] folded faces tried or groups solved.
pub fn untangle_polled(
    mesh: &mut TriMesh,
    reference: &impl Reference,
    fixed: &[bool],
    locked: &EdgeSet,
    max_passes: usize,
    progress: &Progress,
) -> Result<UntangleStats> {
    let ctx = Ctx { reference, fixed, locked };
    let mut stats = UntangleStats::default();
    stats.folded_before = folded_faces(mesh, &ctx, progress)?.len();
    let mut left = local_passes(mesh, &ctx, &mut stats, max_passes, progress)?;
    // What one-vertex moves and flips leave: whole regions at once, then the local fixes again
    // (a region's new layout can open a flip that was blocked).
    for _ in 0..3 {
        if left == 0 {
            break;
        }
        let bad = folded_faces(mesh, &ctx, progress)?;
        let pass = patch::untangle_patches(mesh, &ctx, &bad, progress)?;
        if pass.patches_solved == 0 {
            break;
        }
        stats.patches_solved += pass.patches_solved;
        stats.patch_vertex_moves += pass.vertices_moved;
        stats.uv_batches.extend(pass.uv_batches);
        left = local_passes(mesh, &ctx, &mut stats, max_passes, progress)?;
    }
    // What moves cannot reach (folds among fixed vertices): flip sequences through worse
    // intermediate states, then the local fixes again around the new faces.
    for _ in 0..3 {
        if left == 0 {
            break;
        }
        let bad = folded_faces(mesh, &ctx, progress)?;
        let pass = flip_search::flip_sequences(mesh, &ctx, None, &bad, progress)?;
        if pass.regions == 0 {
            break;
        }
        stats.flip_sequences += pass.regions;
        stats.sequence_flips += pass.flips;
        left = local_passes(mesh, &ctx, &mut stats, max_passes, progress)?;
    }
    stats.folded_after = left;
    Ok(stats)
}

/// One pass of flip sequences ([`flip_search`]) over the faces `bad` that are turned against
/// `reference`, keeping only end states `guard` accepts (the last repair's: [`super::turned`]).
/// Returns what the pass did, including its planar re-triangulations ([`planar`]).
pub(crate) fn guarded_flip_sequences(
    mesh: &mut TriMesh,
    reference: &dyn Reference,
    fixed: &[bool],
    locked: &EdgeSet,
    bad: &[u32],
    guard: &flip_search::GuardFn<'_>,
    progress: &Progress,
) -> Result<flip_search::SearchPass> {
    let ctx = Ctx { reference, fixed, locked };
    flip_search::flip_sequences(mesh, &ctx, Some(guard), bad, progress)
}

/// Flips non-locked edges of faces standing steeply on the surface ([`steep`]); returns the flips.
pub fn flip_steep(
    mesh: &mut TriMesh,
    reference: &dyn Reference,
    locked: &EdgeSet,
    progress: &Progress,
) -> Result<usize> {
    let ctx = Ctx { reference, fixed: &[], locked };
    steep::flip_steep(mesh, &ctx, progress)
}

/// The live folded faces in id order, polling every [`POLL_FACES`] face ids.
fn folded_faces(mesh: &TriMesh, ctx: &Ctx, progress: &Progress) -> Result<Vec<u32>> {
    let mut out = Vec::new();
    for f in 0..mesh.tris.len() {
        progress.check_every(f, POLL_FACES)?;
        if mesh.alive[f] && ctx.folded(mesh, f as u32) {
            out.push(f as u32);
        }
    }
    Ok(out)
}

/// Rounds of edge splits [`untangle_with_splits`] tries after the flips, moves and patches.
const SPLIT_ROUNDS: usize = 3;

/// [`untangle`], then, while folds are left, splits a non-locked interior edge of every folded
/// face at its midpoint and untangles again. A face whose corners are all fixed (three curve
/// vertices around a sharp turn of a curve, where the face on one side of the curve has its third
/// corner on the other side) cannot be unfolded by moves, and by flips only when its free edge's
/// quad is convex; the split puts a free vertex on that edge, whose ring (the two faces' four
/// corners) is a quadrilateral: every simple quadrilateral has points that see all its sides,
/// where the four new faces are all turned the right way, and the moves and the patch solver
/// look for one. Vertices added are reported in `added` (the caller extends its per-vertex
/// arrays) and given to `reference` ([`SplitReference::push_midpoint`], which must cover
/// exactly the mesh's vertices on entry); split vertices are never fixed.
pub fn untangle_with_splits(
    mesh: &mut TriMesh,
    reference: &mut impl SplitReference,
    fixed: &[bool],
    locked: &EdgeSet,
    max_passes: usize,
    progress: &Progress,
) -> Result<UntangleStats> {
    if reference.vertex_count() != mesh.pos.len() {
        return Err(crate::error::Error::Internal(format!(
            "untangle: a reference for {} vertices, the mesh has {}",
            reference.vertex_count(),
            mesh.pos.len()
        )));
    }
    let mut stats = untangle_polled(mesh, reference, fixed, locked, max_passes, progress)?;
    if stats.folded_after == 0 {
        return Ok(stats);
    }
    let mut fixed = fixed[..mesh.pos.len()].to_vec();
    for _ in 0..SPLIT_ROUNDS {
        // Each round clones the mesh and untangles it again: on a 100k-vertex template that is
        // long enough for a cancel to be noticed between rounds.
        progress.check()?;
        mesh.check_growth("untangle")?;
        // A round is kept only when it leaves fewer folds (a split whose ring has no place that
        // sees all its edges, e.g. around crossing fixed curve vertices, only adds faces).
        let snapshot = (mesh.clone(), stats.clone(), reference.vertex_count());
        progress.check()?;
        let ctx = Ctx { reference: &*reference, fixed: &fixed, locked };
        let bad = folded_faces(mesh, &ctx, progress)?;
        let mut batch = Vec::new();
        let mut added = Vec::new();
        for f in bad {
            if !mesh.alive[f as usize] || !ctx.folded(mesh, f) {
                continue; // split already by a neighbour's split
            }
            let t = mesh.tris[f as usize];
            // The longest non-locked edge with a face on both sides (a boundary vertex would be
            // fixed, so a split boundary edge gains nothing).
            let edge = (0..3)
                .map(|k| (t[k], t[(k + 1) % 3]))
                .filter(|&(a, b)| !ctx.locked(a, b) && mesh.face_with_edge(b, a).is_some())
                .max_by(|x, y| mesh.len(x.0, x.1).total_cmp(&mesh.len(y.0, y.1)));
            let Some((a, b)) = edge else { continue };
            let mid = scale(add(mesh.pos[a as usize], mesh.pos[b as usize]), 0.5);
            let Some(m) = mesh.split_edge(a, b, mid) else { continue };
            added.push((m, a, b));
            batch.push(UvMove { vertex: m, weights: [(a, 0.5), (b, 0.5), (a, 0.0)] });
        }
        if added.is_empty() {
            break;
        }
        for &(m, a, b) in &added {
            debug_assert_eq!(m as usize, reference.vertex_count());
            reference.push_midpoint(a, b);
            fixed.push(false);
            stats.added.push([(a, 0.5), (b, 0.5), (a, 0.0)]);
        }
        stats.edge_splits += added.len();
        stats.uv_batches.push(batch);
        let again = untangle_polled(mesh, &*reference, &fixed, locked, max_passes, progress)?;
        if again.folded_after >= stats.folded_after {
            let (m, s, nv) = snapshot;
            *mesh = m;
            stats = s;
            reference.truncate_vertices(nv);
            fixed.truncate(nv);
            break;
        }
        stats.edge_flips += again.edge_flips;
        stats.vertex_moves += again.vertex_moves;
        stats.patches_solved += again.patches_solved;
        stats.patch_vertex_moves += again.patch_vertex_moves;
        stats.flip_sequences += again.flip_sequences;
        stats.sequence_flips += again.sequence_flips;
        stats.uv_batches.extend(again.uv_batches);
        stats.folded_after = again.folded_after;
        if stats.folded_after == 0 {
            break;
        }
    }
    Ok(stats)
}

/// Edge flips and ring-mean moves, face by face, until nothing changes; returns the folded count.
fn local_passes(
    mesh: &mut TriMesh,
    ctx: &Ctx,
    stats: &mut UntangleStats,
    max_passes: usize,
    progress: &Progress,
) -> Result<usize> {
    let mut bad = folded_faces(mesh, ctx, progress)?;
    for _ in 0..max_passes {
        if bad.is_empty() {
            break;
        }
        let mut changed = false;
        for (i, &f) in bad.iter().enumerate() {
            progress.check_every(i, POLL_FOLDED)?;
            if !mesh.alive[f as usize] || !ctx.folded(mesh, f) {
                continue;
            }
            if try_edge_flip(mesh, ctx, f) {
                stats.edge_flips += 1;
                changed = true;
            } else if let Some(m) = try_moves(mesh, ctx, f) {
                stats.vertex_moves += 1;
                stats.uv_batches.push(m.into_iter().collect());
                changed = true;
            }
        }
        bad = folded_faces(mesh, ctx, progress)?;
        if !changed {
            break;
        }
    }
    Ok(bad.len())
}

/// A flip of face `f`'s non-locked edge: the face across it and the two faces of the other
/// diagonal, `[c, a, d]` and `[d, b, c]` for `f = (a, b, c)` and the neighbour's corner `d`.
pub(super) struct FlipQuad {
    pub g: u32,
    pub old: [[u32; 3]; 2],
    pub new: [[u32; 3]; 2],
}

/// The flips of face `f`'s edges that are allowed: not locked, with a neighbour, and not making
/// an edge the mesh already has.
pub(super) fn flip_quads(mesh: &TriMesh, ctx: &Ctx, f: u32) -> Vec<FlipQuad> {
    let t = mesh.tris[f as usize];
    let mut out = Vec::new();
    for k in 0..3 {
        let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        if ctx.locked(a, b) {
            continue;
        }
        let Some(g) = mesh.face_with_edge(b, a) else { continue };
        let tg = mesh.tris[g as usize];
        let Some(&d) = tg.iter().find(|&&v| v != a && v != b) else { continue };
        if d == c || mesh.has_edge(c, d) {
            continue;
        }
        out.push(FlipQuad { g, old: [t, tg], new: [[c, a, d], [d, b, c]] });
    }
    out
}

/// Replaces face `f` and `q.g` by `q.new`.
pub(super) fn apply_flip(mesh: &mut TriMesh, f: u32, q: &FlipQuad) -> bool {
    mesh.remove_face(f);
    mesh.remove_face(q.g);
    let (ok1, ok2) = (mesh.add_face(q.new[0]), mesh.add_face(q.new[1]));
    debug_assert!(ok1.is_ok() && ok2.is_ok());
    ok1.is_ok() && ok2.is_ok()
}

/// Flips the best non-locked edge of folded face `f` when both new faces are unfolded.
fn try_edge_flip(mesh: &mut TriMesh, ctx: &Ctx, f: u32) -> bool {
    let p = |v: u32| mesh.pos[v as usize];
    let mut best: Option<(f64, FlipQuad)> = None;
    for q in flip_quads(mesh, ctx, f) {
        let (s1, s2) = (ctx.score(q.new[0], p), ctx.score(q.new[1], p));
        if s1 <= MIN_COS || s2 <= MIN_COS {
            continue;
        }
        // Prefer the flip whose worse face is the better oriented.
        let worse = s1.min(s2);
        if best.as_ref().is_none_or(|b| worse > b.0) {
            best = Some((worse, q));
        }
    }
    best.is_some_and(|(_, q)| apply_flip(mesh, f, &q))
}

/// Moves one free vertex of `f` (or of a face around `f`'s corners) to a ring mean when that
/// unfolds every face around it and reduces the folded count. Returns whether a vertex moved, with
/// its UV move when its new position could be located.
fn try_moves(mesh: &mut TriMesh, ctx: &Ctx, f: u32) -> Option<Option<UvMove>> {
    let t = mesh.tris[f as usize];
    let mut cand: Vec<u32> = t.iter().copied().filter(|&v| !ctx.fixed[v as usize]).collect();
    for &v in &t {
        for &g in mesh.faces_of(v) {
            for &w in &mesh.tris[g as usize] {
                if !ctx.fixed[w as usize] && !cand.contains(&w) {
                    cand.push(w);
                }
            }
        }
    }
    for v in cand {
        if mesh.is_boundary_vertex(v) {
            continue;
        }
        let star: Vec<u32> = mesh.faces_of(v).to_vec();
        let folded_now = star.iter().filter(|&&g| ctx.folded(mesh, g)).count();
        if folded_now == 0 {
            continue;
        }
        let mut ring: Vec<u32> = Vec::new();
        for &g in &star {
            for &w in &mesh.tris[g as usize] {
                if w != v && !ring.contains(&w) {
                    ring.push(w);
                }
            }
        }
        let mean =
            scale(ring.iter().fold([0.0; 3], |a, &w| add(a, mesh.pos[w as usize])), 1.0 / ring.len() as f64);
        let p0 = mesh.pos[v as usize];
        let n = ctx.normal_at(mesh, v);
        let d = sub(mean, p0);
        let tangential = add(p0, sub(d, scale(n, dot(d, n))));
        // Where a non-convex ring has a place that sees all its edges (the mean does not).
        let ring_edges: Vec<(Point3, Point3)> = star
            .iter()
            .map(|&g| {
                let tg = mesh.tris[g as usize];
                let k = tg.iter().position(|&w| w == v).unwrap_or(0);
                (mesh.pos[tg[(k + 1) % 3] as usize], mesh.pos[tg[(k + 2) % 3] as usize])
            })
            .collect();
        let kernel = kernel::kernel_centre(&ring_edges, n);
        for target in [Some(tangential), Some(mean), kernel].into_iter().flatten() {
            let ok = star.iter().all(|&g| {
                ctx.score_face(mesh, g, |w| if w == v { target } else { mesh.pos[w as usize] }) > MIN_COS
            });
            if ok {
                let uv = uvs::record(mesh, v, target);
                mesh.pos[v as usize] = target;
                return Some(uv);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_untangling_polls_per_8192_faces_of_each_scan_and_stops_at_a_cancel() {
        // An equilateral grid of 257 × 161 vertices (81,920 faces) with its own vertex normals as
        // the reference: nothing folded. Two scans of all faces (the folded count before, the
        // local passes' first list), each polled at face ids 0, 8192, …, 73728: 2 × 10 = 20
        // polls (the code before polled once, on entering `untangle_with_splits`).
        let grid = crate::shapes::triangle_grid(257, 161, 1.0);
        let tris = grid.faces.triangles();
        assert_eq!(tris.len(), 81_920);
        let reference = crate::fit::report::vertex_normals(&grid.positions, &tris);
        let fixed = vec![false; grid.positions.len()];
        let run = |p: &Progress| {
            let mut mesh = TriMesh::new(grid.positions.clone(), tris.clone()).unwrap();
            untangle_with_splits(&mut mesh, &mut reference.clone(), &fixed, &EdgeSet::default(), 8, p)
        };
        let p = Progress::new();
        let st = run(&p).unwrap();
        assert_eq!((st.folded_before, st.folded_after, st.edge_flips, st.vertex_moves), (0, 0, 0, 0));
        assert_eq!(p.checks(), 20);
        let p = Progress::new();
        p.cancel_at_check(13);
        assert!(matches!(run(&p), Err(crate::error::Error::Cancelled)));
        assert_eq!(p.checks(), 13, "stopped at the cancel, not after the scan");
    }

    #[test]
    fn a_free_vertex_pushed_across_its_ring_comes_back() {
        // A fan of 6 triangles around vertex 6 in the plane z = 0; the centre is moved outside the
        // hexagon, folding the faces on the far side. Reference normal +z everywhere.
        let mut pos: Vec<Point3> = (0..6)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 6.0;
                [a.cos(), a.sin(), 0.0]
            })
            .collect();
        pos.push([1.6, 0.2, 0.0]);
        let tris: Vec<[u32; 3]> = (0..6).map(|k| [k, (k + 1) % 6, 6]).collect();
        let mut mesh = TriMesh::new(pos, tris).unwrap();
        let reference = vec![[0.0, 0.0, 1.0]; 7];
        let fixed = vec![true, true, true, true, true, true, false];
        let s = untangle(&mut mesh, &reference, &fixed, &EdgeSet::default(), 5);
        assert!(s.folded_before > 0);
        assert_eq!(s.folded_after, 0);
        // The boundary ring did not move.
        assert_eq!(mesh.pos[0], [1.0, 0.0, 0.0]);
    }

    /// A 10×10 plane grid (reference +z) whose inner 4×4 block of vertices is mirrored through
    /// the block's centre line x = 4.5 (vertex (i, j) goes to (9 − i, j)): every face of the block
    /// is turned over and the block's rows cross each other, so no single vertex has an unfolded
    /// position given its (equally folded) neighbours. A fixed vertex sits next to the block (a
    /// curve vertex). Truth: the grid itself is fold-free with the same fixed vertices, so a
    /// fold-free answer exists; every vertex must stay in the plane and fixed ones must not move.
    #[test]
    fn a_mirrored_block_is_untangled_as_a_whole() {
        let n = 10usize;
        let g = crate::shapes::grid(n, n, 1.0, false);
        let tris = crate::shapes::fan_triangles(&g.faces);
        let id = |i: usize, j: usize| j * (n + 1) + i;
        let mut pos = g.positions.clone();
        for j in 3..=6 {
            for i in 3..=6 {
                pos[id(i, j)][0] = 9.0 - pos[id(i, j)][0];
            }
        }
        let mut fixed: Vec<bool> = (0..pos.len())
            .map(|v| v % (n + 1) == 0 || v % (n + 1) == n || v <= n || v >= n * (n + 1))
            .collect();
        fixed[id(2, 4)] = true;
        let before = pos.clone();
        let mut mesh = TriMesh::new(pos, tris).unwrap();
        let reference = vec![[0.0, 0.0, 1.0]; mesh.pos.len()];
        let s = untangle(&mut mesh, &reference, &fixed, &EdgeSet::default(), 8);
        assert!(s.folded_before >= 9, "{s:?}");
        // (Since session 5 the kernel move of `try_moves` untangles this block vertex by vertex,
        // so the patch solver is not needed here; `fit_untangle_uvs` and the sweep exercise it.)
        assert_eq!(s.folded_after, 0, "{s:?}");
        for (v, p) in mesh.pos.iter().enumerate() {
            assert!(p[2].abs() < 1e-12, "vertex {v} left the plane: {p:?}");
            if fixed[v] {
                assert_eq!(*p, before[v]);
            }
        }
        for f in mesh.alive_faces() {
            let t = mesh.tris[f as usize];
            let c = triangle_cross(mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize]);
            assert!(c[2] > 0.0, "face {t:?} still turned over");
        }
    }

    #[test]
    fn a_fold_between_fixed_vertices_is_flipped_away() {
        // Faces (0,1,2) and (0,2,3) share edge 0-2; vertex 3 = (1, -0.3) lies on the same side of
        // 0→2 as vertex 1, so (0,2,3) is clockwise (folded). All vertices fixed: only flipping
        // 0-2 into 1-3 helps, giving (3,0,1) and (1,2,3), both counter-clockwise (by hand:
        // cross products 0.7 and 0.7).
        let pos = vec![[0.0, 0.0, 0.0], [1.0, -1.0, 0.0], [2.0, 0.0, 0.0], [1.0, -0.3, 0.0]];
        let tris = vec![[0, 1, 2], [0, 2, 3]];
        let mut mesh = TriMesh::new(pos, tris).unwrap();
        let reference = vec![[0.0, 0.0, 1.0]; 4];
        let s = untangle(&mut mesh, &reference, &[true; 4], &EdgeSet::default(), 5);
        assert_eq!((s.folded_before, s.edge_flips, s.folded_after), (1, 1, 0));
        assert!(mesh.has_edge(1, 3) && !mesh.has_edge(0, 2));
        // The same fold with edge 0-2 locked (a curve edge) cannot be fixed, and says so.
        let tris = vec![[0, 1, 2], [0, 2, 3]];
        let pos = vec![[0.0, 0.0, 0.0], [1.0, -1.0, 0.0], [2.0, 0.0, 0.0], [1.0, -0.3, 0.0]];
        let mut mesh = TriMesh::new(pos, tris).unwrap();
        let mut locked = EdgeSet::default();
        locked.insert((0, 2));
        let s = untangle(&mut mesh, &reference, &[true; 4], &locked, 5);
        assert_eq!((s.folded_before, s.edge_flips, s.folded_after), (1, 0, 1));
    }
}
