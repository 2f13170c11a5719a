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
}

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
pub fn approach(
    pos: &mut [Point3],
    tris: &[[u32; 3]],
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
    let mut vf: Vec<Vec<u32>> = vec![Vec::new(); pos.len()];
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            vf[v as usize].push(f as u32);
        }
    }
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
    let feet_of = |pos: &[Point3], which: &[u32]| {
        if in_pieces {
            super::insert::feet(pos, tris, &net.points, which)
        } else {
            super::insert::feet_near_vertex(pos, tris, &vf, &net.points, which)
        }
    };
    if feet_of(pos, &all)?.iter().any(|f| f.2 > max_distance) {
        return Ok(report);
    }
    let length: f64 =
        net.segments.iter().map(|s| dist(net.points[s[0] as usize], net.points[s[1] as usize])).sum();
    for &size in &sizes {
        progress.check()?;
        let h = length / size as f64;
        let sample = spread_sample(net, h, &is_fixed_point);
        let feet = feet_of(pos, &sample)?;
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
        let disp = field.eval_many(pos, progress)?;
        let mut step = 1.0;
        let moved = loop {
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
