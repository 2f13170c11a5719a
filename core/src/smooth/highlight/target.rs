//! Desired highlight lines (seed 001 §3.2, §3.5): every stretch of a highlight line whose nodes can
//! move is replaced by an optimized geometric Hermite (OGH) curve between the nearest fixed nodes on
//! either side, `Q₀` and `Q₁`, with the line's tangents there; each moving node gets the point of the
//! curve at its normalised chord-length parameter (eq. 12), measured along the curve's arc length.
//!
//! Choices the paper leaves open (documented in docs/api.md):
//! - Tangent at `Q₀`: the direction from the nearest fixed node behind it that is at least a quarter
//!   of the region's mean edge length away (nodes on neighbouring edges can nearly coincide). When
//!   the line has no such fixed node (it ends or re-enters the region right there), the chord
//!   `Q₁ − Q₀` is used and the run is counted as a tangent fallback.
//! - Stretches that reach an open end of a line, and closed lines with no fixed node, have no two
//!   delimiting nodes: they get no target (counted, not faired by the difference term).

use crate::geometry::{add, dist, dot, norm, scale, sub};
use crate::mesh::Point3;

use super::lines::Model;

/// Samples of the arc-length table of an OGH curve.
const ARC_SAMPLES: usize = 128;

/// The OGH curve of eq. 5 with an arc-length table for eq. 12.
#[derive(Debug, Clone)]
pub struct Ogh {
    q0: Point3,
    q1: Point3,
    m0: Point3,
    m1: Point3,
    /// (t, normalised arc length) at `ARC_SAMPLES + 1` uniform t.
    table: Vec<(f64, f64)>,
    samples: Vec<Point3>,
}

impl Ogh {
    /// `None` when a tangent is zero (eq. 5's denominators vanish only then).
    pub fn new(q0: Point3, t0: Point3, q1: Point3, t1: Point3) -> Option<Ogh> {
        let d = sub(q1, q0);
        let (t00, t11, t01) = (dot(t0, t0), dot(t1, t1), dot(t0, t1));
        let den = 4.0 * t00 * t11 - t01 * t01;
        if !(den > 0.0) || !den.is_finite() {
            return None;
        }
        let a0 = (6.0 * dot(d, t0) * t11 - 3.0 * dot(d, t1) * t01) / den;
        let a1 = (3.0 * dot(d, t0) * t01 - 6.0 * dot(d, t1) * t00) / (-den);
        let mut c =
            Ogh { q0, q1, m0: scale(t0, a0), m1: scale(t1, a1), table: Vec::new(), samples: Vec::new() };
        let mut acc = 0.0;
        let mut prev = q0;
        for k in 0..=ARC_SAMPLES {
            let t = k as f64 / ARC_SAMPLES as f64;
            let p = c.eval(t);
            acc += dist(p, prev);
            prev = p;
            c.table.push((t, acc));
            c.samples.push(p);
        }
        let total = acc;
        for e in &mut c.table {
            e.1 = if total > 0.0 { e.1 / total } else { e.0 };
        }
        Some(c)
    }

    /// Eq. 5.
    pub fn eval(&self, t: f64) -> Point3 {
        let h00 = (2.0 * t + 1.0) * (t - 1.0) * (t - 1.0);
        let h01 = (-2.0 * t + 3.0) * t * t;
        let h10 = (1.0 - t) * (1.0 - t) * t;
        let h11 = (t - 1.0) * t * t;
        let mut p = scale(self.q0, h00);
        p = add(p, scale(self.q1, h01));
        p = add(p, scale(self.m0, h10));
        add(p, scale(self.m1, h11))
    }

    /// The point at normalised arc length `c ∈ [0, 1]` (table lookup, then linear in t).
    pub fn at_arc(&self, c: f64) -> Point3 {
        let c = c.clamp(0.0, 1.0);
        let k = self.table.partition_point(|e| e.1 < c).clamp(1, self.table.len() - 1);
        let (ta, sa) = self.table[k - 1];
        let (tb, sb) = self.table[k];
        let f = if sb > sa { (c - sa) / (sb - sa) } else { 0.0 };
        self.eval(ta + f * (tb - ta))
    }

    /// Distance from `p` to the curve (its sampled polyline).
    pub fn distance(&self, p: Point3) -> f64 {
        self.samples.windows(2).map(|w| point_segment(p, w[0], w[1])).fold(f64::INFINITY, f64::min)
    }
}

fn point_segment(p: Point3, a: Point3, b: Point3) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 { (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    dist(p, add(a, scale(ab, t)))
}

/// A stretch of moving nodes with its two fixed delimiting nodes and desired curve.
#[derive(Debug, Clone)]
pub struct Run {
    pub m: i64,
    /// Node ids `Q₀, Q₁ … Qₙ, Qₙ₊₁` (first and last fixed).
    pub nodes: Vec<u32>,
    pub curve: Ogh,
    pub tangent_fallback: bool,
}

/// Runs of every line, plus how many stretches had no two delimiting nodes.
#[derive(Debug, Clone, Default)]
pub struct Runs {
    pub runs: Vec<Run>,
    pub untargeted: usize,
    pub tangent_fallbacks: usize,
}

/// Splits the lines into runs of moving nodes (`moving[node]`) and builds their OGH curves.
/// `min_len` is the shortest chord accepted for a tangent estimate.
pub fn runs(model: &Model, moving: &[bool], min_len: f64) -> Runs {
    let mut out = Runs::default();
    for line in &model.lines {
        let mut seq = line.nodes.clone();
        if line.closed {
            match seq.iter().position(|&n| !moving[n as usize]) {
                None => {
                    out.untargeted += 1;
                    continue;
                }
                Some(k) => {
                    seq.rotate_left(k);
                    seq.push(seq[0]);
                }
            }
        }
        let pos = |i: usize| model.nodes[seq[i] as usize].pos;
        // Index in the cyclic (closed) or plain (open) sequence, walking `step` from i.
        let len = seq.len();
        let step_idx = |i: usize, back: bool| -> Option<usize> {
            if back {
                if i > 0 {
                    Some(i - 1)
                } else if line.closed {
                    Some(len - 2)
                } else {
                    None
                }
            } else if i + 1 < len {
                Some(i + 1)
            } else if line.closed {
                Some(1)
            } else {
                None
            }
        };
        let tangent = |i: usize, back: bool| -> Option<Point3> {
            let mut j = i;
            for _ in 0..len {
                j = step_idx(j, back)?;
                if moving[seq[j] as usize] {
                    return None;
                }
                if dist(pos(j), pos(i)) >= min_len {
                    return Some(if back { sub(pos(i), pos(j)) } else { sub(pos(j), pos(i)) });
                }
            }
            None
        };
        let mut i = 0;
        while i < len {
            if !moving[seq[i] as usize] {
                i += 1;
                continue;
            }
            let start = i;
            while i < len && moving[seq[i] as usize] {
                i += 1;
            }
            if start == 0 || i == len {
                out.untargeted += 1;
                continue;
            }
            let (p, q) = (start - 1, i);
            let (q0, q1) = (pos(p), pos(q));
            let chord = sub(q1, q0);
            let t0 = tangent(p, true);
            let t1 = tangent(q, false);
            let fallback = t0.is_none() || t1.is_none();
            let curve = Ogh::new(q0, t0.unwrap_or(chord), q1, t1.unwrap_or(chord));
            match curve {
                Some(curve) if norm(chord) > 0.0 || !fallback => {
                    out.tangent_fallbacks += fallback as usize;
                    out.runs.push(Run {
                        m: line.m,
                        nodes: seq[p..=q].to_vec(),
                        curve,
                        tangent_fallback: fallback,
                    });
                }
                _ => out.untargeted += 1,
            }
        }
    }
    out
}

/// Per moving node of a run: its target (eq. 12) and segment weight `lᵢ` (eq. 14).
pub fn targets(model: &Model, run: &Run) -> Vec<(u32, Point3, f64)> {
    let p: Vec<Point3> = run.nodes.iter().map(|&n| model.nodes[n as usize].pos).collect();
    let mut cum = vec![0.0; p.len()];
    for k in 1..p.len() {
        cum[k] = cum[k - 1] + dist(p[k], p[k - 1]);
    }
    let total = cum[p.len() - 1];
    (1..p.len() - 1)
        .map(|k| {
            let c = if total > 0.0 { cum[k] / total } else { k as f64 / (p.len() - 1) as f64 };
            let l = 0.5 * (dist(p[k], p[k - 1]) + dist(p[k], p[k + 1]));
            (run.nodes[k], run.curve.at_arc(c), l)
        })
        .collect()
}

/// How far the highlight lines are from the desired ones.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Deviation {
    /// Runs (line stretches with a desired curve) and their moving nodes.
    pub runs: usize,
    pub nodes: usize,
    /// Eq. 11 summed over the runs (length³), with the region's mean edge length `e` as unit in
    /// `f_diff_relative` (= f_diff / e³).
    pub f_diff: f64,
    pub f_diff_relative: f64,
    /// Distance of each moving node to its desired curve (closest point, not eq. 12's target):
    /// mean and max, absolute and in units of `e`.
    pub mean_distance: f64,
    pub max_distance: f64,
    pub mean_distance_relative: f64,
    pub max_distance_relative: f64,
    /// Mean and max turning angle (degrees) of the lines at their moving nodes (0 = straight);
    /// segments shorter than 1e-3·e are merged first.
    pub mean_turning_deg: f64,
    pub max_turning_deg: f64,
}

pub fn deviation(model: &Model, runs: &Runs, e: f64) -> Deviation {
    let mut dv = Deviation { runs: runs.runs.len(), ..Default::default() };
    let (mut turn_sum, mut turn_n) = (0.0, 0usize);
    for run in &runs.runs {
        for (n, target, l) in targets(model, run) {
            let p = model.nodes[n as usize].pos;
            dv.f_diff += dist(p, target).powi(2) * l;
            let dc = run.curve.distance(p);
            dv.mean_distance += dc;
            dv.max_distance = dv.max_distance.max(dc);
            dv.nodes += 1;
        }
        // Turning angles along the run, skipping (near) coincident nodes.
        let mut pts: Vec<Point3> = Vec::new();
        for &n in &run.nodes {
            let p = model.nodes[n as usize].pos;
            if pts.last().is_none_or(|q| dist(*q, p) > 1e-3 * e) {
                pts.push(p);
            }
        }
        for w in pts.windows(3) {
            let (a, b) = (sub(w[1], w[0]), sub(w[2], w[1]));
            let ang = (norm(crate::geometry::cross(a, b))).atan2(dot(a, b)).to_degrees();
            turn_sum += ang;
            turn_n += 1;
            dv.max_turning_deg = dv.max_turning_deg.max(ang);
        }
    }
    if dv.nodes > 0 {
        dv.mean_distance /= dv.nodes as f64;
    }
    if turn_n > 0 {
        dv.mean_turning_deg = turn_sum / turn_n as f64;
    }
    if e > 0.0 {
        dv.f_diff_relative = dv.f_diff / (e * e * e);
        dv.mean_distance_relative = dv.mean_distance / e;
        dv.max_distance_relative = dv.max_distance / e;
    }
    dv
}
