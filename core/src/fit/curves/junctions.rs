//! The junction steps of the network build: near-duplicate merges, T-junctions and crossings
//! without a shared vertex (steps 2 and 3 of the module doc of [`super`]), and the small geometry
//! they need.

use std::collections::HashMap;

use crate::geometry::{add, dist, dot, norm2, scale, sub};
use crate::mesh::Point3;

use super::{key, Builder};

/// Union-find over point ids; `find` gives the id that keeps its position.
pub(super) struct Merges(Vec<u32>);

impl Merges {
    pub(super) fn new(n: usize) -> Self {
        Merges((0..n as u32).collect())
    }
    pub(super) fn find(&mut self, mut a: u32) -> u32 {
        while self.0[a as usize] != a {
            let up = self.0[self.0[a as usize] as usize];
            self.0[a as usize] = up;
            a = up;
        }
        a
    }
    /// Merges `gone` into `kept`; false when they were already one.
    pub(super) fn merge(&mut self, gone: u32, kept: u32) -> bool {
        let (g, k) = (self.find(gone), self.find(kept));
        if g == k {
            return false;
        }
        self.0[g as usize] = k;
        true
    }
}

/// Closest points of segments a0–a1 and b0–b1 on their (infinite) lines: parameters (s, t) along
/// each, or None when the lines are (nearly) parallel.
fn line_line(a0: Point3, a1: Point3, b0: Point3, b1: Point3) -> Option<(f64, f64)> {
    let (d1, d2, r) = (sub(a1, a0), sub(b1, b0), sub(a0, b0));
    let (a, e, b) = (norm2(d1), norm2(d2), dot(d1, d2));
    let (c, f) = (dot(d1, r), dot(d2, r));
    let den = a * e - b * b;
    // sin² of the angle between the lines below 1e-6: parallel (overlapping curves are left
    // alone; they are not crossings).
    if den <= 1e-6 * a * e {
        return None;
    }
    Some(((b * f - c * e) / den, (a * f - b * c) / den))
}

/// Parameter of the point of segment a–b closest to p, clamped to [0, 1].
fn segment_param(p: Point3, a: Point3, b: Point3) -> f64 {
    let ab = sub(b, a);
    let l2 = norm2(ab);
    if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

fn lerp(a: Point3, b: Point3, t: f64) -> Point3 {
    add(a, scale(sub(b, a), t))
}

/// Pairs of boxes that overlap (sweep and prune along x): the candidates of the junction tests.
fn overlapping(boxes: &[(Point3, Point3)]) -> Vec<(usize, usize)> {
    let mut order: Vec<usize> = (0..boxes.len()).collect();
    order.sort_by(|&i, &j| boxes[i].0[0].total_cmp(&boxes[j].0[0]));
    let mut out = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        let (lo, hi) = boxes[i];
        for &j in &order[k + 1..] {
            let (lo2, hi2) = boxes[j];
            if lo2[0] > hi[0] {
                break;
            }
            if lo2[1] <= hi[1] && lo[1] <= hi2[1] && lo2[2] <= hi[2] && lo[2] <= hi2[2] {
                out.push((i.min(j), i.max(j)));
            }
        }
    }
    out
}

impl Builder {
    /// Step 2: consecutive points closer than `tol` × the median segment length become one.
    pub(super) fn merge_near_duplicates(&mut self, tol: f64) {
        if tol <= 0.0 {
            return;
        }
        let segs = self.segments();
        let mut lens: Vec<f64> = segs.iter().map(|&s| self.len(s)).collect();
        lens.sort_by(f64::total_cmp);
        let limit = tol * lens[lens.len() / 2];
        let short: Vec<[u32; 2]> = segs.iter().copied().filter(|&s| self.len(s) < limit).collect();
        if short.is_empty() {
            return;
        }
        let degree = self.degrees(&segs);
        let mut m = Merges::new(self.points.len());
        for s in short {
            // The point with more segments (a feature point) keeps its place.
            let (kept, gone) =
                if degree[s[1] as usize] > degree[s[0] as usize] { (s[1], s[0]) } else { (s[0], s[1]) };
            let d = dist(self.points[m.find(kept) as usize], self.points[gone as usize]);
            if m.merge(gone, kept) {
                self.stats.near_duplicates_merged += 1;
                self.stats.near_duplicate_max_distance = self.stats.near_duplicate_max_distance.max(d);
            }
        }
        self.apply_merges(&mut m);
    }

    /// Step 3a: curve ends near another polyline's segment join it (T-junctions).
    pub(super) fn join_ends(&mut self, tol: f64) {
        let segs = self.segments();
        let degree = self.degrees(&segs);
        let ends: Vec<u32> = (0..self.points.len() as u32).filter(|&p| degree[p as usize] == 1).collect();
        if ends.is_empty() {
            return;
        }
        // Neighbours of each end (its one segment's other point).
        let mut nbr: HashMap<u32, u32> = HashMap::new();
        for s in &segs {
            for (a, b) in [(s[0], s[1]), (s[1], s[0])] {
                if degree[a as usize] == 1 {
                    nbr.insert(a, b);
                }
            }
        }
        let mut boxes: Vec<(Point3, Point3)> = segs.iter().map(|&s| self.seg_box(s, tol)).collect();
        boxes.extend(ends.iter().map(|&e| (self.points[e as usize], self.points[e as usize])));
        let ns = segs.len();
        // Best segment per end: (gap / tolerance, segment, parameter).
        let mut best: HashMap<u32, (f64, usize, f64)> = HashMap::new();
        for (i, j) in overlapping(&boxes) {
            let (si, ei) = if i < ns && j >= ns {
                (i, j - ns)
            } else if j < ns && i >= ns {
                (j, i - ns)
            } else {
                continue;
            };
            let (e, s) = (ends[ei], segs[si]);
            let n = nbr[&e];
            // Not its own segment, nor one touching its neighbour (a curve's own bend).
            if s.contains(&e) || s.contains(&n) {
                continue;
            }
            let (a, b) = (self.points[s[0] as usize], self.points[s[1] as usize]);
            let p = self.points[e as usize];
            let t = segment_param(p, a, b);
            let gap = dist(p, lerp(a, b, t));
            let allowed = tol * self.len(s);
            if gap <= allowed && best.get(&e).map_or(true, |x| gap / allowed < x.0) {
                best.insert(e, (gap / allowed, si, t));
            }
        }
        let mut ends_sorted: Vec<u32> = best.keys().copied().collect();
        ends_sorted.sort();
        let mut splits: HashMap<(u32, u32), Vec<(f64, u32)>> = HashMap::new();
        let mut m = Merges::new(self.points.len());
        let mut merged_any = false;
        for e in ends_sorted {
            let (_, si, t) = best[&e];
            let s = segs[si];
            let (a, b) = (self.points[s[0] as usize], self.points[s[1] as usize]);
            let p = self.points[e as usize];
            let len = self.len(s);
            // Near a vertex of the segment (closer than the allowed gap): the end goes to the vertex.
            let near = if t * len <= tol * len {
                Some(s[0])
            } else if (1.0 - t) * len <= tol * len {
                Some(s[1])
            } else {
                None
            };
            match near {
                Some(v) if dist(p, self.points[v as usize]) <= tol * len && v != nbr[&e] => {
                    if m.merge(e, v) {
                        self.stats.ends_merged += 1;
                        merged_any = true;
                        self.stats.junction_max_gap =
                            self.stats.junction_max_gap.max(dist(p, self.points[v as usize]));
                    }
                }
                Some(_) => {}
                None => {
                    splits.entry(key(s[0], s[1])).or_default().push((t, e));
                    self.stats.t_junctions += 1;
                    self.stats.junction_max_gap = self.stats.junction_max_gap.max(dist(p, lerp(a, b, t)));
                }
            }
        }
        self.apply_splits(splits);
        if merged_any {
            self.apply_merges(&mut m);
        }
    }

    /// The box of segment `s` grown by `tol` × its length (the reach of the junction tests).
    fn seg_box(&self, s: [u32; 2], tol: f64) -> (Point3, Point3) {
        let (a, b) = (self.points[s[0] as usize], self.points[s[1] as usize]);
        let r = tol * dist(a, b);
        let lo = [a[0].min(b[0]) - r, a[1].min(b[1]) - r, a[2].min(b[2]) - r];
        let hi = [a[0].max(b[0]) + r, a[1].max(b[1]) + r, a[2].max(b[2]) + r];
        (lo, hi)
    }

    /// Step 3b: segments that cross without a shared vertex get one.
    pub(super) fn insert_crossings(&mut self, tol: f64) {
        let segs = self.segments();
        let boxes: Vec<(Point3, Point3)> = segs.iter().map(|&s| self.seg_box(s, tol)).collect();
        let mut nbrs: Vec<Vec<u32>> = vec![Vec::new(); self.points.len()];
        for s in &segs {
            nbrs[s[0] as usize].push(s[1]);
            nbrs[s[1] as usize].push(s[0]);
        }
        // Points at most two segments apart: curves that already meet there (a shared crossing
        // vertex next to both) are not crossed again by the extensions of their segments.
        let adj = |a: u32, b: u32| {
            a == b || nbrs[a as usize].iter().any(|&x| x == b || nbrs[b as usize].contains(&x))
        };
        let mut splits: HashMap<(u32, u32), Vec<(f64, u32)>> = HashMap::new();
        let mut m = Merges::new(self.points.len());
        let mut merged_any = false;
        let mut pairs = overlapping(&boxes);
        pairs.sort();
        for (i, j) in pairs {
            let (s1, s2) = (segs[i], segs[j]);
            if s1.iter().any(|&v| s2.iter().any(|&w| adj(v, w))) {
                continue;
            }
            let p = |v: u32| self.points[v as usize];
            let (a0, a1, b0, b1) = (p(s1[0]), p(s1[1]), p(s2[0]), p(s2[1]));
            let Some((s, t)) = line_line(a0, a1, b0, b1) else { continue };
            let (l1, l2) = (dist(a0, a1), dist(b0, b1));
            let allowed = tol * l1.min(l2);
            // Within `allowed` of a segment's end counts as at that vertex. Closest points on the
            // lines' extensions are not crossings (curves that pass near each other's ends).
            let snap = |u: f64, l: f64, v: [u32; 2]| -> Option<Option<u32>> {
                if !(0.0..=1.0).contains(&u) {
                    None
                } else if u * l <= allowed {
                    Some(Some(v[0]))
                } else if (1.0 - u) * l <= allowed {
                    Some(Some(v[1]))
                } else {
                    Some(None)
                }
            };
            let (Some(va), Some(vb)) = (snap(s, l1, s1), snap(t, l2, s2)) else { continue };
            match (va, vb) {
                (None, None) => {
                    let (x, y) = (lerp(a0, a1, s), lerp(b0, b1, t));
                    let gap = dist(x, y);
                    if gap > allowed {
                        continue;
                    }
                    let id = self.points.len() as u32;
                    self.points.push(scale(add(x, y), 0.5));
                    m.0.push(id);
                    splits.entry(key(s1[0], s1[1])).or_default().push((s, id));
                    splits.entry(key(s2[0], s2[1])).or_default().push((t, id));
                    self.stats.crossings_inserted += 1;
                    self.stats.junction_max_gap = self.stats.junction_max_gap.max(gap);
                }
                (Some(v), None) | (None, Some(v)) => {
                    // The crossing is at vertex v of one segment: split the other there, unless v
                    // is already joined to it (a bend next to a shared vertex, not a crossing).
                    let (other, (o0, o1)) = if va.is_some() { (s2, (b0, b1)) } else { (s1, (a0, a1)) };
                    if adj(v, other[0]) || adj(v, other[1]) {
                        continue;
                    }
                    let u = segment_param(p(v), o0, o1);
                    let gap = dist(p(v), lerp(o0, o1, u));
                    if gap > allowed || u <= 0.0 || u >= 1.0 {
                        continue;
                    }
                    splits.entry(key(other[0], other[1])).or_default().push((u, v));
                    self.stats.crossings_at_vertices += 1;
                    self.stats.junction_max_gap = self.stats.junction_max_gap.max(gap);
                }
                (Some(v), Some(w)) => {
                    // Both near a vertex: two curves meet at a point each samples separately.
                    if adj(v, w) || dist(p(v), p(w)) > allowed {
                        continue;
                    }
                    let gap = dist(p(v), p(w));
                    if m.merge(w, v) {
                        merged_any = true;
                        self.stats.crossings_at_vertices += 1;
                        self.stats.junction_max_gap = self.stats.junction_max_gap.max(gap);
                    }
                }
            }
        }
        self.apply_splits(splits);
        if merged_any {
            self.apply_merges(&mut m);
        }
    }
}
