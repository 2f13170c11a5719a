//! Fold-free mean-value relaxation on the sphere: Gauss–Seidel sweeps moving each vertex towards
//! the normalised average of its neighbours with Floater's mean-value weights from the 3D mesh
//! (which lowers angle distortion), accepting only moves that flip no incident face.

use super::opposite_edge;
use super::vertex_split::star_quality;
use crate::error::Result;
use crate::geometry::{add, cross, dot, norm, normalize, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;
use crate::morph::simplify::Hierarchy;

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
pub(super) fn mvc_target(h: &Hierarchy, v: u32, pos: &[Point3], sphere: &[Point3]) -> Point3 {
    let pv = pos[v as usize];
    let mut acc = [0.0; 3];
    for &f in &h.vf[v as usize] {
        let (a, b) = opposite_edge(h.tris[f as usize], v);
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
                let (a, b) = opposite_edge(h.tris[f as usize], v as u32);
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
