//! Placing a vertex that a vertex split returns to the sphere: inside the exact kernel of its
//! star (the region where every incident face is positively oriented), at the candidate with the
//! best worst-triangle shape, so the map stays an embedding by construction; and the local
//! smoothing that widens thin triangles when no position is found.

use std::f64::consts::PI;

use super::opposite_edge;
use super::relax::mvc_target;
use crate::error::{Error, Result};
use crate::geometry::{add, cross, dot, norm, normalize, scale, sub};
use crate::mesh::Point3;
use crate::morph::simplify::Hierarchy;

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
    h.vf[v as usize].iter().map(|&f| opposite_edge(h.tris[f as usize], v)).collect()
}

/// Worst shape quality of the faces around `x` if valid (all positively oriented), else None.
#[inline]
pub(super) fn star_quality(x: Point3, ring: &[(Point3, Point3, Point3)]) -> Option<f64> {
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
    star_of(&ring_pairs(h, v), sphere)
}

/// [`star`] from the ring's (a, b) pairs.
fn star_of(pairs: &[(u32, u32)], sphere: &[Point3]) -> Vec<(Point3, Point3, Point3)> {
    pairs
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
pub(super) fn smooth_around(
    h: &Hierarchy,
    v: u32,
    radius: usize,
    sweeps: usize,
    pos: &[Point3],
    sphere: &mut [Point3],
) {
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

/// The best valid position seen so far for a vertex whose star is `ring` (best = highest
/// worst-face shape quality; the first of equals is kept).
struct BestPosition<'a> {
    ring: &'a [(Point3, Point3, Point3)],
    best: Option<(f64, Point3)>,
}

impl BestPosition<'_> {
    fn consider(&mut self, x: Point3) {
        if let Some(q) = star_quality(x, self.ring) {
            if self.best.is_none_or(|(bq, _)| q > bq) {
                self.best = Some((q, x));
            }
        }
    }

    fn found(&self) -> bool {
        self.best.is_some()
    }
}

/// Places the vertex `vt` just re-inserted by the split of `vs`.
///
/// The mean-value target first (it usually wins and lowers distortion), then points of the
/// exact kernel of vt's star; only when the kernel cannot be computed (a ring wider than a
/// hemisphere, near the tetrahedron) the lattice over the fan around vs that covered vt's
/// region before the split; then, while nothing is valid, points ever closer to vs.
pub(super) fn place_split(
    h: &Hierarchy,
    vt: u32,
    vs: u32,
    pos: &[Point3],
    sphere: &mut [Point3],
) -> Result<()> {
    let pairs = ring_pairs(h, vt);
    let ring = star_of(&pairs, sphere);
    let mut best = BestPosition { ring: &ring, best: None };
    let target = mvc_target(h, vt, pos, sphere);
    best.consider(target);
    let mut cands = Vec::with_capacity(4);
    if kernel_candidates(&ring, target, &mut cands) {
        for x in cands {
            best.consider(x);
        }
    } else {
        consider_fan_lattice(&mut best, &pairs, vs, sphere);
    }
    consider_around(&mut best, sphere[vs as usize]);
    consider_towards_ring(&mut best, &pairs, vs, sphere);
    match best.best {
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

/// A barycentric lattice over each fan triangle (vs, a, b) of the ring that does not touch vs.
fn consider_fan_lattice(best: &mut BestPosition, pairs: &[(u32, u32)], vs: u32, sphere: &[Point3]) {
    let ps = sphere[vs as usize];
    for &(a, b) in pairs {
        if a == vs || b == vs {
            continue;
        }
        let (pa, pb) = (sphere[a as usize], sphere[b as usize]);
        const L: usize = 4;
        for i in 1..=L {
            for j in 0..=(L - i) {
                let k = L - i - j;
                let x = add(add(scale(ps, i as f64), scale(pa, j as f64)), scale(pb, k as f64));
                best.consider(normalize(x));
            }
        }
    }
}

/// Last resort, while nothing is valid: every direction around `ps` (vs) at shrinking distances
/// (the valid wedge at vs can be narrow and lie across a thin fan triangle).
fn consider_around(best: &mut BestPosition, ps: Point3) {
    let mut eps = 0.25;
    let e1 =
        normalize(if ps[0].abs() < 0.9 { cross(ps, [1.0, 0.0, 0.0]) } else { cross(ps, [0.0, 1.0, 0.0]) });
    let e2 = cross(ps, e1);
    while !best.found() && eps > 1e-13 {
        for d in 0..256 {
            let th = d as f64 * (2.0 * PI / 256.0);
            best.consider(normalize(add(ps, add(scale(e1, eps * th.cos()), scale(e2, eps * th.sin())))));
        }
        eps *= 0.25;
    }
}

/// Still nothing valid: points from vs ever closer to it, towards several points across each fan
/// triangle and towards each neighbour.
fn consider_towards_ring(best: &mut BestPosition, pairs: &[(u32, u32)], vs: u32, sphere: &[Point3]) {
    let ps = sphere[vs as usize];
    let mut eps = 0.25;
    while !best.found() && eps > 1e-12 {
        for &(a, b) in pairs {
            if a == vs || b == vs {
                continue;
            }
            // Several directions across the fan triangle: the valid wedge at vs may be narrow.
            for w in 1..16 {
                let w = w as f64 / 16.0;
                let m = add(scale(sphere[a as usize], w), scale(sphere[b as usize], 1.0 - w));
                best.consider(normalize(add(scale(ps, 1.0 - eps), scale(m, eps))));
            }
        }
        for &(a, b) in pairs {
            let other = if a == vs {
                b
            } else if b == vs {
                a
            } else {
                continue;
            };
            best.consider(normalize(add(scale(ps, 1.0 - eps), scale(sphere[other as usize], eps))));
        }
        eps *= 0.25;
    }
}
