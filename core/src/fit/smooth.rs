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

use rayon::prelude::*;

use crate::error::Result;
use crate::geometry::{add, cross, dot, norm2, normalize, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;

pub struct SmoothSettings {
    pub mcf_iterations: u32,
    pub mcf_step: f64,
    pub laplacian_iterations: u32,
}

/// Compressed vertex → neighbours and vertex → faces.
struct Rings {
    /// Face across edge k (t[k], t[k+1]) of each face, u32::MAX on the boundary.
    ff: Vec<[u32; 3]>,
    nb_off: Vec<u32>,
    nb: Vec<u32>,
    vf_off: Vec<u32>,
    vf: Vec<u32>,
}

fn rings(nv: usize, tris: &[[u32; 3]]) -> Rings {
    let mut vf_cnt = vec![0u32; nv + 1];
    for t in tris {
        for &v in t {
            vf_cnt[v as usize + 1] += 1;
        }
    }
    for i in 0..nv {
        vf_cnt[i + 1] += vf_cnt[i];
    }
    let mut vf = vec![0u32; vf_cnt[nv] as usize];
    let mut fill = vf_cnt.clone();
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            vf[fill[v as usize] as usize] = f as u32;
            fill[v as usize] += 1;
        }
    }
    let mut nb_off = vec![0u32; nv + 1];
    let mut nb = Vec::with_capacity(vf.len());
    for v in 0..nv {
        let start = nb.len();
        for &f in &vf[vf_cnt[v] as usize..vf_cnt[v + 1] as usize] {
            for &w in &tris[f as usize] {
                if w as usize != v && !nb[start..].contains(&w) {
                    nb.push(w);
                }
            }
        }
        nb_off[v + 1] = nb.len() as u32;
    }
    let mut half: super::trimesh::IntMap<(u32, u32), u32> = super::trimesh::IntMap::default();
    half.reserve(tris.len() * 3);
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            half.insert((t[k], t[(k + 1) % 3]), f as u32);
        }
    }
    let ff = tris
        .iter()
        .map(|t| std::array::from_fn(|k| *half.get(&(t[(k + 1) % 3], t[k])).unwrap_or(&u32::MAX)))
        .collect();
    Rings { ff, nb_off, nb, vf_off: vf_cnt, vf }
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
) -> Result<()> {
    let nv = pos.len();
    let r = rings(nv, tris);
    let total = (s.mcf_iterations + s.laplacian_iterations).max(1) as f64;
    // Stage 1: modified mean-curvature flow.
    for it in 0..s.mcf_iterations {
        progress.fraction(it as f64 / total)?;
        // Cotangent weights per vertex pair, accumulated face by face.
        let mut acc = vec![[0.0f64; 4]; nv]; // Σ w·q (3) and Σ w
        for t in tris {
            for k in 0..3 {
                let (i, j, o) = (t[k] as usize, t[(k + 1) % 3] as usize, t[(k + 2) % 3] as usize);
                let (u, v) = (sub(pos[i], pos[o]), sub(pos[j], pos[o]));
                let cr = norm2(cross(u, v)).sqrt();
                if cr <= 0.0 {
                    continue;
                }
                // Negative cotangents (obtuse corners) are clamped: they make the step leave the ring.
                let w = (dot(u, v) / cr).max(0.0) * 0.5;
                for (a, b) in [(i, j), (j, i)] {
                    acc[a][0] += w * pos[b][0];
                    acc[a][1] += w * pos[b][1];
                    acc[a][2] += w * pos[b][2];
                    acc[a][3] += w;
                }
            }
        }
        let old = pos.to_vec();
        pos.par_iter_mut().enumerate().for_each(|(v, p)| {
            if fixed[v] || acc[v][3] <= 0.0 {
                return;
            }
            let target = scale([acc[v][0], acc[v][1], acc[v][2]], 1.0 / acc[v][3]);
            let faces = &r.vf[r.vf_off[v] as usize..r.vf_off[v + 1] as usize];
            let mut n = [0.0; 3];
            for &f in faces {
                n = add(n, face_normal(&old, tris[f as usize]));
            }
            let n = normalize(n);
            let d = scale(sub(target, old[v]), s.mcf_step);
            let moved = add(old[v], sub(d, scale(n, dot(d, n))));
            // Drop back onto the plane of the nearest incident face (current surface).
            let best = faces.iter().min_by(|&&a, &&b| {
                let ca = centroid(&old, tris[a as usize]);
                let cb = centroid(&old, tris[b as usize]);
                norm2(sub(ca, moved)).total_cmp(&norm2(sub(cb, moved)))
            });
            *p = match best {
                Some(&f) => {
                    let fnorm = normalize(face_normal(&old, tris[f as usize]));
                    let o = old[tris[f as usize][0] as usize];
                    sub(moved, scale(fnorm, dot(sub(moved, o), fnorm)))
                }
                None => moved,
            };
        });
    }
    // Stage 2: modified Laplacian flow, back-projected onto the reference (pre-stage-2) surface.
    let reference = pos.to_vec();
    let mut ref_face: Vec<u32> = (0..nv)
        .map(|v| if r.vf_off[v] < r.vf_off[v + 1] { r.vf[r.vf_off[v] as usize] } else { u32::MAX })
        .collect();
    for it in 0..s.laplacian_iterations {
        progress.fraction((s.mcf_iterations + it) as f64 / total)?;
        let old = pos.to_vec();
        pos.par_iter_mut().zip(ref_face.par_iter_mut()).enumerate().for_each(|(v, (p, rf))| {
            let nbs = &r.nb[r.nb_off[v] as usize..r.nb_off[v + 1] as usize];
            if fixed[v] || nbs.is_empty() || *rf == u32::MAX {
                return;
            }
            let mut m = [0.0; 3];
            for &w in nbs {
                m = add(m, old[w as usize]);
            }
            let m = scale(m, 1.0 / nbs.len() as f64);
            let n = normalize(face_normal(&reference, tris[*rf as usize]));
            let d = sub(m, old[v]);
            let moved = add(old[v], sub(d, scale(n, dot(d, n))));
            let (f, q) = closest_by_walk(&reference, tris, &r, *rf, moved);
            *rf = f;
            *p = q;
        });
    }
    Ok(())
}

fn centroid(pos: &[Point3], t: [u32; 3]) -> Point3 {
    scale(add(add(pos[t[0] as usize], pos[t[1] as usize]), pos[t[2] as usize]), 1.0 / 3.0)
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
        let settings = SmoothSettings { mcf_iterations: 10, mcf_step: 0.5, laplacian_iterations: 20 };
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
    }
}
