//! Smoothing (Ch. 4), with the curve vertices (and the mesh boundary) held fixed (§4.3.3).
//!
//! 1. Modified mean-curvature flow (4.9, with its projection typo corrected): each free vertex
//!    moves by the *tangential* part of a cotangent-weighted Laplacian step and is dropped back
//!    onto the plane of the nearest face of the current surface. The step is scale-free: a
//!    fraction `mcf_step` of the way to the cotangent-weighted mean of the ring (λ of (4.7)
//!    normalised by the weights, so results do not depend on model units).
//! 2. Modified Laplacian flow (4.11, read as the note suggests): a tangential uniform-Laplacian
//!    step from the current position, then back-projection onto the surface *as it was before
//!    smoothing* (closest point, found by a local walk over the reference faces, which keeps the
//!    O(faces) per iteration of §4.3.4).
//!
//! Both flows are guarded ([`Guard::commit`]): all free vertices move at once, then a vertex whose
//! new star has a face turned over (against that face's normal before the step, or before smoothing
//! when it was not turned then), or a face whose
//! smallest angle got worse *and* is below the floor, has its step halved (and re-projected),
//! and after [`MAX_HALVINGS`] halvings is left where it was (a face that fails halves the
//! steps of all its moving corners). The floor is the larger of
//! `min_angle_floor_deg` and the smallest angle of the mesh before smoothing: a face above it
//! may get worse down to it, a face below it may not get worse. The checks repeat on the
//! faces around every changed vertex until none fails, so no face is made degenerate or
//! flipped and the smallest angle of the mesh never decreases.

use rayon::prelude::*;

use crate::error::Result;
use crate::geometry::{add, cross, dot, norm2, normalize, scale, sub, triangle_centroid};
use crate::job::Progress;
use crate::mesh::Point3;
use crate::topology::Csr;

use super::reference::Reference;

mod creases;
mod guard;

pub use creases::{crease_vertices, edge_bends, hold_template_creases, EdgeBend};
use guard::{face_shape, Guard};

pub struct SmoothSettings {
    pub mcf_iterations: u32,
    pub mcf_step: f64,
    pub laplacian_iterations: u32,
    /// Faces above this smallest angle (degrees) may get worse down to it, not below.
    pub min_angle_floor_deg: f64,
}

/// What the guard did, over all iterations.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct SmoothStats {
    /// Vertex steps proposed by the flows (free vertices that wanted to move).
    pub moves: usize,
    /// Steps halved at least once because they flipped a face or lowered the worst angle.
    pub moves_halved: usize,
    /// Steps given up after [`MAX_HALVINGS`] halvings (the vertex stayed put that iteration).
    pub moves_rejected: usize,
    /// Vertices put back where they were before smoothing because a face of theirs ended turned
    /// against the reference surface ([`undo_new_flips`]).
    pub undone_for_flips: usize,
    /// Template vertices held on a crease of the template (`smooth_hold_creases_deg`).
    pub held_at_creases: usize,
}

/// Halvings of a failing step before the vertex is left where it was.
pub const MAX_HALVINGS: u32 = 3;

/// Compressed vertex → neighbours and vertex → faces.
struct Rings {
    /// Face across edge k (t[k], t[k+1]) of each face, u32::MAX on the boundary.
    ff: Vec<[u32; 3]>,
    nb_off: Vec<u32>,
    nb: Vec<u32>,
    /// Vertex → faces, each row in face order.
    vf: Csr,
}

fn rings(nv: usize, tris: &[[u32; 3]]) -> Rings {
    let vf = Csr::vertex_triangles(nv, tris);
    let mut nb_off = vec![0u32; nv + 1];
    let mut nb = Vec::with_capacity(vf.items.len());
    for v in 0..nv {
        let start = nb.len();
        for &f in vf.row(v) {
            for &w in &tris[f as usize] {
                if w as usize != v && !nb[start..].contains(&w) {
                    nb.push(w);
                }
            }
        }
        nb_off[v + 1] = nb.len() as u32;
    }
    // The face across edge k of f uses that edge the other way round; with several (a
    // non-manifold input), the last in face order, as a directed-edge map filled in face order
    // would keep. Looked up in the ring of the edge's second end: no hash map (~60 ms of serial
    // CPU on the headline's 200k faces).
    let across = |f: usize, k: usize| {
        let t = tris[f];
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let ring = vf.row(b as usize);
        ring.iter().rev().copied().find(|&g| {
            let u = tris[g as usize];
            (0..3).any(|j| u[j] == b && u[(j + 1) % 3] == a)
        })
    };
    let ff = (0..tris.len())
        .into_par_iter()
        .with_min_len(4096)
        .map(|f| std::array::from_fn(|k| across(f, k).unwrap_or(u32::MAX)))
        .collect();
    Rings { ff, nb_off, nb, vf }
}

fn face_normal(pos: &[Point3], t: [u32; 3]) -> Point3 {
    cross(sub(pos[t[1] as usize], pos[t[0] as usize]), sub(pos[t[2] as usize], pos[t[0] as usize]))
}

/// Smooths `pos` in place; `fixed[v]` vertices never move.
pub fn smooth(
    pos: &mut [Point3],
    tris: &[[u32; 3]],
    fixed: &[bool],
    s: &SmoothSettings,
    progress: &Progress,
) -> Result<SmoothStats> {
    let nv = pos.len();
    let r = rings(nv, tris);
    // Normal and quality of every face at the current positions, kept up to date by the guard.
    let shape: Vec<(Point3, f64)> = tris.par_iter().map(|&t| face_shape(pos, t)).collect();
    let q_start = shape.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
    let mut guard = Guard {
        tris,
        r: &r,
        q_floor: s.min_angle_floor_deg.to_radians().sin().powi(2).max(q_start),
        // Each face's normal before smoothing: a face may not end turned against it (the per-step
        // test alone lets a face turn a little every step, past 90° in sum: the raw cow fitted to
        // its own sections kept one such face, session 22).
        start: tris.par_iter().map(|&t| face_normal(pos, t)).collect(),
        scratch: shape.clone(),
        shape,
        stats: SmoothStats::default(),
    };
    let total = (s.mcf_iterations + s.laplacian_iterations).max(1) as f64;
    // Stage 1: modified mean-curvature flow.
    // The positions being smoothed, replaced by each step's result (no copy per step); `pos`
    // gets them at the end.
    let mut cur = pos.to_vec();
    for it in 0..s.mcf_iterations {
        progress.fraction(it as f64 / total)?;
        let old = &cur;
        let shape = &guard.shape;
        // One pass over the faces at the old positions: cotangent weights and centroids (the
        // normals are in `shape`, kept up to date by the guard), computed once per face instead
        // of at each corner; then one pass over the vertices.
        let per_face: Vec<([f64; 3], Point3)> = tris
            .par_iter()
            .with_min_len(4096)
            .map(|&t| (cotangent_weights(old, t), centroid(old, t)))
            .collect();
        let proposed: Vec<Point3> = (0..nv)
            .into_par_iter()
            .with_min_len(1024)
            .map(|v| {
                if fixed[v] {
                    return old[v];
                }
                let acc = cotangent_sum(v, old, tris, &r, &per_face);
                if acc[3] <= 0.0 {
                    return old[v];
                }
                let target = scale([acc[0], acc[1], acc[2]], 1.0 / acc[3]);
                let faces = r.vf.row(v);
                let mut n = [0.0; 3];
                for &f in faces {
                    n = add(n, shape[f as usize].0);
                }
                let n = normalize(n);
                let d = scale(sub(target, old[v]), s.mcf_step);
                let moved = add(old[v], sub(d, scale(n, dot(d, n))));
                // Drop back onto the plane of the nearest incident face (current surface).
                let best = faces.iter().min_by(|&&a, &&b| {
                    let (ca, cb) = (per_face[a as usize].1, per_face[b as usize].1);
                    norm2(sub(ca, moved)).total_cmp(&norm2(sub(cb, moved)))
                });
                match best {
                    Some(&f) => {
                        let fnorm = normalize(shape[f as usize].0);
                        let o = old[tris[f as usize][0] as usize];
                        sub(moved, scale(fnorm, dot(sub(moved, o), fnorm)))
                    }
                    None => moved,
                }
            })
            .collect();
        // A halved step stays on the plane it was dropped onto (old and new are both on it).
        cur = guard.commit(old, proposed, |_, q| q).0;
    }
    // Stage 2: modified Laplacian flow, back-projected onto the surface as it was before
    // smoothing (the seed's p⁰, 5b: "the original surface is the reference"). Until session 22
    // this was the surface after stage 1, whose projections onto the planes of the current faces
    // drift off the surface at curved spots: a coarse rocker-arm fitted to the fine one's
    // sections ended with vertices 0.013 (unit box) off the unsmoothed surface, 0.004 now
    // (`fit_coarse_template`).
    let reference = if std::env::var("MW_OLDREF").is_ok() { cur.clone() } else { pos.to_vec() };
    // Unit normals of the reference faces (the reference does not move in this stage).
    let ref_normals: Vec<Point3> =
        tris.par_iter().with_min_len(4096).map(|&t| normalize(face_normal(&reference, t))).collect();
    let mut ref_face: Vec<u32> = (0..nv).map(|v| r.vf.row(v).first().copied().unwrap_or(u32::MAX)).collect();
    for it in 0..s.laplacian_iterations {
        progress.fraction((s.mcf_iterations + it) as f64 / total)?;
        let old = &cur;
        let mut new_ref = ref_face.clone();
        let proposed: Vec<Point3> = new_ref
            .par_iter_mut()
            .enumerate()
            .map(|(v, rf)| {
                let nbs = &r.nb[r.nb_off[v] as usize..r.nb_off[v + 1] as usize];
                if fixed[v] || nbs.is_empty() || *rf == u32::MAX {
                    return old[v];
                }
                let mut m = [0.0; 3];
                for &w in nbs {
                    m = add(m, old[w as usize]);
                }
                let m = scale(m, 1.0 / nbs.len() as f64);
                let n = ref_normals[*rf as usize];
                let d = sub(m, old[v]);
                let moved = add(old[v], sub(d, scale(n, dot(d, n))));
                let (f, q) = closest_by_walk(&reference, tris, &r, *rf, moved);
                *rf = f;
                q
            })
            .collect();
        // A halved step is dropped back onto the reference surface like a full one.
        let (next, kept) =
            guard.commit(old, proposed, |v, q| closest_by_walk(&reference, tris, &r, ref_face[v], q).1);
        for v in kept {
            let (f, _) = closest_by_walk(&reference, tris, &r, ref_face[v as usize], next[v as usize]);
            new_ref[v as usize] = f;
        }
        for (v, rf) in ref_face.iter_mut().enumerate() {
            if next[v] == old[v] {
                continue; // did not move: keep its face
            }
            *rf = new_ref[v];
        }
        cur = next;
    }
    pos.copy_from_slice(&cur);
    Ok(guard.stats)
}

/// The mean-curvature flow's weight of each edge k = (t[k], t[k+1]) of a face: half the cotangent
/// of the corner opposite it, negative ones clamped to 0 (they make the step leave the ring); NaN
/// for a degenerate corner, which adds nothing (a computed weight is never NaN: `max` drops a NaN
/// quotient).
fn cotangent_weights(pos: &[Point3], t: [u32; 3]) -> [f64; 3] {
    std::array::from_fn(|k| {
        let (i, j, o) = (t[k] as usize, t[(k + 1) % 3] as usize, t[(k + 2) % 3] as usize);
        let (u, v) = (sub(pos[i], pos[o]), sub(pos[j], pos[o]));
        let cr = norm2(cross(u, v)).sqrt();
        if cr <= 0.0 {
            f64::NAN
        } else {
            (dot(u, v) / cr).max(0.0) * 0.5
        }
    })
}

/// Σ w·q over the ring of `v` (3) and Σ w, with w the [`cotangent_weights`] (`per_face[f].0`). The
/// terms are added in the order of a serial face-by-face scatter (faces ascending, as `r.vf`
/// lists them, then edges in face order), so the sums do not depend on how the vertices are
/// split among threads.
fn cotangent_sum(
    v: usize,
    pos: &[Point3],
    tris: &[[u32; 3]],
    r: &Rings,
    per_face: &[([f64; 3], Point3)],
) -> [f64; 4] {
    let mut a = [0.0f64; 4];
    for &f in r.vf.row(v) {
        let (t, w) = (tris[f as usize], per_face[f as usize].0);
        let Some(c) = t.iter().position(|&x| x as usize == v) else { continue };
        // v is the first end of edge c and the second end of edge c − 1 (mod 3): in edge order.
        let (before, at) = ((c + 2) % 3, c);
        for k in if before < at { [before, at] } else { [at, before] } {
            let other = if k == at { t[(k + 1) % 3] } else { t[k] } as usize;
            let w = w[k];
            if w.is_nan() {
                continue;
            }
            a[0] += w * pos[other][0];
            a[1] += w * pos[other][1];
            a[2] += w * pos[other][2];
            a[3] += w;
        }
    }
    a
}

/// Is the face at `pos` turned against its reference `r` (negative), degenerate (zero) or right
/// (positive)? The report's `flipped_faces` test.
fn orientation(pos: &[Point3], t: [u32; 3], r: Point3) -> f64 {
    dot(face_normal(pos, t), r)
}

/// Puts back to `before` (the positions before smoothing) every moved corner of a face that the
/// smoothing turned against its `reference` (or made degenerate) while it was
/// right before, and repeats on the faces that changes, until no face is worse than before (a face
/// thinner than the thinnest before smoothing counts as worse: a corner put back next to
/// neighbours that stay smoothed must not make one). Returns how many vertices were put back.
///
/// Why: the flows' guard ([`Guard::commit`]) compares each step with the face's normal before
/// that step, so a face can turn by small steps over many iterations until it faces away from
/// the surface (a 20k-face icosphere fitted through 90° arcs: 0 flipped faces before smoothing,
/// 1 after, and the untangling after smoothing did not unfold it). Terminates: every round puts
/// back at least one vertex, and a face whose corners are all put back is as it was.
pub fn undo_new_flips(
    pos: &mut [Point3],
    before: &[Point3],
    tris: &[[u32; 3]],
    reference: &impl Reference,
) -> usize {
    // A corner put back next to neighbours that stay smoothed could make a face thinner than any
    // before smoothing: such a face counts as worse too, so the smallest angle never drops.
    let quality =
        |p: &[Point3], t: [u32; 3]| min_angle_quality(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
    let floor = tris.iter().map(|&t| quality(before, t)).fold(f64::INFINITY, f64::min);
    // Each face's reference once (the rounds test every face again).
    let refs: Vec<Point3> = tris.par_iter().with_min_len(4096).map(|&t| reference.face(t)).collect();
    let mut undone = 0;
    loop {
        let mut changed = 0;
        for (&t, &r) in tris.iter().zip(&refs) {
            if t.iter().all(|&v| pos[v as usize] == before[v as usize]) {
                continue;
            }
            let (now, was) = (orientation(pos, t, r), orientation(before, t, r));
            let turned = (now < 0.0 && was >= 0.0) || (now == 0.0 && was > 0.0);
            let worse = turned || {
                let q = quality(pos, t);
                q < floor && q < quality(before, t)
            };
            if !worse {
                continue;
            }
            for &v in &t {
                if pos[v as usize] != before[v as usize] {
                    pos[v as usize] = before[v as usize];
                    changed += 1;
                }
            }
        }
        if changed == 0 {
            return undone;
        }
        undone += changed;
    }
}

/// The product of the two larger of three squared edge lengths (those beside the smallest angle).
pub(super) fn longer_edges_product(la: f64, lb: f64, lc: f64) -> f64 {
    if la <= lb && la <= lc {
        lb * lc
    } else if lb <= lc {
        la * lc
    } else {
        la * lb
    }
}

/// sin² of a face's smallest angle (the corner opposite the shortest edge): |n|² / (|e1|²·|e2|²)
/// with e1, e2 the two longer edges. Monotone in the angle on [0°, 60°], where a smallest angle
/// always is, and free of trigonometry. 0 for a degenerate face.
pub fn min_angle_quality(a: Point3, b: Point3, c: Point3) -> f64 {
    let (la, lb, lc) = (norm2(sub(b, c)), norm2(sub(c, a)), norm2(sub(a, b)));
    let n = norm2(cross(sub(b, a), sub(c, a)));
    let prod = longer_edges_product(la, lb, lc);
    if prod > 0.0 {
        n / prod
    } else {
        0.0
    }
}

fn centroid(pos: &[Point3], t: [u32; 3]) -> Point3 {
    triangle_centroid(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize])
}

/// Closest point on the reference surface near face `start`: walk across the edge opposite the
/// most negative barycentric coordinate of `p`'s projection until it falls inside a face (one
/// triangle test per step; usually 0–2 steps since vertices move little per iteration).
fn closest_by_walk(pos: &[Point3], tris: &[[u32; 3]], r: &Rings, start: u32, p: Point3) -> (u32, Point3) {
    let mut f = start;
    for _ in 0..12 {
        let t = tris[f as usize];
        let a = pos[t[0] as usize];
        let (v0, v1, v2) = (sub(pos[t[1] as usize], a), sub(pos[t[2] as usize], a), sub(p, a));
        let (d00, d01, d11, d20, d21) = (dot(v0, v0), dot(v0, v1), dot(v1, v1), dot(v2, v0), dot(v2, v1));
        let den = d00 * d11 - d01 * d01;
        if den <= 0.0 {
            break;
        }
        let v = (d11 * d20 - d01 * d21) / den;
        let w = (d00 * d21 - d01 * d20) / den;
        let u = 1.0 - v - w;
        // Edge k of a face is (t[k], t[k+1]); the edge opposite corner 0 is 1, and so on.
        let (m, edge) = if u <= v && u <= w {
            (u, 1)
        } else if v <= w {
            (v, 2)
        } else {
            (w, 0)
        };
        if m >= -1e-12 {
            return (f, add(a, add(scale(v0, v), scale(v1, w))));
        }
        let next = r.ff[f as usize][edge];
        if next == u32::MAX {
            break;
        }
        f = next;
    }
    (f, closest_on_triangle(p, tris[f as usize], pos))
}

/// Closest point on triangle `t` to `p`: [`crate::spatial::closest_on_triangle`].
pub fn closest_on_triangle(p: Point3, t: [u32; 3], pos: &[Point3]) -> Point3 {
    crate::spatial::closest_on_triangle(p, &[pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::norm;
    use crate::shapes::icosphere;

    #[test]
    fn a_face_the_smoothing_turned_over_gets_its_moved_corners_back() {
        // Square A(-1,-1) B(1,-1) C(1,1) D(-1,1) around E(0,0), and F(3,0) beyond B–C, all in
        // z = 0 with reference normals +z. Smoothed: E went to (1.5, 0), past the edge B–C, so
        // (B, C, E) turned over (hand: cross((0,2),(0.5,1)) = −1); F went to (2.8, 0), and its
        // face (B, F, C) stays right and fatter (smallest angle 53° → 58°). Only E goes back.
        let before = vec![
            [-1.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
        ];
        let tris = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [1, 5, 2]];
        let reference = vec![[0.0, 0.0, 1.0]; 6];
        let mut pos = before.clone();
        pos[4] = [1.5, 0.0, 0.0];
        pos[5] = [2.8, 0.0, 0.0];
        assert!(orientation(&pos, tris[1], reference.face(tris[1])) < 0.0);
        assert_eq!(undo_new_flips(&mut pos, &before, &tris, &reference), 1);
        assert_eq!(pos[4], before[4]);
        assert_eq!(pos[5], [2.8, 0.0, 0.0]);
        // A face already turned over before smoothing is not the smoothing's doing: left alone
        // (E from (1.5, 0) to (1.45, 0): no face thinner than the thinnest before, 21.8°).
        let mut before2 = before.clone();
        before2[4] = [1.5, 0.0, 0.0];
        let mut pos2 = before2.clone();
        pos2[4] = [1.45, 0.0, 0.0];
        assert_eq!(undo_new_flips(&mut pos2, &before2, &tris, &reference), 0);
        assert_eq!(pos2[4], [1.45, 0.0, 0.0]);
        // F pushed out to (3.5, 0) instead makes (B, F, C) thinner (43.6° at F) than the thinnest
        // face before (45°): it goes back too.
        let mut pos3 = before.clone();
        pos3[4] = [1.5, 0.0, 0.0];
        pos3[5] = [3.5, 0.0, 0.0];
        assert_eq!(undo_new_flips(&mut pos3, &before, &tris, &reference), 2);
        assert_eq!(pos3, before);
    }

    #[test]
    fn undoing_a_corner_that_turns_a_neighbour_over_undoes_the_neighbour_too() {
        // Vertices 0 (0,0), 1 (1,1), 2 (2,0), 3 (3,1) in z = 0, reference +z; faces Y = (1,2,3)
        // (listed first, so the scan meets it before X) and X = (0,2,1). Smoothed: 1 → (1,−0.5),
        // 3 → (1.5, 0). Hand values (z of the cross products): X = cross((2,0),(1,−0.5)) = −1,
        // turned over; Y = cross((1,0.5),(0.5,0.5)) = 0.25, right. Round 1 puts 1 back; then
        // Y = cross((1,−1),(0.5,−1)) = −0.5, turned over, so round 2 puts 3 back.
        let before = vec![[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0], [3.0, 1.0, 0.0]];
        let tris = [[1, 2, 3], [0, 2, 1]];
        let reference = vec![[0.0, 0.0, 1.0]; 4];
        let mut pos = before.clone();
        pos[1] = [1.0, -0.5, 0.0];
        pos[3] = [1.5, 0.0, 0.0];
        assert!(
            orientation(&pos, tris[0], reference.face(tris[0])) > 0.0
                && orientation(&pos, tris[1], reference.face(tris[1])) < 0.0
        );
        assert_eq!(undo_new_flips(&mut pos, &before, &tris, &reference), 2);
        assert_eq!(pos, before);
    }

    #[test]
    fn tangential_flows_keep_a_sphere_and_fixed_vertices() {
        // A unit sphere with its vertices jittered *along* the surface (rotated about random-ish
        // axes by small angles): the flows should even them out and stay on the sphere.
        let s = icosphere(3, 1.0);
        let tris = crate::shapes::fan_triangles(&s.faces);
        let mut pos: Vec<Point3> = s
            .positions
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let k = i as f64;
                let t = normalize(cross(p, [k.sin(), (1.7 * k).cos(), 0.3]));
                let q = add(p, scale(t, 0.04 * (k * 0.37).sin()));
                scale(q, 1.0 / norm(q))
            })
            .collect();
        let fixed: Vec<bool> = (0..pos.len()).map(|i| i % 7 == 0).collect();
        let before = pos.clone();
        let q0 = crate::fit::report::angle_stats(&pos, &tris);
        let settings = SmoothSettings {
            mcf_iterations: 10,
            mcf_step: 0.5,
            laplacian_iterations: 20,
            min_angle_floor_deg: 15.0,
        };
        smooth(&mut pos, &tris, &fixed, &settings, &Progress::new()).unwrap();
        let q1 = crate::fit::report::angle_stats(&pos, &tris);
        for (i, p) in pos.iter().enumerate() {
            if fixed[i] {
                assert_eq!(*p, before[i]);
            }
            // Back-projection keeps vertices on the (inscribed) surface: within the sagitta of a
            // level-3 icosphere (edge ≈ 0.15 → sagitta ≈ 0.003) of the unit sphere.
            assert!((norm(*p) - 1.0).abs() < 0.006, "vertex {i} at radius {}", norm(*p));
        }
        assert!(q1.mean_min_deg > q0.mean_min_deg, "{q0:?} → {q1:?}");
        assert!(q1.min_deg >= q0.min_deg, "{q0:?} → {q1:?}");
        // No face turned against the sphere's outward normal.
        for t in &tris {
            let c = add(add(pos[t[0] as usize], pos[t[1] as usize]), pos[t[2] as usize]);
            assert!(dot(face_normal(&pos, *t), c) > 0.0);
        }
    }
}
