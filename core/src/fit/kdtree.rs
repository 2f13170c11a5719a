//! A static k-d tree over points: nearest neighbour with a filter (the correspondence step asks for
//! "the nearest template vertex nobody has claimed yet"). Private to the fit job until
//! `core::spatial` offers the same query.

use crate::mesh::Point3;

const LEAF: usize = 12;

struct Node {
    /// Range of `idx` this node covers.
    lo: u32,
    hi: u32,
    /// Split axis and value; `axis == 3` marks a leaf.
    axis: u8,
    split: f64,
    left: u32,
    right: u32,
}

pub struct KdTree {
    pts: Vec<Point3>,
    idx: Vec<u32>,
    nodes: Vec<Node>,
}

impl KdTree {
    pub fn new(points: &[Point3]) -> Self {
        let mut t =
            KdTree { pts: points.to_vec(), idx: (0..points.len() as u32).collect(), nodes: Vec::new() };
        if !points.is_empty() {
            t.build(0, points.len());
        }
        t
    }

    fn build(&mut self, lo: usize, hi: usize) -> u32 {
        let id = self.nodes.len() as u32;
        self.nodes.push(Node { lo: lo as u32, hi: hi as u32, axis: 3, split: 0.0, left: 0, right: 0 });
        if hi - lo <= LEAF {
            return id;
        }
        let (mut mn, mut mx) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for &i in &self.idx[lo..hi] {
            let p = self.pts[i as usize];
            for k in 0..3 {
                mn[k] = mn[k].min(p[k]);
                mx[k] = mx[k].max(p[k]);
            }
        }
        let axis = (0..3).max_by(|&a, &b| (mx[a] - mn[a]).total_cmp(&(mx[b] - mn[b]))).unwrap_or(0);
        let mid = (lo + hi) / 2;
        let pts = &self.pts;
        self.idx[lo..hi].select_nth_unstable_by(mid - lo, |&a, &b| {
            pts[a as usize][axis].total_cmp(&pts[b as usize][axis])
        });
        let split = self.pts[self.idx[mid] as usize][axis];
        let left = self.build(lo, mid);
        let right = self.build(mid, hi);
        let n = &mut self.nodes[id as usize];
        n.axis = axis as u8;
        n.split = split;
        n.left = left;
        n.right = right;
        id
    }

    /// Nearest point index accepted by `keep`, with its squared distance.
    pub fn nearest_filtered(&self, q: Point3, keep: impl Fn(u32) -> bool) -> Option<(u32, f64)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = (u32::MAX, f64::INFINITY);
        self.search(0, q, &keep, &mut best);
        (best.0 != u32::MAX).then_some(best)
    }

    pub fn nearest(&self, q: Point3) -> Option<(u32, f64)> {
        self.nearest_filtered(q, |_| true)
    }

    fn search(&self, node: u32, q: Point3, keep: &impl Fn(u32) -> bool, best: &mut (u32, f64)) {
        let n = &self.nodes[node as usize];
        if n.axis == 3 {
            for &i in &self.idx[n.lo as usize..n.hi as usize] {
                let p = self.pts[i as usize];
                let d = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                if d < best.1 && keep(i) {
                    *best = (i, d);
                }
            }
            return;
        }
        let diff = q[n.axis as usize] - n.split;
        let (near, far) = if diff < 0.0 { (n.left, n.right) } else { (n.right, n.left) };
        self.search(near, q, keep, best);
        if diff * diff < best.1 {
            self.search(far, q, keep, best);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_brute_force_with_and_without_filter() {
        // Deterministic pseudo-random points (LCG) so the test needs no RNG crate.
        let mut s = 12345u64;
        let mut rnd = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let pts: Vec<Point3> = (0..2000).map(|_| [rnd(), rnd(), rnd()]).collect();
        let t = KdTree::new(&pts);
        for _ in 0..200 {
            let q = [rnd(), rnd(), rnd()];
            let keep = |i: u32| i % 3 != 0;
            let brute = (0..pts.len() as u32)
                .filter(|&i| keep(i))
                .map(|i| (i, crate::geometry::norm2(crate::geometry::sub(pts[i as usize], q))))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert_eq!(t.nearest_filtered(q, keep).unwrap().0, brute.0);
            let b2 = (0..pts.len() as u32)
                .map(|i| (i, crate::geometry::norm2(crate::geometry::sub(pts[i as usize], q))))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert_eq!(t.nearest(q).unwrap().0, b2.0);
        }
    }
}
