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
use crate::geometry::{dist, Aabb};
use crate::mesh::{Mesh, Point3};

mod json;
mod junctions;

pub use json::polylines_from_json;
use junctions::Merges;

/// Whether two segments (their end points) that cross in space may get a shared vertex.
pub type MayJoin<'a> = dyn Fn([Point3; 2], [Point3; 2]) -> bool + 'a;

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
    /// Input points merged into an equal (within `join_tolerance`) point, and the largest
    /// distance such a point moved (shared ends written by different node transforms of a glTF
    /// file differ by f32 rounding; the output carries the welded position).
    pub welded_points: usize,
    pub welded_max_distance: f64,
    /// Consecutive repeated points removed.
    pub zero_length_segments: usize,
    /// Input polylines dropped because they have fewer than two distinct points.
    pub dropped_polylines: Vec<usize>,
    /// Segments listed more than once (repeated polylines); each is used once.
    pub duplicate_segments: usize,
    /// Consecutive points merged by `merge_tolerance`, and the largest distance merged.
    pub near_duplicates_merged: usize,
    pub near_duplicate_max_distance: f64,
    /// Points of a curve given twice (other sampling) put into the other copy's segments or
    /// merged into its vertices (step 3a of the module doc).
    pub overlap_points_joined: usize,
    /// Curve ends joined to another polyline's segment (split there) or vertex (merged).
    pub t_junctions: usize,
    pub ends_merged: usize,
    /// Crossings without a shared vertex given one: new points, and existing vertices used.
    pub crossings_inserted: usize,
    pub crossings_at_vertices: usize,
    /// Crossings left unjoined because the aligned template has the two curves on two sheets
    /// that pass through each other (a self-intersecting template; see `fit::sheets`).
    pub crossings_on_two_sheets: usize,
    /// Curve ends left free (no T-junction, no merge) for the same reason, or because the end
    /// and the segment it would join lie on two pieces of the template (see `fit::sheets`).
    pub ends_on_two_sheets: usize,
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
        Self::build_checked(curves, opt, &|_, _| true)
    }

    /// [`CurveNetwork::build`] joining two crossing segments `a`, `b` (or an end's segment `a` to
    /// a segment `b`) only where `may_join(a, b)` (the fit asks its aligned template:
    /// [`crate::fit::sheets`]); refusals are counted in `crossings_on_two_sheets` and
    /// `ends_on_two_sheets`.
    pub fn build_checked(curves: &Mesh, opt: &NetworkOptions, may_join: &MayJoin<'_>) -> Result<Self> {
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
        stats.welded_max_distance = weld.max_moved;
        let mut b = Builder { points: weld.points, polylines, stats };
        b.merge_near_duplicates(opt.merge_tolerance);
        if opt.junction_tolerance > 0.0 {
            b.merge_overlaps();
            b.join_ends(opt.junction_tolerance, may_join);
            b.insert_crossings(opt.junction_tolerance, may_join);
        }
        Ok(b.finish(&polyline_input))
    }
    pub fn is_feature(&self, p: u32) -> bool {
        self.degree[p as usize] > 2
    }

    pub fn feature_count(&self) -> usize {
        self.degree.iter().filter(|&&d| d > 2).count()
    }

    /// Parts of the network (connected through segments) smaller than the others together and
    /// farther from them than the others' bounding-box diagonal: (input curves of the part, gap,
    /// the others' diagonal).
    /// Used to name a stray curve when the curves do not fit the template: an automatic
    /// alignment stretches the template between the stray part and the rest, so the curves it
    /// then finds far are the good ones.
    pub fn stray_parts(&self) -> Vec<(Vec<u32>, f64, f64)> {
        let n = self.points.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn root(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for s in &self.segments {
            let (a, b) = (root(&mut parent, s[0] as usize), root(&mut parent, s[1] as usize));
            parent[a] = b;
        }
        let part: Vec<usize> = (0..n).map(|i| root(&mut parent, i)).collect();
        let mut roots: Vec<usize> = part.clone();
        roots.sort_unstable();
        roots.dedup();
        if roots.len() < 2 {
            return Vec::new();
        }
        let mut out = Vec::new();
        for &r in &roots {
            let (inside, others): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| part[i] == r);
            let pts = |ids: &[usize]| ids.iter().map(|&i| self.points[i]).collect::<Vec<_>>();
            let Some(rest) = Aabb::of(&pts(&others)) else { continue };
            // Distance of each point of the part to the others' box; the part's nearest point counts.
            let gap = inside
                .iter()
                .map(|&i| {
                    let p = self.points[i];
                    let d: Vec<f64> =
                        (0..3).map(|k| (rest.min[k] - p[k]).max(p[k] - rest.max[k]).max(0.0)).collect();
                    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            let own = Aabb::of(&pts(&inside)).map_or(0.0, |b| b.diagonal());
            // The smaller of two far-apart parts is the stray one.
            if gap > rest.diagonal() && own < rest.diagonal() {
                let mut curves: Vec<u32> = inside.iter().map(|&i| self.curve_of_point[i]).collect();
                curves.sort_unstable();
                curves.dedup();
                out.push((curves, gap, rest.diagonal()));
            }
        }
        out
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
    /// Largest distance from an input point to the point it was welded into.
    max_moved: f64,
    points: Vec<Point3>,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl Weld {
    fn new(tol: f64) -> Self {
        Weld { tol, max_moved: 0.0, points: Vec::new(), cells: HashMap::new() }
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
                            let d = dist(self.points[i as usize], p);
                            if d <= self.tol {
                                self.max_moved = self.max_moved.max(d);
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
