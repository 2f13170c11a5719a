//! The curve network: polylines from the curves input, cleaned and joined into one graph.
//!
//! Real curve files are not clean plane sections, so the network is built in steps, each counted
//! in [`NetworkStats`] (the report's `network` object; nothing is changed silently):
//! 1. *Weld*: points closer than `join_tolerance` × the curves' bounding-box diagonal are one
//!    vertex, so polylines given with repeated shared endpoints form a network. Consecutive repeats
//!    (zero-length segments) are removed; a polyline left with one point (e.g. a closed loop of one
//!    point) is dropped and listed, an error only when no polyline is left.
//! 2. *Near-duplicates*: consecutive points closer than `merge_tolerance` × the median segment
//!    length are merged (the point with more segments, i.e. a feature point, keeps its position).
//!    Such pairs make slivers (0.008° corners) that no later stage can remove.
//! 3. *Junctions* (`junction_tolerance`, 0 disables), all relative to the segments involved:
//!    - a curve end within `junction_tolerance` × the length of another polyline's segment from it
//!      is joined to it (a T-junction: the segment is split at the end point; an end near that
//!      segment's vertex is merged into the vertex);
//!    - two segments that cross when seen along their common normal, with a gap below
//!      `junction_tolerance` × the shorter one's length, get a shared crossing vertex (the
//!      midpoint of their closest points; a crossing that close to a vertex uses the vertex).
//!    Crossing curves must share a vertex for the regions between them to close: sampled curves
//!    on a curved surface are chords, which pass each other by up to their sag (≈ length × angle
//!    / 8), hence a tolerance relative to segment length and not to the network's size.
//!
//! A *feature point* (§2.1) is a vertex where more than two segments meet: it wins
//! correspondence conflicts.

use std::collections::HashMap;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::geometry::{add, dist, dot, norm2, scale, sub, Aabb};
use crate::mesh::{Mesh, Point3};

#[derive(Debug, Clone)]
pub struct CurveNetwork {
    /// Welded curve vertices (with any inserted crossing points at the end).
    pub points: Vec<Point3>,
    /// Unique undirected segments (point indices, smaller first).
    pub segments: Vec<[u32; 2]>,
    /// The input polylines as point indices (consecutive repeats removed, junctions inserted);
    /// their order is kept so the output can carry the same curves. Dropped polylines are absent.
    pub polylines: Vec<Vec<u32>>,
    /// Number of distinct segments at each point.
    pub degree: Vec<u32>,
    /// Index of the first input polyline that uses each point (for error messages).
    pub curve_of_point: Vec<u32>,
    /// Input vertices merged into another one by the weld.
    pub welded_vertices: usize,
    /// What the clean-up steps did (see the module doc).
    pub stats: NetworkStats,
}

/// The tolerances of [`CurveNetwork::build`] (see the module doc for what each one does).
#[derive(Debug, Clone, Copy)]
pub struct NetworkOptions {
    /// × the curves' bounding-box diagonal.
    pub join_tolerance: f64,
    /// × the median segment length.
    pub merge_tolerance: f64,
    /// × the length of the segment(s) involved.
    pub junction_tolerance: f64,
}

impl Default for NetworkOptions {
    fn default() -> Self {
        NetworkOptions { join_tolerance: 1e-6, merge_tolerance: 1e-3, junction_tolerance: 0.25 }
    }
}

/// Counts of what building the network changed (the report's `network` object).
#[derive(Debug, Clone, Default, Serialize)]
pub struct NetworkStats {
    pub input_polylines: usize,
    pub input_points: usize,
    /// Input points merged into an equal (within `join_tolerance`) point.
    pub welded_points: usize,
    /// Consecutive repeated points removed.
    pub zero_length_segments: usize,
    /// Input polylines dropped because they have fewer than two distinct points.
    pub dropped_polylines: Vec<usize>,
    /// Segments listed more than once (repeated polylines); each is used once.
    pub duplicate_segments: usize,
    /// Consecutive points merged by `merge_tolerance`, and the largest distance merged.
    pub near_duplicates_merged: usize,
    pub near_duplicate_max_distance: f64,
    /// Curve ends joined to another polyline's segment (split there) or vertex (merged).
    pub t_junctions: usize,
    pub ends_merged: usize,
    /// Crossings without a shared vertex given one: new points, and existing vertices used.
    pub crossings_inserted: usize,
    pub crossings_at_vertices: usize,
    /// Largest gap closed by a junction or crossing (model units).
    pub junction_max_gap: f64,
    /// Curve ends left free (degree 1) after the junctions.
    pub dangling_ends: usize,
    pub feature_points: usize,
}

impl CurveNetwork {
    /// The raw network: welded, zero-length segments and one-point polylines removed, but no
    /// near-duplicate merge and no junctions (tests of later stages feed crossing inputs on
    /// purpose). The fit job uses [`CurveNetwork::build`] with its parameters.
    pub fn from_mesh(curves: &Mesh, join_tolerance: f64) -> Result<Self> {
        Self::build(curves, &NetworkOptions { join_tolerance, merge_tolerance: 0.0, junction_tolerance: 0.0 })
    }

    /// Builds the network from the polylines of `curves` (`Mesh::curves`). Faces of the curves
    /// input are ignored.
    pub fn build(curves: &Mesh, opt: &NetworkOptions) -> Result<Self> {
        if curves.curves.is_empty() {
            return Err(Error::params(
                "curves",
                "the curves input has no polylines (OBJ `l` lines, glTF LINES/LINE_STRIP)",
            ));
        }
        for (ci, c) in curves.curves.iter().enumerate() {
            for (j, &v) in c.iter().enumerate() {
                let p = curves.positions.get(v as usize).ok_or_else(|| {
                    Error::params("curves", format!("curve {ci} point {j} refers to missing vertex {v}"))
                })?;
                if !p.iter().all(|x| x.is_finite()) {
                    return Err(Error::params("curves", format!("curve {ci} point {j} is not finite")));
                }
            }
        }
        let used: Vec<Point3> =
            curves.curves.iter().flatten().map(|&v| curves.positions[v as usize]).collect();
        let diag = Aabb::of(&used).map(|b| b.diagonal()).unwrap_or(0.0);
        if diag <= 0.0 {
            return Err(Error::params("curves", "all curve vertices are at one point"));
        }
        let mut stats = NetworkStats {
            input_polylines: curves.curves.len(),
            input_points: used.len(),
            ..Default::default()
        };
        let tol = join_tolerance_abs(opt.join_tolerance, diag);
        let mut weld = Weld::new(tol);
        let mut input_to_point: HashMap<u32, u32> = HashMap::new();
        let mut polylines = Vec::with_capacity(curves.curves.len());
        let mut polyline_input = Vec::with_capacity(curves.curves.len());
        let mut inputs_seen = 0usize;
        for (ci, c) in curves.curves.iter().enumerate() {
            let mut line: Vec<u32> = Vec::with_capacity(c.len());
            for &v in c {
                let id = match input_to_point.get(&v) {
                    Some(&id) => id,
                    None => {
                        inputs_seen += 1;
                        let id = weld.insert(curves.positions[v as usize]);
                        input_to_point.insert(v, id);
                        id
                    }
                };
                if line.last() == Some(&id) {
                    stats.zero_length_segments += 1;
                } else {
                    line.push(id);
                }
            }
            if line.len() < 2 {
                stats.dropped_polylines.push(ci);
                continue;
            }
            polylines.push(line);
            polyline_input.push(ci as u32);
        }
        if polylines.is_empty() {
            let c = stats.dropped_polylines.first().map_or(0, |&c| curves.curves[c].len());
            return Err(Error::params(
                "curves",
                format!("no curve has two distinct points (each is at one point; curve 0 has {c} given)"),
            ));
        }
        stats.welded_points = inputs_seen - weld.points.len();
        let mut b = Builder { points: weld.points, polylines, stats };
        b.merge_near_duplicates(opt.merge_tolerance);
        if opt.junction_tolerance > 0.0 {
            b.join_ends(opt.junction_tolerance);
            b.insert_crossings(opt.junction_tolerance);
        }
        Ok(b.finish(&polyline_input))
    }
    pub fn is_feature(&self, p: u32) -> bool {
        self.degree[p as usize] > 2
    }

    pub fn feature_count(&self) -> usize {
        self.degree.iter().filter(|&&d| d > 2).count()
    }

    /// Shortest segment length (0 when there is none).
    pub fn min_segment(&self) -> f64 {
        self.segments
            .iter()
            .map(|s| dist(self.points[s[0] as usize], self.points[s[1] as usize]))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Merges points closer than `tol` (hash grid with cell = tol, 27-cell lookup).
struct Weld {
    tol: f64,
    points: Vec<Point3>,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl Weld {
    fn new(tol: f64) -> Self {
        Weld { tol, points: Vec::new(), cells: HashMap::new() }
    }

    fn cell(&self, p: Point3) -> [i64; 3] {
        [(p[0] / self.tol).floor() as i64, (p[1] / self.tol).floor() as i64, (p[2] / self.tol).floor() as i64]
    }

    fn insert(&mut self, p: Point3) -> u32 {
        let c = self.cell(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        for &i in list {
                            if dist(self.points[i as usize], p) <= self.tol {
                                return i;
                            }
                        }
                    }
                }
            }
        }
        let id = self.points.len() as u32;
        self.points.push(p);
        self.cells.entry(c).or_default().push(id);
        id
    }
}

/// The weld distance: `join_tolerance` × the diagonal, never below rounding noise of the
/// coordinates (so curves far from the origin still weld their shared points).
fn join_tolerance_abs(join_tolerance: f64, diag: f64) -> f64 {
    (join_tolerance.max(0.0) * diag).max(diag * 1e-15)
}

/// The network while it is cleaned: points and polylines of point ids.
struct Builder {
    points: Vec<Point3>,
    polylines: Vec<Vec<u32>>,
    stats: NetworkStats,
}

/// Undirected segment key, smaller id first.
fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Union-find over point ids; `find` gives the id that keeps its position.
struct Merges(Vec<u32>);

impl Merges {
    fn new(n: usize) -> Self {
        Merges((0..n as u32).collect())
    }
    fn find(&mut self, mut a: u32) -> u32 {
        while self.0[a as usize] != a {
            let up = self.0[self.0[a as usize] as usize];
            self.0[a as usize] = up;
            a = up;
        }
        a
    }
    /// Merges `gone` into `kept`; false when they were already one.
    fn merge(&mut self, gone: u32, kept: u32) -> bool {
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
    /// Unique segments of the current polylines.
    fn segments(&self) -> Vec<[u32; 2]> {
        let mut seen: HashMap<(u32, u32), ()> = HashMap::new();
        let mut out = Vec::new();
        for line in &self.polylines {
            for w in line.windows(2) {
                let k = key(w[0], w[1]);
                if seen.insert(k, ()).is_none() {
                    out.push([k.0, k.1]);
                }
            }
        }
        out
    }

    fn degrees(&self, segments: &[[u32; 2]]) -> Vec<u32> {
        let mut d = vec![0u32; self.points.len()];
        for s in segments {
            d[s[0] as usize] += 1;
            d[s[1] as usize] += 1;
        }
        d
    }

    fn len(&self, s: [u32; 2]) -> f64 {
        dist(self.points[s[0] as usize], self.points[s[1] as usize])
    }

    /// Renames merged points in every polyline and drops the consecutive repeats this makes.
    fn apply_merges(&mut self, m: &mut Merges) {
        for line in &mut self.polylines {
            let mut out: Vec<u32> = Vec::with_capacity(line.len());
            for &v in line.iter() {
                let r = m.find(v);
                if out.last() != Some(&r) {
                    out.push(r);
                }
            }
            *line = out;
        }
        // A polyline merged down to one point was a near-duplicate pair only: it is gone (its
        // point, merged, is still in the network when another polyline uses it).
        self.polylines.retain(|l| l.len() >= 2);
    }

    /// Inserts points into segments: `splits[(a, b)]` = (parameter from a, point) for a < b.
    fn apply_splits(&mut self, mut splits: HashMap<(u32, u32), Vec<(f64, u32)>>) {
        if splits.is_empty() {
            return;
        }
        for list in splits.values_mut() {
            list.sort_by(|x, y| x.0.total_cmp(&y.0));
            list.dedup_by_key(|x| x.1);
        }
        for line in &mut self.polylines {
            let mut out = Vec::with_capacity(line.len());
            for (i, &v) in line.iter().enumerate() {
                if i > 0 {
                    let u = line[i - 1];
                    if let Some(list) = splits.get(&key(u, v)) {
                        let inner = list.iter().map(|x| x.1).filter(|&x| x != u && x != v);
                        if u < v {
                            out.extend(inner);
                        } else {
                            out.extend(inner.collect::<Vec<_>>().into_iter().rev());
                        }
                    }
                }
                out.push(v);
            }
            out.dedup();
            *line = out;
        }
    }

    /// Step 2: consecutive points closer than `tol` × the median segment length become one.
    fn merge_near_duplicates(&mut self, tol: f64) {
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
    fn join_ends(&mut self, tol: f64) {
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
    fn insert_crossings(&mut self, tol: f64) {
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

    fn finish(mut self, polyline_input: &[u32]) -> CurveNetwork {
        // Points no polyline uses any more (merged away) are removed; ids are renumbered in
        // order of first use.
        let mut new_id = vec![u32::MAX; self.points.len()];
        let mut points = Vec::new();
        let mut curve_of_point = Vec::new();
        for (li, line) in self.polylines.iter_mut().enumerate() {
            for v in line.iter_mut() {
                if new_id[*v as usize] == u32::MAX {
                    new_id[*v as usize] = points.len() as u32;
                    points.push(self.points[*v as usize]);
                    curve_of_point.push(polyline_input.get(li).copied().unwrap_or(li as u32));
                }
                *v = new_id[*v as usize];
            }
        }
        self.points = points;
        let mut seen: HashMap<(u32, u32), ()> = HashMap::new();
        let mut segments = Vec::new();
        let mut degree = vec![0u32; self.points.len()];
        for line in &self.polylines {
            for w in line.windows(2) {
                let k = key(w[0], w[1]);
                if seen.insert(k, ()).is_none() {
                    segments.push([k.0, k.1]);
                    degree[w[0] as usize] += 1;
                    degree[w[1] as usize] += 1;
                } else {
                    self.stats.duplicate_segments += 1;
                }
            }
        }
        self.stats.dangling_ends = degree.iter().filter(|&&d| d == 1).count();
        self.stats.feature_points = degree.iter().filter(|&&d| d > 2).count();
        CurveNetwork {
            points: self.points,
            segments,
            polylines: self.polylines,
            degree,
            curve_of_point,
            welded_vertices: self.stats.welded_points,
            stats: self.stats,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(points: Vec<Point3>, curves: Vec<Vec<u32>>) -> Mesh {
        Mesh { positions: points, curves, ..Default::default() }
    }

    #[test]
    fn shared_endpoints_join_and_features_are_found() {
        // A plus sign from four two-point lines whose centre is given four times (slightly apart).
        let m = lines(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1e-9, 0.0, 0.0],
                [-1.0, 0.0, 0.0],
                [0.0, 0.0, 1e-9],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0],
                [0.0, -1.0, 0.0],
            ],
            vec![vec![0, 1], vec![2, 3], vec![4, 5], vec![6, 7]],
        );
        let n = CurveNetwork::from_mesh(&m, 1e-6).unwrap();
        assert_eq!(n.points.len(), 5);
        assert_eq!(n.segments.len(), 4);
        assert_eq!(n.feature_count(), 1);
        assert_eq!(n.degree[0], 4);
        assert_eq!(n.welded_vertices, 3);
    }

    #[test]
    fn empty_and_one_point_curves_are_named() {
        let e = CurveNetwork::from_mesh(&lines(vec![[0.0; 3]], vec![]), 1e-6).unwrap_err();
        assert!(matches!(e, Error::InvalidParams { ref field, .. } if field == "curves"), "{e}");
        // A one-point curve next to a good one is dropped and listed; alone it is an error.
        let n = CurveNetwork::from_mesh(
            &lines(vec![[0.0; 3], [1.0, 0.0, 0.0]], vec![vec![0, 1], vec![1, 1]]),
            1e-6,
        )
        .unwrap();
        assert_eq!(n.stats.dropped_polylines, vec![1]);
        assert_eq!(n.stats.zero_length_segments, 1);
        let e = CurveNetwork::from_mesh(&lines(vec![[1.0; 3]], vec![vec![0, 0]]), 1e-6).unwrap_err();
        assert!(e.to_string().contains("one point"), "{e}");
    }
}

/// Reads a curve network given as JSON `{"polylines": [[[x, y, z], …], …]}` (issue 5's third curve
/// format besides OBJ `l` and glTF lines). Returns `None` when `bytes` is not such a document, so the
/// caller can fall back to the mesh readers. Each polyline becomes one `Mesh::curves` entry; shared
/// endpoints are joined later, like those of any other curve input.
pub fn polylines_from_json(bytes: &[u8]) -> Option<Result<Mesh>> {
    let text = std::str::from_utf8(bytes).ok()?.trim_start();
    if !text.starts_with('{') || !text.contains("\"polylines\"") {
        return None;
    }
    let doc: serde_json::Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => {
            return Some(Err(Error::malformed(
                "json",
                crate::error::Location::Line(e.line()),
                format!("curve network JSON: {e}"),
            )))
        }
    };
    let lines = doc.get("polylines")?;
    Some(parse_polylines(lines))
}

fn parse_polylines(lines: &serde_json::Value) -> Result<Mesh> {
    use crate::error::Location;
    let at = |path: String, msg: &str| Error::malformed("json", Location::Gltf(path), msg.to_string());
    let lines = lines.as_array().ok_or_else(|| at("polylines".into(), "must be an array of polylines"))?;
    let mut mesh = Mesh::default();
    for (i, line) in lines.iter().enumerate() {
        let points =
            line.as_array().ok_or_else(|| at(format!("polylines[{i}]"), "must be an array of points"))?;
        if points.len() < 2 {
            return Err(at(format!("polylines[{i}]"), "a polyline needs at least 2 points"));
        }
        let mut curve = Vec::with_capacity(points.len());
        for (j, p) in points.iter().enumerate() {
            let xyz = p
                .as_array()
                .filter(|c| c.len() == 3)
                .and_then(|c| Some([c[0].as_f64()?, c[1].as_f64()?, c[2].as_f64()?]))
                .filter(|c| c.iter().all(|v| v.is_finite()))
                .ok_or_else(|| {
                    at(format!("polylines[{i}][{j}]"), "a point is [x, y, z] with finite numbers")
                })?;
            let index = u32::try_from(mesh.positions.len())
                .map_err(|_| at(format!("polylines[{i}]"), "too many points"))?;
            mesh.positions.push(xyz);
            curve.push(index);
        }
        mesh.curves.push(curve);
    }
    if mesh.curves.is_empty() {
        return Err(at("polylines".into(), "no polylines"));
    }
    Ok(mesh)
}

#[cfg(test)]
mod json_tests {
    use super::*;

    #[test]
    fn polylines_json_becomes_curves() {
        let doc = br#"{"polylines": [[[0,0,0],[1,0,0],[1,1,0]], [[1,1,0],[0,1,0.5]]]}"#;
        let m = polylines_from_json(doc).unwrap().unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.curves, vec![vec![0, 1, 2], vec![3, 4]]);
        assert_eq!(m.positions[4], [0.0, 1.0, 0.5]);
        assert_eq!(m.face_count(), 0);
    }

    #[test]
    fn polylines_json_errors_name_the_point() {
        let e = polylines_from_json(br#"{"polylines": [[[0,0,0],[1,0]]]}"#).unwrap().unwrap_err();
        assert!(e.to_string().contains("polylines[0][1]"), "{e}");
        let e = polylines_from_json(br#"{"polylines": [[[0,0,0]]]}"#).unwrap().unwrap_err();
        assert!(e.to_string().contains("polylines[0]"), "{e}");
        assert!(polylines_from_json(b"v 0 0 0\n").is_none());
        assert!(polylines_from_json(br#"{"asset": {"version": "2.0"}}"#).is_none());
    }
}
