//! Multi-level approach to the curves before the exact fine fit (the "k steps" the seed's remarks
//! allow): at each level an RBF through a spread-out subset of the curve vertices, each matched to
//! its closest point on the *current* surface, moves the template towards the curves.
//!
//! Why: the fine RBF interpolates the displacement from each curve vertex's foot on the surface to
//! the vertex. Where the coarse alignment (a handful of user pairs) leaves the surface farther
//! from the curves than the local edge length, neighbouring feet get displacements that differ by
//! more than their spacing: the field's gradient exceeds 1 and faces fold (measured on the bent
//! homer: 16 folded faces, every one with a displacement 4–11× its edge length, and the curve
//! segments there could not be made edge chains). A field through sparse samples has a small
//! gradient (displacement differences over a large spacing); each level shrinks the distance left,
//! so the next, denser level again moves by little compared with its spacing, and the final
//! exact fit only corrects small residuals.
//!
//! A level that would fold faces (orientation test against the face before the move) is scaled
//! back by halves; a level whose centres are degenerate (too few, coplanar) is skipped.

use serde::Serialize;

use crate::error::Result;
use crate::geometry::{add, dist, dot, scale, sub, triangle_cross};
use crate::job::Progress;
use crate::mesh::Point3;

use super::curves::CurveNetwork;
use super::rbf::{self, Kernel, Rbf};

#[derive(Debug, Clone, Default, Serialize)]
pub struct ApproachReport {
    /// Centres used per level.
    pub centres: Vec<usize>,
    /// Fraction of each level's displacement applied (1 unless it would have folded faces).
    pub step: Vec<f64>,
    /// Largest and mean distance of each level's sampled curve vertices to the surface before the
    /// level moved it (what the level corrects).
    pub distance_max: Vec<f64>,
    pub distance_mean: Vec<f64>,
    /// Per level: the template refined where the level's field bends within a face
    /// ([`super::field_refine`]).
    pub refined: Vec<super::field_refine::FieldRefineStats>,
}

/// Field refinement tolerance, × the curves' median segment length ([`super::field_refine`]).
const FIELD_TOLERANCE: f64 = 0.1;
/// Templates whose median edge is below this × the curves' median segment are not refined
/// (the 96k headline, whose edges are about as long as its curve segments, is not).
const FINE_TEMPLATE_EDGE: f64 = 2.0;
/// The field refinement adds at most this many faces per curve vertex, over the template's.
const FIELD_FACES_PER_CURVE_VERTEX: usize = 4;
/// Extra runs of the densest level at most.
const MAX_REPEATS: usize = 2;
/// The densest level is repeated while its samples end farther than this × the median segment.
const REPEAT_DISTANCE: f64 = 0.5;

/// Sample counts per level: each level uses 4× the centres of the previous one, the last at most
/// a quarter of the curve vertices (the exact fit does the rest).
fn level_sizes(n: usize, levels: usize) -> Vec<usize> {
    let mut sizes = Vec::new();
    let mut k = n / 4;
    while k >= 16 && sizes.len() < levels {
        sizes.push(k);
        k /= 4;
    }
    sizes.reverse();
    sizes
}

/// Moves `pos` towards the curves in up to `levels` levels. `fixed` template vertices (user pairs
/// already on their curve points) are centres with zero displacement at every level. Nothing moves
/// when a curve vertex is farther than `max_distance` from the surface.
#[allow(clippy::too_many_arguments)]
pub fn approach(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    parents: &mut Vec<[(u32, f64); 3]>,
    net: &CurveNetwork,
    fixed: &[(u32, u32)],
    kernel: Kernel,
    levels: usize,
    max_distance: f64,
    progress: &Progress,
) -> Result<ApproachReport> {
    let mut report = ApproachReport::default();
    let sizes = level_sizes(net.points.len(), levels);
    if sizes.is_empty() {
        return Ok(report);
    }
    let faces_around = |nv: usize, tris: &[[u32; 3]]| {
        let mut vf: Vec<Vec<u32>> = vec![Vec::new(); nv];
        for (f, t) in tris.iter().enumerate() {
            for &v in t {
                vf[v as usize].push(f as u32);
            }
        }
        vf
    };
    let mut vf = faces_around(pos.len(), tris);
    let is_fixed_point = {
        let mut m = vec![false; net.points.len()];
        for &(p, _) in fixed {
            m[p as usize] = true;
        }
        m
    };
    // Curves farther from the surface than the limit are an input error the fine stage reports,
    // naming the curve: do not drag the template there first.
    let all: Vec<u32> = (0..net.points.len() as u32).collect();
    // Around the nearest vertex's two-ring is cheap and exact on one piece; on a template in
    // pieces the nearest vertex can be on another piece passing close by (raw suzanne: the eyes
    // were pulled onto the head's curves, 7 flips), so the exact search is used there.
    let in_pieces = super::insert::walk::face_components(pos.len(), tris).iter().any(|&c| c != 0);
    let feet_of = |pos: &[Point3], tris: &[[u32; 3]], vf: &[Vec<u32>], which: &[u32]| {
        if in_pieces {
            super::insert::feet(pos, tris, &net.points, which)
        } else {
            super::insert::feet_near_vertex(pos, tris, vf, &net.points, which)
        }
    };
    if feet_of(pos, tris, &vf, &all)?.iter().any(|f| f.2 > max_distance) {
        return Ok(report);
    }
    let length: f64 =
        net.segments.iter().map(|s| dist(net.points[s[0] as usize], net.points[s[1] as usize])).sum();
    // Field refinement (see [`super::field_refine`]): feet must land within a tenth of the
    // curves' median segment; no edge is split below a quarter of it.
    let median = {
        let mut l: Vec<f64> =
            net.segments.iter().map(|s| dist(net.points[s[0] as usize], net.points[s[1] as usize])).collect();
        l.sort_by(f64::total_cmp);
        l.get(l.len() / 2).copied().unwrap_or(0.0)
    };
    // Only a template coarse against the curves can miss a field that bends at the curves'
    // scale; a finer one follows it already (and is too large to check every edge of).
    let template_edge = {
        let mut l: Vec<f64> = tris.iter().map(|t| dist(pos[t[0] as usize], pos[t[1] as usize])).collect();
        let k = l.len() / 2;
        if l.is_empty() {
            0.0
        } else {
            *l.select_nth_unstable_by(k, f64::total_cmp).1
        }
    };
    let refine_tolerance =
        if template_edge > FINE_TEMPLATE_EDGE * median { FIELD_TOLERANCE * median } else { 0.0 };
    let refine_min_edge = 0.25 * median;
    let max_faces = tris.len() + FIELD_FACES_PER_CURVE_VERTEX * net.points.len();
    // The densest level is repeated (up to [`MAX_REPEATS`] times) while its own samples end
    // farther than half the median segment from the curves after it moved: the surface is still
    // converging (measured on spot's sections with a level-3 icosphere: 3.3e-2 → 1.2e-2 → 1.1e-3
    // over two repeats, and 21 → 1 flipped faces; without the field refinement the repeats do not
    // converge, 23 flips, as fit-loops found).
    let mut queue: std::collections::VecDeque<(usize, usize)> =
        sizes.iter().enumerate().map(|(i, &s)| (s, (i + 1 == sizes.len()) as usize * MAX_REPEATS)).collect();
    while let Some((size, repeats_left)) = queue.pop_front() {
        progress.check()?;
        let h = length / size as f64;
        let sample = spread_sample(net, h, &is_fixed_point);
        let feet = feet_of(pos, tris, &vf, &sample)?;
        report.distance_max.push(feet.iter().map(|f| f.2).fold(0.0, f64::max));
        report.distance_mean.push(feet.iter().map(|f| f.2).sum::<f64>() / feet.len().max(1) as f64);
        let mut centres: Vec<Point3> = Vec::with_capacity(sample.len() + fixed.len());
        let mut values: Vec<Point3> = Vec::with_capacity(centres.capacity());
        for &(_, v) in fixed {
            centres.push(pos[v as usize]);
            values.push([0.0; 3]);
        }
        for (&p, f) in sample.iter().zip(&feet) {
            centres.push(f.1);
            values.push(sub(net.points[p as usize], f.1));
        }
        dedup_centres(&mut centres, &mut values);
        if rbf::check_centres(&centres).is_err() || rbf::spread_ratios(&centres)[0] < 1e-3 {
            continue;
        }
        let Ok(field) = Rbf::fit(&centres, &values, kernel, "fine") else { continue };
        let mut disp = field.eval_many(pos, progress)?;
        if refine_tolerance > 0.0 {
            let s = super::field_refine::refine_for_field(
                pos,
                tris,
                parents,
                &mut disp,
                &field,
                refine_tolerance,
                refine_min_edge,
                max_faces,
                progress,
            )?;
            if s.faces_added > 0 {
                vf = faces_around(pos.len(), tris);
            }
            report.refined.push(s);
        }
        let mut step = 1.0;
        let moved: Vec<Point3> = loop {
            let moved: Vec<Point3> = pos.iter().zip(&disp).map(|(p, d)| add(*p, scale(*d, step))).collect();
            if step < 0.1 || folds(pos, &moved, tris) == 0 {
                break moved;
            }
            step *= 0.5;
        };
        if step < 0.1 {
            report.centres.push(centres.len());
            report.step.push(0.0);
            continue;
        }
        pos.copy_from_slice(&moved);
        for &(p, v) in fixed {
            pos[v as usize] = net.points[p as usize];
        }
        if repeats_left > 0 {
            let after = feet_of(pos, tris, &vf, &sample)?;
            let left = after.iter().map(|f| f.2).fold(0.0, f64::max);
            if left > REPEAT_DISTANCE * median {
                queue.push_back((size, repeats_left - 1));
            }
        }
        report.centres.push(centres.len());
        report.step.push(step);
    }
    Ok(report)
}

/// Faces whose normal turns by more than 90° between `before` and `after`.
pub fn folds(before: &[Point3], after: &[Point3], tris: &[[u32; 3]]) -> usize {
    use rayon::prelude::*;
    tris.par_iter()
        .filter(|t| {
            let p = |x: &[Point3], i: usize| x[t[i] as usize];
            let nb = triangle_cross(p(before, 0), p(before, 1), p(before, 2));
            let na = triangle_cross(p(after, 0), p(after, 1), p(after, 2));
            dot(nb, na) <= 0.0 && dot(nb, nb) > 0.0
        })
        .count()
}

/// Curve points no closer than `h` to each other (greedy, feature points first, fixed points
/// excluded: they are centres already), found with a hash grid of cell `h`.
fn spread_sample(net: &CurveNetwork, h: f64, excluded: &[bool]) -> Vec<u32> {
    use std::collections::HashMap;
    let key = |p: Point3| [(p[0] / h).floor() as i64, (p[1] / h).floor() as i64, (p[2] / h).floor() as i64];
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut order: Vec<u32> = (0..net.points.len() as u32).filter(|&p| !excluded[p as usize]).collect();
    order.sort_by_key(|&p| !net.is_feature(p));
    let mut out = Vec::new();
    for p in order {
        let x = net.points[p as usize];
        let k = key(x);
        let mut near = false;
        'scan: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(c) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        if c.iter().any(|&q| dist(net.points[q as usize], x) < h) {
                            near = true;
                            break 'scan;
                        }
                    }
                }
            }
        }
        if !near {
            grid.entry(k).or_default().push(p);
            out.push(p);
        }
    }
    out
}

/// Drops centres that coincide (within 1e-9 of the extent) with an earlier one: two samples can
/// share a foot where the surface is concave.
fn dedup_centres(centres: &mut Vec<Point3>, values: &mut Vec<Point3>) {
    let Some(bb) = crate::geometry::Aabb::of(centres) else { return };
    let tol = 1e-7 * bb.diagonal().max(f64::MIN_POSITIVE);
    let tree = super::kdtree::KdTree::new(centres);
    let mut keep = vec![true; centres.len()];
    for i in 0..centres.len() {
        if !keep[i] {
            continue;
        }
        if let Some((j, d2)) = tree.nearest_filtered(centres[i], |j| j as usize != i && keep[j as usize]) {
            if d2.sqrt() <= tol && (j as usize) > i {
                keep[j as usize] = false;
            }
        }
    }
    let mut k = 0;
    centres.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    let mut k = 0;
    values.retain(|_| {
        k += 1;
        keep[k - 1]
    });
}
