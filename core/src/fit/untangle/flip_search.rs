//! Folds whose corners cannot move undone by *sequences* of edge flips.
//!
//! The local fixes of [`super`] flip one edge at a time and only when both new faces are
//! unfolded; they move free vertices only. A fold among fixed vertices (curve points, chain
//! vertices) that no single flip undoes stays, e.g.:
//! - three consecutive collinear curve points on a flat face, two coplanar faces overlapping:
//!   flipping their shared edge gives a zero-area face over the middle point, and only a second
//!   flip (of that face's long edge) finishes the repair;
//! - a face whose corners are all curve points, turned against its three neighbours;
//! - strips of coplanar faces folded onto each other between curve vertices.
//!
//! Here each folded face's neighbourhood (the faces at its corners, grown over the folded faces
//! met there) is copied, and flip sequences of up to [`MAX_DEPTH`] non-locked edges are searched
//! on the copy, each flip taken from the currently bad faces, intermediate states allowed to be
//! worse (zero-area, folded). The best end state — fewest faces turned over (or zero-area), then
//! fewest folded, then least fold energy — replaces the neighbourhood in the mesh when it is
//! better on the first two counts than before. Vertices never move and locked (curve) edges are
//! never flipped, so every chain stays an edge chain and every curve vertex stays where it is;
//! the edges only change among the neighbourhood's own vertices.

use std::collections::HashSet;

use crate::error::Result;
use crate::geometry::{norm2, sub, triangle_cross};
use crate::job::Progress;

use super::super::trimesh::TriMesh;
use super::{planar, Ctx, MIN_COS};

/// Longest flip sequence searched per neighbourhood (3: the collinear overlap needs 2).
const MAX_DEPTH: usize = 3;
/// Largest neighbourhood copied (faces): the folds this is for are a few faces.
const MAX_PATCH_FACES: usize = 64;
/// Flip sequences evaluated per neighbourhood at most (the search stops there, keeping its best).
const MAX_STATES: usize = 4_000;
/// A face whose doubled area is under this fraction of its longest edge squared counts as
/// zero-area (its normal is round-off).
const DEGENERATE: f64 = 1e-12;

/// A rule every end state must pass to be kept, given the neighbourhood's original face ids and
/// the state's faces (the last repair's rules: [`crate::fit::turned`]); none: the badness alone.
pub(crate) type Guard<'a> = Option<&'a GuardFn<'a>>;

/// The rule of a [`Guard`]: (mesh, original face ids, the state's faces, whether the state is a
/// planar re-triangulation rather than a flip sequence) → keep.
pub(crate) type GuardFn<'a> = dyn Fn(&TriMesh, &[u32], &[[u32; 3]], bool) -> bool + 'a;

/// What the flip-sequence pass did.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct SearchPass {
    /// Neighbourhoods replaced by a flip sequence.
    pub regions: usize,
    /// Flips in the sequences applied.
    pub flips: usize,
    /// Neighbourhoods replaced by a planar re-triangulation ([`super::planar`]).
    pub planar: usize,
}

/// How a neighbourhood was replaced.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Replaced {
    /// By a sequence of this many flips.
    Flips(usize),
    /// By a new triangulation of its vertices in its plane.
    Planar,
}

/// A state's badness ([`Patch::badness`]): turned, folded, fold energy.
type Badness = (usize, usize, f64);

/// Whether badness `new` is better than `old`: fewer turned or folded (lexicographically), or as
/// many with less energy.
fn improves(new: Badness, old: Badness) -> bool {
    (new.0, new.1) < (old.0, old.1) || ((new.0, new.1) == (old.0, old.1) && new.2 < old.2 - 1e-12)
}

/// Cosine of face `t`'s normal with its reference (0 for a zero-area face): folded at or below
/// [`MIN_COS`].
fn quality(mesh: &TriMesh, ctx: &Ctx, t: [u32; 3]) -> f64 {
    let p = |v: u32| mesh.pos[v as usize];
    let n = triangle_cross(p(t[0]), p(t[1]), p(t[2]));
    let longest =
        [(0, 1), (1, 2), (2, 0)].iter().map(|&(i, j)| norm2(sub(p(t[i]), p(t[j])))).fold(0.0, f64::max);
    if norm2(n) <= (DEGENERATE * longest).powi(2) {
        return 0.0;
    }
    ctx.score(t, p)
}

/// How far a face is from unfolded (0 when unfolded): ranks states with as many folded faces.
fn energy(q: f64) -> f64 {
    (MIN_COS - q).max(0.0)
}

/// The copied neighbourhood: its faces (the mesh's ids of the originals, then local faces).
struct Patch {
    original: Vec<u32>,
    faces: Vec<[u32; 3]>,
    quality: Vec<f64>,
}

impl Patch {
    /// How bad the patch is, lexicographically: faces turned over or zero-area (what the report
    /// counts as flipped or zero-area), then faces folded (within [`MIN_COS`] of perpendicular, or
    /// beyond), then the summed fold energy.
    fn badness(&self) -> Badness {
        let turned = self.quality.iter().filter(|&&q| q <= 0.0).count();
        let folded = self.quality.iter().filter(|&&q| q <= MIN_COS).count();
        (turned, folded, self.quality.iter().map(|&q| energy(q)).sum())
    }
    /// The local face with directed edge a → b.
    fn with_edge(&self, a: u32, b: u32) -> Option<usize> {
        self.faces.iter().position(|t| (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b))
    }
    fn has_edge(&self, mesh: &TriMesh, a: u32, b: u32) -> bool {
        if self.with_edge(a, b).is_some() || self.with_edge(b, a).is_some() {
            return true;
        }
        // Faces outside the patch with that edge.
        mesh.faces_of(a).iter().any(|&g| !self.original.contains(&g) && mesh.tris[g as usize].contains(&b))
    }
}

/// The faces at the corners of folded face `f`, grown over the folded faces met (up to
/// [`MAX_PATCH_FACES`]).
fn neighbourhood(mesh: &TriMesh, ctx: &Ctx, f: u32) -> Vec<u32> {
    let mut faces = vec![f];
    let mut grown = 0;
    while grown < faces.len() && faces.len() < MAX_PATCH_FACES {
        let g = faces[grown];
        grown += 1;
        if g != f && !ctx.folded(mesh, g) {
            continue;
        }
        for &v in &mesh.tris[g as usize] {
            for &h in mesh.faces_of(v) {
                if !faces.contains(&h) && faces.len() < MAX_PATCH_FACES {
                    faces.push(h);
                }
            }
        }
    }
    faces
}

/// The flips of the patch's bad faces' edges: (face, k) with the edge t[k] → t[k+1], the face
/// across and the two new faces, deduplicated by edge.
fn candidate_flips(patch: &Patch, mesh: &TriMesh, ctx: &Ctx) -> Vec<(usize, usize, [u32; 3], [u32; 3])> {
    let mut out: Vec<(usize, usize, [u32; 3], [u32; 3])> = Vec::new();
    let mut seen: Vec<(u32, u32)> = Vec::new();
    for (i, t) in patch.faces.iter().enumerate() {
        if patch.quality[i] > MIN_COS {
            continue;
        }
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let key = (a.min(b), a.max(b));
            if ctx.locked(a, b) || seen.contains(&key) {
                continue;
            }
            seen.push(key);
            let Some(j) = patch.with_edge(b, a) else { continue };
            let tg = patch.faces[j];
            let Some(&d) = tg.iter().find(|&&v| v != a && v != b) else { continue };
            if d == c || patch.has_edge(mesh, c, d) {
                continue;
            }
            out.push((i, j, [c, a, d], [d, b, c]));
        }
    }
    out
}

struct Search<'a> {
    mesh: &'a TriMesh,
    ctx: &'a Ctx<'a>,
    guard: Guard<'a>,
    states: usize,
    /// The best state seen: its badness, faces and how it was made.
    best: (Badness, Vec<[u32; 3]>, Replaced),
}

impl Search<'_> {
    /// Depth-first over the flips of the bad faces' edges, down to `max_depth` flips, never
    /// undoing the flip just made (`last`: the edge it made).
    fn visit(&mut self, patch: &mut Patch, depth: usize, max_depth: usize, last: (u32, u32)) {
        self.states += 1;
        let badness = patch.badness();
        if improves(badness, self.best.0)
            && self.guard.is_none_or(|g| depth == 0 || g(self.mesh, &patch.original, &patch.faces, false))
        {
            self.best = (badness, patch.faces.clone(), Replaced::Flips(depth));
        }
        if depth == max_depth || self.best.0 .1 == 0 || self.states >= MAX_STATES {
            return;
        }
        for (i, j, n1, n2) in candidate_flips(patch, self.mesh, self.ctx) {
            // n1 = [c, a, d], n2 = [d, b, c]: edge a–b is flipped into c–d.
            let made = (n1[0].min(n1[2]), n1[0].max(n1[2]));
            if (n1[1].min(n2[1]), n1[1].max(n2[1])) == last {
                continue;
            }
            if self.states >= MAX_STATES || self.best.0 .1 == 0 {
                return;
            }
            let (old_i, old_j) = (patch.faces[i], patch.faces[j]);
            let (qi, qj) = (patch.quality[i], patch.quality[j]);
            patch.faces[i] = n1;
            patch.faces[j] = n2;
            patch.quality[i] = quality(self.mesh, self.ctx, n1);
            patch.quality[j] = quality(self.mesh, self.ctx, n2);
            self.visit(patch, depth + 1, max_depth, made);
            patch.faces[i] = old_i;
            patch.faces[j] = old_j;
            patch.quality[i] = qi;
            patch.quality[j] = qj;
        }
    }
}

/// Replaces the neighbourhood of folded face `f` by the best flip sequence's faces when that has
/// fewer folded faces; returns how it was replaced, or the neighbourhood searched in vain.
fn repair_one(
    mesh: &mut TriMesh,
    ctx: &Ctx,
    guard: Guard,
    f: u32,
) -> std::result::Result<Replaced, Vec<u32>> {
    let original = neighbourhood(mesh, ctx, f);
    let faces: Vec<[u32; 3]> = original.iter().map(|&g| mesh.tris[g as usize]).collect();
    let quality_of: Vec<f64> = faces.iter().map(|&t| quality(mesh, ctx, t)).collect();
    let mut patch = Patch { original, faces, quality: quality_of };
    let before = patch.badness();
    let mut search = Search { mesh, ctx, guard, states: 0, best: (before, Vec::new(), Replaced::Flips(0)) };
    // Shortest sequences first: a fix by one or two flips changes least.
    for max_depth in 1..=MAX_DEPTH {
        search.visit(&mut patch, 0, max_depth, (u32::MAX, u32::MAX));
        if search.best.0 .1 == 0 || search.states >= MAX_STATES {
            break;
        }
    }
    // The last repair only (a guard): where no sequence leaves the neighbourhood free of turned
    // faces, a new triangulation of its vertices in its plane. Not in the untangling stages
    // before it (no guard): there the moves and splits that follow do better on what it would
    // take (session 24: cow twisted (auto) 35 -> 40 flips with it there too).
    if let Some(g) = guard.filter(|_| search.best.0 .0 > 0) {
        if let Some((badness, faces)) = planar_state(mesh, ctx, &patch.original, &patch.faces) {
            if improves(badness, search.best.0) && g(mesh, &patch.original, &faces, true) {
                search.best = (badness, faces, Replaced::Planar);
            }
        }
    }
    // Kept only with fewer faces turned over (or as many and fewer folded): a trade of two faces
    // standing on their edge (folded, not flipped) for one turned over is refused.
    let ((turned, folded, _), new_faces, replaced) = search.best;
    if (turned, folded) >= (before.0, before.1) || new_faces.is_empty() {
        return Err(patch.original);
    }
    for &g in &patch.original {
        mesh.remove_face(g);
    }
    let mut added = Vec::new();
    for &t in &new_faces {
        match mesh.add_face(t) {
            Ok(g) => added.push(g),
            Err(()) => {
                // Not expected (the flips keep every directed edge unique); put the originals back.
                for g in added {
                    mesh.remove_face(g);
                }
                for &g in &patch.original {
                    let _ = mesh.add_face(mesh.tris[g as usize]);
                }
                return Err(Vec::new());
            }
        }
    }
    Ok(replaced)
}

/// The neighbourhood `faces` (ids `original`) triangulated anew in its plane
/// ([`planar::retriangulate`]), with its badness.
fn planar_state(
    mesh: &TriMesh,
    ctx: &Ctx,
    original: &[u32],
    faces: &[[u32; 3]],
) -> Option<(Badness, Vec<[u32; 3]>)> {
    let faces = planar::retriangulate(mesh, ctx, faces)?;
    let quality = faces.iter().map(|&t| quality(mesh, ctx, t)).collect();
    let flat = Patch { original: original.to_vec(), faces, quality };
    Some((flat.badness(), flat.faces))
}

/// One pass over the folded faces `bad` (in id order): each one still folded gets its
/// neighbourhood's flip-sequence search.
pub(super) fn flip_sequences(
    mesh: &mut TriMesh,
    ctx: &Ctx,
    guard: Guard,
    bad: &[u32],
    progress: &Progress,
) -> Result<SearchPass> {
    let mut out = SearchPass::default();
    // Faces of neighbourhoods already searched in vain this pass: the same search again from
    // another of their folded faces would mostly repeat it.
    let mut searched: HashSet<u32> = HashSet::new();
    for (i, &f) in bad.iter().enumerate() {
        progress.check_every(i, super::POLL_FOLDED)?;
        if searched.contains(&f) || !mesh.alive[f as usize] || !ctx.folded(mesh, f) {
            continue;
        }
        match repair_one(mesh, ctx, guard, f) {
            Ok(Replaced::Flips(flips)) => {
                out.regions += 1;
                out.flips += flips;
            }
            Ok(Replaced::Planar) => out.planar += 1,
            Err(faces) => searched.extend(faces),
        }
    }
    Ok(out)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::{untangle, EdgeSet};
    use super::*;

    /// Normals of the live faces of a planar mesh: faces at or below zero z (turned over or
    /// zero-area), by a cross product computed here.
    fn faces_not_up(mesh: &TriMesh) -> Vec<[u32; 3]> {
        mesh.live_triangles()
            .into_iter()
            .filter(|t| {
                triangle_cross(mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize])[2]
                    <= 0.0
            })
            .collect()
    }

    /// The collinear case (fandisk's flat face): a = (0,0), m = (1,0), b = (2,0) are curve points
    /// on one straight line, a–m a curve edge, b–c3 another; every vertex fixed. Face (a, m, c1)
    /// is turned over (doubled signed area −1.2, by hand) under face (c1, b, a), whose edge b–a
    /// passes over m, and against its other two neighbours. Flipping their shared edge a–c1 gives
    /// the zero-area (m, a, b) (refused by the one-flip rule), and flipping that face's long edge
    /// a–b then finishes: (a, m, c4), (m, b, c4). The hexagon c0…c5 with a, m, b inside has such
    /// a fold-free triangulation (the one the fold was made from by flips), so 0 is reachable.
    /// Vertices a, m, b, c0, …, c5 are 0, …, 8 (plane z = 0). Also the last repair's
    /// flip-sequence case ([`crate::fit::turned`]).
    pub(crate) fn collinear_overlap() -> (Vec<crate::mesh::Point3>, Vec<[u32; 3]>) {
        let pos = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [-1.0, -1.0, 0.0],
            [1.0, -1.2, 0.0],
            [3.0, -1.0, 0.0],
            [3.0, 1.0, 0.0],
            [1.0, 1.2, 0.0],
            [-1.0, 1.0, 0.0],
        ];
        let (a, m, b, c0, c1, c2, c3, c4, c5) = (0, 1, 2, 3, 4, 5, 6, 7, 8);
        let tris = vec![
            [a, c4, c5],
            [a, c5, c0],
            [a, m, c1],
            [b, c1, c2],
            [b, c2, c3],
            [b, c3, c4],
            [b, c4, a],
            [c0, c1, m],
            [c1, b, a],
            [m, a, c0],
        ];
        (pos, tris)
    }

    /// A 4 × 4 vertex grid of unit squares (vertex (i, j) is 4j + i, squares split along their
    /// rising diagonal) with the positions of inner vertices 5 = (1,1) and 10 = (2,2) swapped,
    /// every vertex fixed: the faces around both are turned over. With a guard (the last repair)
    /// a neighbourhood no sequence of up to 3 flips leaves unturned is triangulated anew in its
    /// plane; without one (the untangling stages) it is not.
    #[test]
    fn a_swap_no_short_sequence_undoes_is_retriangulated_only_under_a_guard() {
        let (mut pos, tris) = super::super::planar::tests::grid();
        pos.swap(5, 10);
        let reference = vec![[0.0, 0.0, 1.0]; 16];
        let fixed = [true; 16];
        let locked = EdgeSet::default();
        let ctx = Ctx { reference: &reference, fixed: &fixed, locked: &locked };
        let progress = crate::job::Progress::new();
        let run = |guard: Guard| {
            let mut mesh = TriMesh::new(pos.clone(), tris.clone()).unwrap();
            let bad: Vec<u32> = (0..18).filter(|&f| ctx.folded(&mesh, f)).collect();
            assert!(!bad.is_empty());
            let pass = flip_sequences(&mut mesh, &ctx, guard, &bad, &progress).unwrap();
            (pass, mesh)
        };
        let (pass, mesh) = run(None);
        assert_eq!(pass.planar, 0);
        assert!(!faces_not_up(&mesh).is_empty(), "3 flips do not undo the swap: {pass:?}");
        let accept = |_: &TriMesh, _: &[u32], _: &[[u32; 3]], _: bool| true;
        let (pass, mesh) = run(Some(&accept));
        assert!(pass.planar >= 1, "{pass:?}");
        assert_eq!(faces_not_up(&mesh), Vec::<[u32; 3]>::new());
        assert_eq!(mesh.live_faces(), 18);
        assert_eq!(mesh.pos, pos, "a fixed vertex moved");
        // A guard that refuses everything keeps the mesh as it was.
        let refuse = |_: &TriMesh, _: &[u32], _: &[[u32; 3]], _: bool| false;
        let (pass, mesh) = run(Some(&refuse));
        assert_eq!((pass.regions, pass.planar), (0, 0));
        assert_eq!(mesh.live_triangles(), tris);
    }

    #[test]
    fn an_overlap_over_three_collinear_fixed_points_is_undone_by_two_flips() {
        let (pos, tris) = collinear_overlap();
        let (a, m, b, c1, c3) = (0, 1, 2, 4, 6);
        let mut mesh = TriMesh::new(pos.clone(), tris).unwrap();
        assert_eq!(faces_not_up(&mesh), vec![[a, m, c1]]);
        let mut locked = EdgeSet::default();
        locked.insert((a, m));
        locked.insert((b, c3));
        let reference = vec![[0.0, 0.0, 1.0]; pos.len()];
        let s = untangle(&mut mesh, &reference, &[true; 9], &locked, 8);
        assert_eq!(s.folded_before, 1);
        assert_eq!(faces_not_up(&mesh), Vec::<[u32; 3]>::new(), "{s:?}");
        assert_eq!(s.folded_after, 0);
        assert!(mesh.has_edge(a, m) && mesh.has_edge(b, c3), "a curve edge was flipped away");
        assert_eq!(mesh.pos, pos, "a fixed vertex moved");
        assert_eq!(mesh.live_faces(), 10);
        // Still a triangulation of the hexagon: total area by the shoelace formula, 8.8.
        let area: f64 = mesh
            .live_triangles()
            .iter()
            .map(|t| {
                triangle_cross(mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize])[2]
                    / 2.0
            })
            .sum();
        assert!((area - 8.8).abs() < 1e-12, "{area}");
    }
}
