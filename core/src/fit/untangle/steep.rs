//! Faces standing steeply on the surface, flipped flat: a face whose normal is more than ~73°
//! from its reference ([`STEEP_COS`]) but not folded, e.g. three consecutive points of one planar
//! section joined into a triangle (a *fin* in the section plane, perpendicular to the surface where
//! the surface crosses the plane). The untangling leaves such faces (they are not folded), and the
//! last repair cannot turn them once the count calls one turned: the fin across the curve on the
//! other side folds against it (session 20, `cow-raw vs own sections`).
//!
//! Each steep face's non-locked edges are tried: the flip whose worse new face is better oriented
//! than the worse of the two old ones is made, when neither new face is thinner than the old
//! ones' smallest angle or [`MIN_FLIP_ANGLE_DEG`]. Locked (curve) edges never flip and no vertex
//! moves, so chains and curve points stay as they are.

use crate::error::Result;
use crate::geometry::{self, triangle_cross};
use crate::job::Progress;

use super::super::trimesh::TriMesh;
use super::{apply_flip, flip_quads, folded_pair, Ctx, FlipQuad, MIN_COS};

/// A face whose normal's cosine with its reference is below this stands steeply on the surface.
pub(crate) const STEEP_COS: f64 = 0.3;
/// New faces keep at least this smallest angle (or the old faces' smallest, when thinner).
const MIN_FLIP_ANGLE_DEG: f64 = 5.0;
/// Passes over the steep faces left.
const PASSES: usize = 4;

pub(super) fn flip_steep(mesh: &mut TriMesh, ctx: &Ctx, progress: &Progress) -> Result<usize> {
    let mut flips = 0;
    for _ in 0..PASSES {
        let mut changed = false;
        let n = mesh.tris.len();
        for f in 0..n as u32 {
            progress.check_every(f as usize, super::POLL_FOLDED)?;
            if !mesh.alive[f as usize] {
                continue;
            }
            let q = ctx.score_face(mesh, f, |v| mesh.pos[v as usize]);
            if q <= MIN_COS || q >= STEEP_COS {
                continue;
            }
            if flip_best(mesh, ctx, f) {
                flips += 1;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    Ok(flips)
}

fn min_angle_deg(mesh: &TriMesh, t: [u32; 3]) -> f64 {
    let p = |v: u32| mesh.pos[v as usize];
    geometry::min_angle_deg(p(t[0]), p(t[1]), p(t[2]))
}

/// Folded pairs ([`folded_pair`]) among the two faces of a quad and between each and its
/// neighbour across the quad's four outer edges.
fn folds(mesh: &TriMesh, faces: [[u32; 3]; 2]) -> usize {
    let p = |v: u32| mesh.pos[v as usize];
    let normal = |t: [u32; 3]| triangle_cross(p(t[0]), p(t[1]), p(t[2]));
    let (n0, n1) = (normal(faces[0]), normal(faces[1]));
    let mut count = usize::from(folded_pair(n0, n1));
    for (t, n) in [(faces[0], n0), (faces[1], n1)] {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            // The quad's inner edge is shared by the two faces (counted above).
            if faces[0].contains(&a)
                && faces[0].contains(&b)
                && faces[1].contains(&a)
                && faces[1].contains(&b)
            {
                continue;
            }
            if let Some(g) = mesh.face_with_edge(b, a) {
                count += usize::from(folded_pair(n, normal(mesh.tris[g as usize])));
            }
        }
    }
    count
}

fn flip_best(mesh: &mut TriMesh, ctx: &Ctx, f: u32) -> bool {
    let p = |v: u32| mesh.pos[v as usize];
    let mut best: Option<(f64, FlipQuad)> = None;
    for q in flip_quads(mesh, ctx, f) {
        let [t, tg] = q.old;
        let [n1, n2] = q.new;
        let old = ctx.score(t, p).min(ctx.score(tg, p));
        let new = ctx.score(n1, p).min(ctx.score(n2, p));
        let floor = min_angle_deg(mesh, t).min(min_angle_deg(mesh, tg)).min(MIN_FLIP_ANGLE_DEG);
        if new <= old || new <= MIN_COS || min_angle_deg(mesh, n1).min(min_angle_deg(mesh, n2)) < floor {
            continue;
        }
        if folds(mesh, q.new) > folds(mesh, q.old) {
            continue;
        }
        if best.as_ref().is_none_or(|b| new > b.0) {
            best = Some((new, q));
        }
    }
    best.is_some_and(|(_, q)| apply_flip(mesh, f, &q))
}
