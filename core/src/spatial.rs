//! Closest points on a triangle mesh: a bounding-volume hierarchy over the (fan-triangulated)
//! faces, queried depth-first, nearer child first, pruning boxes farther than the best hit.
//!
//! Used for the Hausdorff distance in the smoothing report and for projecting vertices back onto
//! a reference surface (tangential flows). Hand-written (≈150 lines) instead of a dependency.

use rayon::prelude::*;

use crate::error::Result;
use crate::geometry::{add, dot, scale, sub};
use crate::job::Progress;
use crate::mesh::{Faces, Point3};

/// A hit: closest point, the input face it lies on, squared distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    pub point: Point3,
    pub face: u32,
    pub dist2: f64,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    min: Point3,
    max: Point3,
    /// Leaf: first triangle (`count > 0`); inner: index of the left child (right = left + 1).
    start: u32,
    count: u32,
}

/// BVH over the triangles of a mesh (polygons are fan-triangulated; hits report the input face).
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<[Point3; 3]>,
    face_of: Vec<u32>,
}

const LEAF: usize = 4;

/// Work (triangles sorted or queried) between two polls of `progress.check()`: a few ms.
const POLL_WORK: usize = 1 << 15;

impl Bvh {
    pub fn new(positions: &[Point3], faces: &Faces) -> Bvh {
        match Self::build(positions, faces, || Ok::<(), std::convert::Infallible>(())) {
            Ok(b) => b,
            Err(never) => match never {},
        }
    }

    /// [`Bvh::new`] polling `progress` while it builds (a 300k-triangle tree takes ~100 ms).
    pub fn new_polled(positions: &[Point3], faces: &Faces, progress: &Progress) -> Result<Bvh> {
        Self::build(positions, faces, || progress.check())
    }

    /// The build, calling `poll` every [`POLL_WORK`] triangles of splitting work.
    fn build<E>(
        positions: &[Point3],
        faces: &Faces,
        mut poll: impl FnMut() -> Result<(), E>,
    ) -> Result<Bvh, E> {
        let mut tris = Vec::with_capacity(faces.len());
        let mut face_of = Vec::with_capacity(faces.len());
        for (fi, f) in faces.iter().enumerate() {
            for k in 1..f.len().saturating_sub(1) {
                tris.push([positions[f[0] as usize], positions[f[k] as usize], positions[f[k + 1] as usize]]);
                face_of.push(fi as u32);
            }
        }
        let mut order: Vec<u32> = (0..tris.len() as u32).collect();
        let centroids: Vec<Point3> =
            tris.iter().map(|t| scale(add(add(t[0], t[1]), t[2]), 1.0 / 3.0)).collect();
        let mut nodes = Vec::with_capacity(2 * tris.len() / LEAF + 1);
        nodes.push(Node { min: [0.0; 3], max: [0.0; 3], start: 0, count: 0 });
        // Iterative build: (node index, range in `order`).
        let mut stack = vec![(0usize, 0usize, order.len())];
        let mut leaf = vec![false];
        let mut work = 0;
        while let Some((ni, lo, hi)) = stack.pop() {
            work += hi - lo;
            if work >= POLL_WORK {
                work = 0;
                poll()?;
            }
            if hi - lo <= LEAF {
                // The boxes are filled in below, from the leaves up.
                nodes[ni].start = lo as u32;
                nodes[ni].count = (hi - lo) as u32;
                leaf[ni] = true;
                continue;
            }
            let (mut cmin, mut cmax) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for &t in &order[lo..hi] {
                let c = centroids[t as usize];
                for k in 0..3 {
                    cmin[k] = cmin[k].min(c[k]);
                    cmax[k] = cmax[k].max(c[k]);
                }
            }
            let ext = sub(cmax, cmin);
            let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
                0
            } else if ext[1] >= ext[2] {
                1
            } else {
                2
            };
            let mid = (lo + hi) / 2;
            order[lo..hi].select_nth_unstable_by(mid - lo, |a, b| {
                centroids[*a as usize][axis].total_cmp(&centroids[*b as usize][axis])
            });
            let left = nodes.len();
            nodes.push(Node { min: [0.0; 3], max: [0.0; 3], start: 0, count: 0 });
            nodes.push(Node { min: [0.0; 3], max: [0.0; 3], start: 0, count: 0 });
            leaf.extend([false, false]);
            nodes[ni].start = left as u32;
            nodes[ni].count = 0;
            stack.push((left, lo, mid));
            stack.push((left + 1, mid, hi));
        }
        // Boxes from the leaves up (children come after their parent): each triangle is read once,
        // not once per level (~16 levels on the headline's 194k faces). Min and max are exact, so
        // a box is the same as over its triangles directly.
        for ni in (0..nodes.len()).rev() {
            let (mut bmin, mut bmax) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            if leaf[ni] {
                let (start, count) = (nodes[ni].start as usize, nodes[ni].count as usize);
                for &t in &order[start..start + count] {
                    for p in &tris[t as usize] {
                        for k in 0..3 {
                            bmin[k] = bmin[k].min(p[k]);
                            bmax[k] = bmax[k].max(p[k]);
                        }
                    }
                }
            } else {
                let left = nodes[ni].start as usize;
                for child in [left, left + 1] {
                    for k in 0..3 {
                        bmin[k] = bmin[k].min(nodes[child].min[k]);
                        bmax[k] = bmax[k].max(nodes[child].max[k]);
                    }
                }
            }
            nodes[ni].min = bmin;
            nodes[ni].max = bmax;
        }
        let tris_sorted = order.iter().map(|&t| tris[t as usize]).collect();
        let face_sorted = order.iter().map(|&t| face_of[t as usize]).collect();
        Ok(Bvh { nodes, tris: tris_sorted, face_of: face_sorted })
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The closest point of the surface to `p`: None for a mesh without faces, and when no
    /// distance to `p` is finite (`p` is not finite, or so far away that its squared distance
    /// overflows), rather than an answer with face `u32::MAX` for callers to index with.
    pub fn closest(&self, p: Point3) -> Option<Closest> {
        if self.tris.is_empty() {
            return None;
        }
        let mut slot = 0;
        let best =
            self.closest_search(p, Closest { point: p, face: u32::MAX, dist2: f64::INFINITY }, &mut slot);
        (best.face != u32::MAX).then_some(best)
    }

    /// [`Bvh::closest`] starting from a guess: `hint` is an index into this BVH's triangles (the
    /// `slot` of an earlier answer). The guess only tightens the initial bound, so the answer is
    /// the same; for a run of nearby query points (the previous answer's slot as hint) most of
    /// the tree is pruned at once.
    pub fn closest_hinted(&self, p: Point3, hint: u32) -> Option<(Closest, u32)> {
        if self.tris.is_empty() {
            return None;
        }
        let h = (hint as usize).min(self.tris.len() - 1);
        let q = closest_on_triangle(p, &self.tris[h]);
        let start = Closest { point: q, face: self.face_of[h], dist2: dot(sub(q, p), sub(q, p)) };
        let mut slot = h as u32;
        let best = self.closest_search(p, start, &mut slot);
        Some((best, slot))
    }

    fn closest_search(&self, p: Point3, start: Closest, slot: &mut u32) -> Closest {
        let mut best = start;
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(ni) = stack.pop() {
            let node = &self.nodes[ni as usize];
            if box_dist2(node, p) >= best.dist2 {
                continue;
            }
            if node.count > 0 {
                for t in node.start..node.start + node.count {
                    let q = closest_on_triangle(p, &self.tris[t as usize]);
                    let d = dot(sub(q, p), sub(q, p));
                    if d < best.dist2 {
                        best = Closest { point: q, face: self.face_of[t as usize], dist2: d };
                        *slot = t;
                    }
                }
            } else {
                let (l, r) = (node.start, node.start + 1);
                let (dl, dr) = (box_dist2(&self.nodes[l as usize], p), box_dist2(&self.nodes[r as usize], p));
                // Push the farther child first so the nearer one is explored first.
                if dl < dr {
                    stack.push(r);
                    stack.push(l);
                } else {
                    stack.push(l);
                    stack.push(r);
                }
            }
        }
        best
    }

    /// Largest distance from any of `points` to the surface (0 for no points or no faces).
    pub fn max_distance(&self, points: &[Point3]) -> f64 {
        match self.max_dist2_with(points, || Ok::<(), std::convert::Infallible>(())) {
            Ok(d2) => d2.sqrt(),
            Err(never) => match never {},
        }
    }

    /// Largest squared distance from any of `points` to the surface (0 for no points or no
    /// faces), polling `progress` between chunks of queries.
    pub fn max_distance2(&self, points: &[Point3], progress: &Progress) -> Result<f64> {
        self.max_dist2_with(points, || progress.check())
    }

    /// Parallel chunks calling `poll` first. Within a chunk each query starts from the previous
    /// answer ([`Bvh::closest_hinted`]): points in mesh order follow their neighbours, so the hint
    /// prunes most of the tree.
    fn max_dist2_with<E: Send>(
        &self,
        points: &[Point3],
        poll: impl Fn() -> Result<(), E> + Sync,
    ) -> Result<f64, E> {
        points
            .par_chunks(4096)
            .map(|chunk| {
                poll()?;
                let mut slot = 0;
                let mut m = 0.0f64;
                for &p in chunk {
                    if let Some((h, s)) = self.closest_hinted(p, slot) {
                        slot = s;
                        m = m.max(h.dist2);
                    }
                }
                Ok(m)
            })
            .try_reduce(|| 0.0, |a, b| Ok(a.max(b)))
    }
}

fn box_dist2(n: &Node, p: Point3) -> f64 {
    let mut d = 0.0;
    for k in 0..3 {
        let v = (n.min[k] - p[k]).max(0.0).max(p[k] - n.max[k]);
        d += v * v;
    }
    d
}

/// Closest point on triangle `t` to `p` (Ericson, Real-Time Collision Detection §5.1.5).
pub fn closest_on_triangle(p: Point3, t: &[Point3; 3]) -> Point3 {
    let [a, b, c] = *t;
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return add(a, scale(ab, v));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return add(a, scale(ac, w));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return add(b, scale(sub(c, b), w));
    }
    let denom = va + vb + vc;
    if denom.abs() < f64::MIN_POSITIVE {
        // Degenerate triangle: fall back to the nearest vertex.
        let da = dot(ap, ap);
        let db = dot(bp, bp);
        let dc = dot(cp, cp);
        return if da <= db && da <= dc {
            a
        } else if db <= dc {
            b
        } else {
            c
        };
    }
    let v = vb / denom;
    let w = vc / denom;
    add(a, add(scale(ab, v), scale(ac, w)))
}

/// Symmetric Hausdorff distance between two surfaces, sampled at their vertices: the larger of
/// max over A's vertices of the distance to surface B and vice versa. (Vertex sampling bounds
/// the true Hausdorff distance from below; for smoothing, where both surfaces share connectivity,
/// the two agree closely.) Vertices no face uses are not part of a surface and are skipped.
pub fn hausdorff_vertices(
    a: &[Point3],
    fa: &Faces,
    b: &[Point3],
    fb: &Faces,
    progress: &Progress,
) -> Result<f64> {
    let used = |x: &[Point3], f: &Faces| -> Vec<Point3> {
        let mut mark = vec![false; x.len()];
        for &v in f.indices() {
            if let Some(m) = mark.get_mut(v as usize) {
                *m = true;
            }
        }
        x.iter().zip(&mark).filter(|(_, m)| **m).map(|(p, _)| *p).collect()
    };
    let (ba, bb) = rayon::join(|| Bvh::new_polled(a, fa, progress), || Bvh::new_polled(b, fb, progress));
    let (ba, bb) = (ba?, bb?);
    let (d1, d2) =
        rayon::join(|| bb.max_distance2(&used(a, fa), progress), || ba.max_distance2(&used(b, fb), progress));
    Ok(d1?.max(d2?).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::norm;
    use crate::shapes::{grid, icosphere};

    #[test]
    fn hinted_query_gives_the_same_distance_as_the_plain_one() {
        // Any hint, good or bad, only changes where the search starts.
        let m = icosphere(3, 1.0);
        let bvh = Bvh::new(&m.positions, &m.faces);
        let mut slot = 0;
        for k in 0..200 {
            let t = k as f64 * 0.37;
            let p = [1.3 * t.cos(), 0.9 * (1.7 * t).sin(), 0.5 * t.sin()];
            let a = bvh.closest(p).unwrap();
            let (b, s) = bvh.closest_hinted(p, if k % 3 == 0 { 17 * k } else { slot }).unwrap();
            slot = s;
            assert_eq!(a.dist2, b.dist2, "query {k}");
        }
    }

    #[test]
    fn closest_point_regions_of_a_triangle() {
        let t = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]];
        let q = closest_on_triangle([0.2, 0.2, 5.0], &t);
        assert!((q[0] - 0.2).abs() < 1e-15 && (q[1] - 0.2).abs() < 1e-15 && q[2] == 0.0);
        assert_eq!(closest_on_triangle([-1., -1., 0.], &t), [0., 0., 0.]);
        assert_eq!(closest_on_triangle([0.5, -2., 1.], &t), [0.5, 0., 0.]);
        let q = closest_on_triangle([1., 1., 0.], &t);
        assert!((q[0] - 0.5).abs() < 1e-15 && (q[1] - 0.5).abs() < 1e-15);
    }

    #[test]
    fn bvh_matches_brute_force_on_a_sphere() {
        let m = icosphere(3, 1.0);
        let bvh = Bvh::new(&m.positions, &m.faces);
        let tris = crate::shapes::fan_triangles(&m.faces);
        for k in 0..200 {
            let a = k as f64 * 0.731;
            let p = [2.0 * a.cos() * (0.3 * a).sin(), 1.5 * a.sin(), 0.7 * (1.7 * a).cos()];
            let hit = bvh.closest(p).unwrap();
            let brute = tris
                .iter()
                .map(|t| {
                    let q = closest_on_triangle(
                        p,
                        &[m.positions[t[0] as usize], m.positions[t[1] as usize], m.positions[t[2] as usize]],
                    );
                    dot(sub(q, p), sub(q, p))
                })
                .fold(f64::INFINITY, f64::min);
            assert!((hit.dist2 - brute).abs() < 1e-14, "{} vs {brute}", hit.dist2);
        }
    }

    #[test]
    fn hausdorff_of_a_lifted_plane() {
        let a = grid(8, 8, 0.25, false);
        let mut b = a.clone();
        b.positions[40][2] = 0.3; // one interior vertex lifted
        let p = Progress::new();
        let h = hausdorff_vertices(&a.positions, &a.faces, &b.positions, &b.faces, &p).unwrap();
        assert!((h - 0.3).abs() < 1e-15, "{h}");
        assert_eq!(hausdorff_vertices(&a.positions, &a.faces, &a.positions, &a.faces, &p).unwrap(), 0.0);
        let _ = norm([0.0; 3]);
    }
}
