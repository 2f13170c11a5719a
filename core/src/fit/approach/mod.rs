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
//! A level that would fold faces (orientation test against the face before the move) or turn space
//! inside out at a vertex first leaves out the samples nearest those places, then is scaled back
//! by halves ([`level`]); a level whose centres are degenerate (too few, coplanar) is skipped.

use serde::Serialize;

use crate::error::Result;
use crate::geometry::{dist, sub};
use crate::job::Progress;
use crate::mesh::Point3;

use super::curves::CurveNetwork;
use super::rbf::{self, Kernel};

mod level;

pub use level::folds;
use level::{dedup_centres, level_field, LevelField};

#[derive(Debug, Clone, Default, Serialize)]
pub struct ApproachReport {
    /// Centres used per level.
    pub centres: Vec<usize>,
    /// Fraction of each level's displacement applied (1 unless it would have folded faces or
    /// turned space inside out at a vertex).
    pub step: Vec<f64>,
    /// Samples left out of a level and its field solved again, where at full step it folded a
    /// face or inverted the map at a vertex (the centre nearest each), summed over the levels.
    pub dropped_centres: usize,
    /// Largest and mean distance of each level's sampled curve vertices to the surface before the
    /// level moved it (what the level corrects).
    pub distance_max: Vec<f64>,
    pub distance_mean: Vec<f64>,
    /// Curve points per level whose walked foot was used instead of their closest point (user
    /// pairs only, [`walked_feet`]).
    pub walked_feet: Vec<usize>,
    /// Per level run: the template refined where the level's field bends within the faces
    /// holding its samples ([`super::field_refine`]).
    pub refined: Vec<super::field_refine::FieldRefineStats>,
    /// Extra runs of the densest level (after a refinement, while its samples stay far).
    pub repeats: usize,
    /// Sampled curve points per level whose foot was moved from a sheet to the rim, because they
    /// lie between the template's two sheets near its rim ([`super::thin`]).
    pub rim_feet: Vec<usize>,
    /// Levels whose field was fitted again with the in-plane polynomial, because on their nearly
    /// flat centres the full affine part turned space inside out ([`level_field`]).
    pub in_plane_fields: usize,
    /// Segments whose closest feet on the surface before the approach are out of the curve's
    /// order or stretched ([`super::insert::order`]), as the insertion counts them after it.
    pub out_of_order_before: usize,
    pub stretched_before: usize,
}

/// Field refinement gate ([`super::field_refine`]): a level's sample missed by more than this
/// share of its face's longest edge opens the refinement.
const FIELD_MISS_RATIO: f64 = 0.1;
/// Edges whose midpoint the field moves by more than this × the curves' median segment away from
/// the mean of their ends are split.
const FIELD_TOLERANCE: f64 = 0.1;
/// No face shorter than this × the curves' median segment is split for the field.
const FIELD_MIN_EDGE: f64 = 0.25;
/// The field refinement adds at most this many faces per curve vertex, over the template's.
const FIELD_FACES_PER_CURVE_VERTEX: usize = 4;
/// Extra runs of the densest level at most.
const MAX_REPEATS: usize = 2;
/// The densest level is repeated, when its samples opened the field refinement, while they end
/// farther than this × the median segment from the curves.
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
/// when a curve vertex is farther than `max_distance` from the surface. With `rim_feet`, feet of
/// points between two sheets of a thin part are moved to its rim ([`super::thin`]).
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
    rim_feet: bool,
    orientation: &mut super::orientation::Orientation,
    progress: &Progress,
) -> Result<ApproachReport> {
    let mut report = ApproachReport::default();
    let sizes = level_sizes(net.points.len(), levels);
    if sizes.is_empty() {
        return Ok(report);
    }
    let mut vf = super::insert::vertex_faces(pos.len(), tris);
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
    let mut unmoved = Some(feet_of(pos, tris, &vf, &all)?);
    if let Some(f) = &unmoved {
        let points: Vec<Point3> = f.iter().map(|f| f.1).collect();
        report.out_of_order_before = super::insert::order::out_of_order_segments(net, &points);
        report.stretched_before = super::insert::order::stretched_segments(net, &points);
    }
    if unmoved.iter().flatten().any(|f| f.2 > max_distance) {
        return Ok(report);
    }
    let length: f64 =
        net.segments.iter().map(|s| dist(net.points[s[0] as usize], net.points[s[1] as usize])).sum();
    // With user pairs, feet follow their curve as in the insertion ([`walked_feet`]); the
    // automatic alignment's warp is fitted to every curve point, there the closest points are kept.
    let mut anchor: Vec<bool> = net.degree.iter().map(|&d| d != 2).collect();
    for &(p, _) in fixed {
        anchor[p as usize] = true;
    }
    let walk = !fixed.is_empty() && !in_pieces;
    let median = median_segment(net);
    let max_faces = tris.len() + FIELD_FACES_PER_CURVE_VERTEX * net.points.len();
    let gate = super::field_refine::Gate {
        ratio: FIELD_MISS_RATIO,
        tolerance: FIELD_TOLERANCE * median,
        min_edge: FIELD_MIN_EDGE * median,
        max_faces,
    };
    let mut queue: std::collections::VecDeque<(usize, usize)> =
        sizes.iter().enumerate().map(|(i, &s)| (s, (i + 1 == sizes.len()) as usize * MAX_REPEATS)).collect();
    while let Some((size, repeats_left)) = queue.pop_front() {
        progress.check()?;
        let h = length / size as f64;
        let sample = spread_sample(net, h, &is_fixed_point);
        let feet = if walk {
            // The first level's surface is the one just measured.
            let closest = match unmoved.take() {
                Some(feet) => feet,
                None => feet_of(pos, tris, &vf, &all)?,
            };
            let (feet, walked) = walked_feet(pos, tris, &vf, net, &anchor, closest, progress)?;
            report.walked_feet.push(walked);
            sample.iter().map(|&p| feet[p as usize]).collect()
        } else {
            feet_of(pos, tris, &vf, &sample)?
        };
        let mut feet = feet;
        if rim_feet {
            report.rim_feet.push(super::thin::rim_feet(pos, tris, &vf, &net.points, &sample, &mut feet));
        }
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
        // The field, its values and gradients at every vertex (the gradients for the orientation
        // count below and the inside-out check).
        let Some(LevelField { field, mut disp, mut gradients, in_plane }) =
            level_field(&centres, &values, kernel, pos, progress)?
        else {
            continue;
        };
        report.in_plane_fields += in_plane as usize;
        let targets: Vec<Point3> = sample.iter().map(|&p| net.points[p as usize]).collect();
        let refined = super::field_refine::refine_for_field(
            pos, tris, parents, &mut disp, &field, &targets, &feet, gate, progress,
        )?;
        if refined.faces_added > 0 {
            vf = super::insert::vertex_faces(pos.len(), tris);
            gradients.extend(field.eval_with_gradients(&pos[gradients.len()..], progress)?.1);
        }
        report.refined.push(refined);
        // A few samples whose feet disagree with their neighbours' (a foot on another sheet, a fold
        // of the aligned template) can make the whole level fold; they are left out and the level
        // solved again rather than the whole level shortened or skipped.
        let (level_dropped, clean) = level::drop_folding_centres(
            &mut centres,
            &mut values,
            &mut disp,
            &mut gradients,
            pos,
            tris,
            kernel,
            progress,
        )?;
        report.dropped_centres += level_dropped;
        let (step, moved) = if clean {
            (1.0, level::moved_by(pos, &disp, 1.0))
        } else {
            level::step_search(pos, &disp, &gradients, tris)
        };
        if step < 0.1 {
            report.centres.push(centres.len());
            report.step.push(0.0);
            continue;
        }
        // The template's normals through this level's map, x ↦ x + step · s(x).
        orientation.sync(parents);
        orientation.push_gradients(pos, &gradients, step);
        pos.copy_from_slice(&moved);
        for &(p, v) in fixed {
            pos[v as usize] = net.points[p as usize];
        }
        // The densest level is run again, when its samples opened the refinement, while they stay
        // farther than half the median segment: with the faces split the field can follow and
        // the surface converges (spot's sections with a level-3 icosphere: 21 flips without,
        // none with; without the refinement the repeats do not converge, 23 flips, as
        // fit-loops found). A fit whose samples the surface follows is not repeated.
        // Also when samples were left out: their places were not approached, and the next run
        // takes fresh feet there (held-out beetle idented pairs: 45 -> 30 flips; session 21).
        if repeats_left > 0 && (refined.samples_over > 0 || level_dropped > 0) {
            let after = feet_of(pos, tris, &vf, &sample)?;
            let left = after.iter().map(|f| f.2).fold(0.0, f64::max);
            if left > REPEAT_DISTANCE * median {
                queue.push_back((size, repeats_left - 1));
                report.repeats += 1;
            }
        }
        report.centres.push(centres.len());
        report.step.push(step);
    }
    Ok(report)
}

/// The curves' median segment length.
pub(super) fn median_segment(net: &CurveNetwork) -> f64 {
    let mut l: Vec<f64> =
        net.segments.iter().map(|s| dist(net.points[s[0] as usize], net.points[s[1] as usize])).collect();
    if l.is_empty() {
        return 0.0;
    }
    let k = l.len() / 2;
    *l.select_nth_unstable_by(k, f64::total_cmp).1
}

/// Every curve point's foot: its closest point, or the foot walked along its curve from the
/// previous point's ([`super::insert::walk`]; anchors keep their closest points) when the walks
/// from both sides of the point agree on it. Returns the feet and how many were walked.
///
/// Why walked: with user pairs the coarse RBF is exact only near the pairs, and elsewhere the
/// surface can be farther from the curves than two of its sheets are from each other. A sample's
/// closest point then lands on the other sheet, the level drags that sheet towards the curve and
/// the distance left for the next level *grows* (bent homer with 12 pairs: 0.0068 → 0.018, 0.030
/// at the insertion, 1/2 flipped faces at the end; walked: 0.016 → 0.011, 0.008, none).
///
/// Why both sides: a walk that follows a wrong foot goes astray for the rest of its run (on
/// `tests/fit_real.rs`'s network walked feet 20–400× farther than the closest point, 179 faces
/// against the truth when used). A point whose nearby sheet is the wrong one is reached from
/// both of its run's ends on the right sheet, so both walks agree; a walk gone astray from one
/// end is not followed by the walk from the other end.
fn walked_feet(
    pos: &[Point3],
    tris: &[[u32; 3]],
    vf: &[Vec<u32>],
    net: &CurveNetwork,
    anchor: &[bool],
    closest: Vec<(u32, Point3, f64)>,
    progress: &Progress,
) -> Result<(Vec<(u32, Point3, f64)>, usize)> {
    use super::insert::walk::walk_feet_directed;
    let mut forward = closest.clone();
    if walk_feet_directed(pos, tris, vf, net, &mut forward, anchor, false, progress)? == 0 {
        return Ok((forward, 0));
    }
    let mut backward = closest.clone();
    walk_feet_directed(pos, tris, vf, net, &mut backward, anchor, true, progress)?;
    let mut walked = 0;
    let mut feet = closest;
    for ((c, f), b) in feet.iter_mut().zip(&forward).zip(&backward) {
        let agree = dist(f.1, b.1) <= 1e-9 * (1.0 + f.2);
        if f.0 != c.0 && agree {
            *c = *f;
            walked += 1;
        }
    }
    Ok((feet, walked))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The insertion tests' two-sheet plate, with its vertex-face lists.
    fn plate() -> (Vec<Point3>, Vec<[u32; 3]>, Vec<Vec<u32>>) {
        let (pos, tris) = crate::fit::insert::tests::two_sheet_plate();
        let mut vf = vec![Vec::new(); pos.len()];
        for (f, t) in tris.iter().enumerate() {
            for &v in t {
                vf[v as usize].push(f as u32);
            }
        }
        (pos, tris, vf)
    }

    fn network(pts: &[Point3]) -> CurveNetwork {
        let curves = crate::mesh::Mesh {
            positions: pts.to_vec(),
            curves: vec![(0..pts.len() as u32).collect()],
            ..Default::default()
        };
        CurveNetwork::from_mesh(&curves, 1e-9).unwrap()
    }

    fn closest(pos: &[Point3], tris: &[[u32; 3]], pts: &[Point3]) -> Vec<(u32, Point3, f64)> {
        let all: Vec<u32> = (0..pts.len() as u32).collect();
        super::super::insert::feet(pos, tris, pts, &all).unwrap()
    }

    #[test]
    fn a_run_bulging_towards_the_other_sheet_keeps_its_own_sheet() {
        let (pos, tris, vf) = plate();
        // Nine points above the lower sheet; the 5th and 6th come within 0.03 of the upper one.
        let pts: Vec<Point3> = (1..=9)
            .map(|k| [0.1 * k as f64 - 0.03, 0.45, if k == 5 || k == 6 { 0.07 } else { 0.03 }])
            .collect();
        let net = network(&pts);
        let anchor: Vec<bool> = net.degree.iter().map(|&d| d != 2).collect();
        let c = closest(&pos, &tris, &pts);
        assert!(
            (c[4].1[2] - 0.1).abs() < 1e-12 && (c[5].1[2] - 0.1).abs() < 1e-12,
            "the case: closest points on the upper sheet"
        );
        let (feet, walked) = walked_feet(&pos, &tris, &vf, &net, &anchor, c, &Progress::new()).unwrap();
        assert_eq!(walked, 2);
        for (p, f) in feet.iter().enumerate() {
            assert!(f.1[2].abs() < 1e-12, "point {p} on the upper sheet");
            // Straight below the point: the lower sheet's closest point.
            assert!((f.1[0] - pts[p][0]).abs() < 1e-12 && (f.1[1] - 0.45).abs() < 1e-12);
        }
    }

    #[test]
    fn a_walk_from_a_wrong_end_is_not_followed() {
        let (pos, tris, vf) = plate();
        // The first point (an end, so an anchor keeping its closest point) is nearer the upper
        // sheet, every other point the lower one: the forward walk stays on the upper sheet for
        // the whole run, the backward walk (from the last point) on the lower one.
        let pts: Vec<Point3> =
            (1..=9).map(|k| [0.1 * k as f64 - 0.03, 0.45, if k == 1 { 0.08 } else { 0.02 }]).collect();
        let net = network(&pts);
        let anchor: Vec<bool> = net.degree.iter().map(|&d| d != 2).collect();
        let c = closest(&pos, &tris, &pts);
        let mut forward = c.clone();
        let changed = super::super::insert::walk::walk_feet_directed(
            &pos,
            &tris,
            &vf,
            &net,
            &mut forward,
            &anchor,
            false,
            &Progress::new(),
        )
        .unwrap();
        assert!(
            changed > 0 && (forward[4].1[2] - 0.1).abs() < 1e-12,
            "the case: the one-sided walk goes astray"
        );
        let (feet, walked) =
            walked_feet(&pos, &tris, &vf, &net, &anchor, c.clone(), &Progress::new()).unwrap();
        assert_eq!(walked, 0);
        assert_eq!(feet.iter().map(|f| f.1).collect::<Vec<_>>(), c.iter().map(|f| f.1).collect::<Vec<_>>());
    }
}
