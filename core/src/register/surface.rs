//! Closest point on a triangle surface: a bounding-volume hierarchy over the triangles (a k-d
//! style median split on the longest axis), queried by best-first descent. Used by ICP
//! (point-to-plane pairs) and by the morph report (Hausdorff distances).

use crate::geometry::{add, cross, dot, scale, sub};
use crate::mesh::Point3;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: Point3,
    max: Point3,
    /// Leaf: first triangle index in `order`, count; inner: left child, right child (count = 0).
    a: u32,
    b: u32,
    count: u32,
}

/// The answer to a closest-point query.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub dist2: f64,
    pub face: u32,
    pub point: Point3,
}

pub struct SurfaceIndex {
    pos: Vec<Point3>,
    tris: Vec<[u32; 3]>,
    order: Vec<u32>,
    nodes: Vec<Node>,
}

const LEAF: usize = 4;

impl SurfaceIndex {
    pub fn new(pos: &[Point3], tris: &[[u32; 3]]) -> SurfaceIndex {
        let centroids: Vec<Point3> = tris
            .iter()
            .map(|t| scale(add(add(pos[t[0] as usize], pos[t[1] as usize]), pos[t[2] as usize]), 1.0 / 3.0))
            .collect();
        let mut s = SurfaceIndex {
            pos: pos.to_vec(),
            tris: tris.to_vec(),
            order: (0..tris.len() as u32).collect(),
            nodes: Vec::with_capacity(2 * tris.len() / LEAF + 2),
        };
        if !tris.is_empty() {
            s.build(0, tris.len(), &centroids);
        }
        s
    }

    fn bounds(&self, lo: usize, hi: usize) -> (Point3, Point3) {
        let mut mn = [f64::INFINITY; 3];
        let mut mx = [f64::NEG_INFINITY; 3];
        for &f in &self.order[lo..hi] {
            for &v in &self.tris[f as usize] {
                let p = self.pos[v as usize];
                for k in 0..3 {
                    mn[k] = mn[k].min(p[k]);
                    mx[k] = mx[k].max(p[k]);
                }
            }
        }
        (mn, mx)
    }

    fn build(&mut self, lo: usize, hi: usize, c: &[Point3]) -> u32 {
        let (min, max) = self.bounds(lo, hi);
        let id = self.nodes.len();
        self.nodes.push(Node { min, max, a: lo as u32, b: 0, count: (hi - lo) as u32 });
        if hi - lo <= LEAF {
            return id as u32;
        }
        let ext = sub(max, min);
        let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
            0
        } else if ext[1] >= ext[2] {
            1
        } else {
            2
        };
        let mid = (lo + hi) / 2;
        self.order[lo..hi].select_nth_unstable_by(mid - lo, |&x, &y| {
            c[x as usize][axis].partial_cmp(&c[y as usize][axis]).unwrap_or(std::cmp::Ordering::Equal)
        });
        let l = self.build(lo, mid, c);
        let r = self.build(mid, hi, c);
        self.nodes[id] = Node { min, max, a: l, b: r, count: 0 };
        id as u32
    }

    fn box_dist2(n: &Node, p: Point3) -> f64 {
        let mut d = 0.0;
        for k in 0..3 {
            let e = (n.min[k] - p[k]).max(0.0).max(p[k] - n.max[k]);
            d += e * e;
        }
        d
    }

    /// The closest point of the surface to `p`; None for an empty surface.
    pub fn closest(&self, p: Point3) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = Hit { dist2: f64::INFINITY, face: u32::MAX, point: p };
        let mut stack: Vec<(f64, u32)> = Vec::with_capacity(64);
        stack.push((Self::box_dist2(&self.nodes[0], p), 0));
        while let Some((d, id)) = stack.pop() {
            if d >= best.dist2 {
                continue;
            }
            let n = self.nodes[id as usize];
            if n.count > 0 {
                for &f in &self.order[n.a as usize..(n.a + n.count) as usize] {
                    let t = self.tris[f as usize];
                    let q = closest_on_triangle(
                        p,
                        self.pos[t[0] as usize],
                        self.pos[t[1] as usize],
                        self.pos[t[2] as usize],
                    );
                    let d2 = dot(sub(q, p), sub(q, p));
                    if d2 < best.dist2 {
                        best = Hit { dist2: d2, face: f, point: q };
                    }
                }
            } else {
                let (l, r) = (n.a, n.b);
                let dl = Self::box_dist2(&self.nodes[l as usize], p);
                let dr = Self::box_dist2(&self.nodes[r as usize], p);
                // Push the farther child first so the nearer is explored first.
                if dl < dr {
                    stack.push((dr, r));
                    stack.push((dl, l));
                } else {
                    stack.push((dl, l));
                    stack.push((dr, r));
                }
            }
        }
        Some(best)
    }

    /// Unit normal of face `f` (zero for a degenerate face).
    pub fn face_normal(&self, f: u32) -> Point3 {
        let t = self.tris[f as usize];
        crate::geometry::normalize(cross(
            sub(self.pos[t[1] as usize], self.pos[t[0] as usize]),
            sub(self.pos[t[2] as usize], self.pos[t[0] as usize]),
        ))
    }
}

/// Closest point to `p` on triangle (a, b, c): [`crate::spatial::closest_on_triangle`].
pub fn closest_on_triangle(p: Point3, a: Point3, b: Point3, c: Point3) -> Point3 {
    crate::spatial::closest_on_triangle(p, &[a, b, c])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::norm;

    #[test]
    fn closest_point_on_icosphere_matches_brute_force() {
        let m = crate::shapes::icosphere(2, 1.0);
        let tris = crate::shapes::fan_triangles(&m.faces);
        let idx = SurfaceIndex::new(&m.positions, &tris);
        for k in 0..50 {
            let t = k as f64 * 0.37;
            let p = [1.7 * t.cos(), 0.3 * t.sin() - 0.5, (0.7 * t).sin() * 1.2];
            let hit = idx.closest(p).unwrap();
            let brute = tris
                .iter()
                .map(|t| {
                    let q = closest_on_triangle(
                        p,
                        m.positions[t[0] as usize],
                        m.positions[t[1] as usize],
                        m.positions[t[2] as usize],
                    );
                    dot(sub(q, p), sub(q, p))
                })
                .fold(f64::INFINITY, f64::min);
            assert!((hit.dist2 - brute).abs() < 1e-12, "{} vs {}", hit.dist2, brute);
        }
    }

    #[test]
    fn closest_on_triangle_regions() {
        let (a, b, c) = ([0., 0., 0.], [1., 0., 0.], [0., 1., 0.]);
        let q = closest_on_triangle([0.2, 0.2, 5.0], a, b, c);
        assert!(norm(sub(q, [0.2, 0.2, 0.0])) < 1e-15, "{q:?}");
        assert_eq!(closest_on_triangle([-1.0, -1.0, 0.0], a, b, c), a);
        assert_eq!(closest_on_triangle([0.5, -2.0, 1.0], a, b, c), [0.5, 0.0, 0.0]);
        let q = closest_on_triangle([1.0, 1.0, 0.0], a, b, c);
        assert!((q[0] - 0.5).abs() < 1e-15 && (q[1] - 0.5).abs() < 1e-15);
    }
}
