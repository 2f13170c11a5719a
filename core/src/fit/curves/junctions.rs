//! The junction steps of the network build: near-duplicate merges, T-junctions and crossings
//! without a shared vertex (steps 2 and 3 of the module doc of [`super`]), and the small geometry
//! they need.

use std::collections::HashMap;

use crate::geometry::{add, dist, dot, norm2, scale, sub};
use crate::mesh::Point3;

use super::{key, Builder, MayJoin};

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

    /// Step 3a: a curve given twice with other samplings (the shared border of two CAD patches,
    /// each exported with its own boundary; a stroke drawn over another) is one curve. Every
    /// point lying on a nearly parallel segment of the network, within that segment's sag (the
    /// distance a chord of the sampled curve can be from it), is put into that segment (or merged
    /// into its end vertex when that close to it). After that both copies run through the same
    /// points, so their segments are the same and are used once. Without it the two copies make
    /// a strip of slivers between them and a region per strip piece (measured: the equator drawn
    /// twice gave 36 regions instead of 8).
    ///
    /// The reach is the sag of the segment, estimated from the polyline's turn at its ends
    /// (length × angle / 8 for an arc, ×1.5, angle capped at 0.5 rad; at least 1e-3 × length):
    /// distinct curves farther apart than the curve's own chord error are never merged, however
    /// sparsely they are sampled. Points two segments apart or less (a curve's own bend) and
    /// crossings (segments more than 25° apart) are left alone.
    pub(super) fn merge_overlaps(&mut self) {
        const MAX_TURN: f64 = 0.5;
        const MIN_COS: f64 = 0.9;
        let segs = self.segments();
        let seg_id: HashMap<(u32, u32), usize> =
            segs.iter().enumerate().map(|(i, s)| (key(s[0], s[1]), i)).collect();
        // Largest turn at either end of each segment, along its polylines.
        let mut turn = vec![0.0f64; segs.len()];
        for line in &self.polylines {
            for w in line.windows(3) {
                let (a, b, c) =
                    (self.points[w[0] as usize], self.points[w[1] as usize], self.points[w[2] as usize]);
                let (u, v) = (sub(b, a), sub(c, b));
                let d = (norm2(u) * norm2(v)).sqrt();
                let angle = if d > 0.0 { (dot(u, v) / d).clamp(-1.0, 1.0).acos() } else { 0.0 };
                for s in [key(w[0], w[1]), key(w[1], w[2])] {
                    if let Some(&i) = seg_id.get(&s) {
                        turn[i] = turn[i].max(angle.min(MAX_TURN));
                    }
                }
            }
        }
        let reach: Vec<f64> =
            segs.iter().zip(&turn).map(|(&s, &t)| self.len(s) * (1.5 * t / 8.0).max(1e-3)).collect();
        let mut nbrs: Vec<Vec<u32>> = vec![Vec::new(); self.points.len()];
        for s in &segs {
            nbrs[s[0] as usize].push(s[1]);
            nbrs[s[1] as usize].push(s[0]);
        }
        let near = |a: u32, b: u32| {
            a == b || nbrs[a as usize].iter().any(|&x| x == b || nbrs[b as usize].contains(&x))
        };
        let mut boxes: Vec<(Point3, Point3)> = segs
            .iter()
            .zip(&reach)
            .map(|(&s, &r)| {
                let (a, b) = (self.points[s[0] as usize], self.points[s[1] as usize]);
                (
                    [a[0].min(b[0]) - r, a[1].min(b[1]) - r, a[2].min(b[2]) - r],
                    [a[0].max(b[0]) + r, a[1].max(b[1]) + r, a[2].max(b[2]) + r],
                )
            })
            .collect();
        let np = self.points.len();
        boxes.extend(self.points.iter().map(|&p| (p, p)));
        let ns = segs.len();
        // Best segment per point: (gap / reach, segment, parameter).
        let mut best: HashMap<u32, (f64, usize, f64)> = HashMap::new();
        for (i, j) in overlapping(&boxes) {
            let (si, pi) = match (i < ns, j < ns) {
                (true, false) => (i, (j - ns) as u32),
                (false, true) => (j, (i - ns) as u32),
                _ => continue,
            };
            let s = segs[si];
            if nbrs[pi as usize].is_empty() || near(pi, s[0]) || near(pi, s[1]) {
                continue;
            }
            let (a, b, p) =
                (self.points[s[0] as usize], self.points[s[1] as usize], self.points[pi as usize]);
            let t = segment_param(p, a, b);
            let gap = dist(p, lerp(a, b, t));
            if gap > reach[si] || best.get(&pi).is_some_and(|x| gap / reach[si] >= x.0) {
                continue;
            }
            // Parallel to one of the point's own segments: a copy, not a crossing.
            let d = sub(b, a);
            let parallel = nbrs[pi as usize].iter().any(|&q| {
                let e = sub(self.points[q as usize], p);
                let den = (norm2(d) * norm2(e)).sqrt();
                den > 0.0 && dot(d, e).abs() >= MIN_COS * den
            });
            if parallel {
                best.insert(pi, (gap / reach[si], si, t));
            }
        }
        self.keep_copied_runs(&mut best, &segs);
        if best.is_empty() {
            return;
        }
        let mut points: Vec<u32> = best.keys().copied().collect();
        points.sort_unstable();
        let mut splits: HashMap<(u32, u32), Vec<(f64, u32)>> = HashMap::new();
        let mut m = Merges::new(np);
        let mut merged_any = false;
        for p in points {
            let (_, si, t) = best[&p];
            let s = segs[si];
            let (len, r) = (self.len(s), reach[si]);
            let gap = dist(
                self.points[p as usize],
                lerp(self.points[s[0] as usize], self.points[s[1] as usize], t),
            );
            let end = if t * len <= r {
                Some(s[0])
            } else if (1.0 - t) * len <= r {
                Some(s[1])
            } else {
                None
            };
            match end {
                Some(v) => {
                    // The merged point takes the vertex's place: that is how far it moves.
                    let moved = dist(self.points[p as usize], self.points[v as usize]);
                    if m.merge(p, v) {
                        merged_any = true;
                        self.stats.overlap_points_joined += 1;
                        self.stats.junction_max_gap = self.stats.junction_max_gap.max(moved);
                    }
                }
                None => {
                    splits.entry(key(s[0], s[1])).or_default().push((t, p));
                    self.stats.overlap_points_joined += 1;
                    self.stats.junction_max_gap = self.stats.junction_max_gap.max(gap);
                }
            }
        }
        self.apply_splits(splits);
        if merged_any {
            self.apply_merges(&mut m);
        }
    }

    /// Keeps only the points of [`Builder::merge_overlaps`] that belong to a copy: a run of at
    /// least 3 consecutive points of a polyline lying along at least 3 distinct segments of one
    /// other polyline. Two curves crossing at a shallow angle are close along a few segments
    /// around the crossing only (measured on the bent homer sections: merging those made 46
    /// regions of 44).
    fn keep_copied_runs(&self, best: &mut HashMap<u32, (f64, usize, f64)>, segs: &[[u32; 2]]) {
        const MIN_RUN: usize = 3;
        let mut owner: HashMap<(u32, u32), usize> = HashMap::new();
        for (li, line) in self.polylines.iter().enumerate() {
            for w in line.windows(2) {
                owner.entry(key(w[0], w[1])).or_insert(li);
            }
        }
        let mut keep: HashMap<u32, ()> = HashMap::new();
        for (li, line) in self.polylines.iter().enumerate() {
            // (other polyline, its segments touched, the run's points)
            let mut run: Option<(usize, Vec<usize>, Vec<u32>)> = None;
            let mut close = |run: &mut Option<(usize, Vec<usize>, Vec<u32>)>| {
                if let Some((_, mut touched, pts)) = run.take() {
                    touched.sort_unstable();
                    touched.dedup();
                    if pts.len() >= MIN_RUN && touched.len() >= MIN_RUN {
                        keep.extend(pts.into_iter().map(|p| (p, ())));
                    }
                }
            };
            for &p in line {
                let target = best.get(&p).and_then(|&(_, si, _)| {
                    let o = *owner.get(&key(segs[si][0], segs[si][1]))?;
                    (o != li).then_some((o, si))
                });
                match (target, run.as_mut()) {
                    (Some((o, si)), Some(r)) if r.0 == o => {
                        r.1.push(si);
                        r.2.push(p);
                    }
                    (Some((o, si)), _) => {
                        close(&mut run);
                        run = Some((o, vec![si], vec![p]));
                    }
                    (None, _) => close(&mut run),
                }
            }
            close(&mut run);
        }
        best.retain(|p, _| keep.contains_key(p));
    }

    /// Step 3b: curve ends near another polyline's segment join it (T-junctions), where
    /// `may_join(end segment, segment)` (the fit asks its aligned template: an end on another
    /// piece or sheet is left free, counted in `ends_on_two_sheets`).
    pub(super) fn join_ends(&mut self, tol: f64, may_join: &MayJoin<'_>) {
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
        let mut refused: Vec<u32> = Vec::new();
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
                if !may_join([p, self.points[n as usize]], [a, b]) {
                    refused.push(e);
                    continue;
                }
                best.insert(e, (gap / allowed, si, t));
            }
        }
        refused.sort_unstable();
        refused.dedup();
        self.stats.ends_on_two_sheets += refused.iter().filter(|e| !best.contains_key(e)).count();
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

    /// Step 3c: segments that cross without a shared vertex get one.
    pub(super) fn insert_crossings(&mut self, tol: f64, may_join: &MayJoin<'_>) {
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
        // Asked only of crossings that pass every other test, so that refusals count crossings.
        let mut refused = 0;
        let mut join_ok = |a: [Point3; 2], b: [Point3; 2]| {
            let ok = may_join(a, b);
            refused += usize::from(!ok);
            ok
        };
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
                    if !join_ok([a0, a1], [b0, b1]) {
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
                    if gap > allowed || u <= 0.0 || u >= 1.0 || !join_ok([a0, a1], [b0, b1]) {
                        continue;
                    }
                    splits.entry(key(other[0], other[1])).or_default().push((u, v));
                    self.stats.crossings_at_vertices += 1;
                    self.stats.junction_max_gap = self.stats.junction_max_gap.max(gap);
                }
                (Some(v), Some(w)) => {
                    // Both near a vertex: two curves meet at a point each samples separately,
                    // or two curves cross near a sample of each.
                    if adj(v, w) {
                        continue;
                    }
                    let into = |x: u32, o: [u32; 2]| {
                        let u = segment_param(p(x), p(o[0]), p(o[1]));
                        let gap = dist(p(x), lerp(p(o[0]), p(o[1]), u));
                        (gap, u, x, o)
                    };
                    let (gap, u, x, o) = [into(v, s2), into(w, s1)]
                        .into_iter()
                        .min_by(|a, b| a.0.total_cmp(&b.0))
                        .unwrap_or(into(v, s2));
                    let apart = dist(p(v), p(w));
                    // A split (the vertex nearer the other segment put into it) moves a curve by
                    // `gap`, a merge by `apart`. Split when the vertices are far apart (a shallow
                    // crossing, whose point slides along both segments) or when one vertex lies on
                    // the other segment much closer than the two vertices are to each other (two
                    // curves closer than a quarter segment, e.g. two parallels crossed by a
                    // meridian: merging would pinch one onto the other at every crossing).
                    let split_ok = gap <= allowed && u > 0.0 && u < 1.0 && !adj(x, o[0]) && !adj(x, o[1]);
                    if apart > allowed || (4.0 * gap <= apart && split_ok) {
                        if !split_ok || !join_ok([a0, a1], [b0, b1]) {
                            continue;
                        }
                        splits.entry(key(o[0], o[1])).or_default().push((u, x));
                        self.stats.crossings_at_vertices += 1;
                        self.stats.junction_max_gap = self.stats.junction_max_gap.max(gap);
                        continue;
                    }
                    if !join_ok([a0, a1], [b0, b1]) {
                        continue;
                    }
                    if m.merge(w, v) {
                        merged_any = true;
                        self.stats.crossings_at_vertices += 1;
                        self.stats.junction_max_gap = self.stats.junction_max_gap.max(apart);
                    }
                }
            }
        }
        self.stats.crossings_on_two_sheets += refused;
        self.apply_splits(splits);
        if merged_any {
            self.apply_merges(&mut m);
        }
    }
}
