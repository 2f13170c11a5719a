//! The fine stage: every curve vertex gets a template vertex (inserted at its foot, or the nearest
//! one), the template approaches the curves, the exact RBF lands them, flips are handled.

use serde::Serialize;

use crate::error::{Error, Result};
use crate::geometry::{add, dist, sub};
use crate::job::Progress;
use crate::mesh::Point3;

use super::coarse::{fit_rbf, CoarseReport};
use super::insert::coincident;
use super::orientation::Orientation;
use super::rbf::{Gradient, Rbf};
use super::{approach, correspond, curves, flips, insert, refine, FitParams, Matching};

/// The fine stage's result.
pub struct Fine {
    pub positions: Vec<Point3>,
    pub vertex_of_point: Vec<u32>,
    pub report: FineReport,
}

#[derive(Debug, Clone, Serialize)]
pub struct FineReport {
    pub rounds: u32,
    pub correspondence_conflicts: usize,
    pub correspondence_distance_max: f64,
    pub correspondence_distance_mean: f64,
    /// Faces flagged per round (flip counter ∪ orientation test).
    pub flagged_per_round: Vec<usize>,
    pub flagged_by_counter: usize,
    pub flagged_by_orientation: usize,
    /// Faces added by local subdivision.
    pub faces_added: usize,
    /// Faces still flipped by the last round (goal 0).
    pub flipped_faces: usize,
    /// Curve points whose inserted template vertex coincided with another's (within the RBF's
    /// duplicate tolerance), left out of the fine RBF (matching = insert; goal 0).
    pub coincident_centres: usize,
    /// The fine centres were coplanar and `coplanar_centres = "augment"` handled them (RBF with
    /// the in-plane polynomial, [`super::rbf::Rbf::fit_in_plane`]).
    pub augmented: bool,
    /// "insert" or "nearest_vertex".
    pub matching: &'static str,
    /// What the insertion did (matching = insert).
    pub insertion: Option<insert::InsertStats>,
    /// Milliseconds per step of the fine stage (matching = insert): insert, solve, evaluate, flips.
    pub steps_ms: Option<[f64; 4]>,
    /// The multi-level approach to the curves before the exact fit (see [`approach`]).
    pub approach: Option<approach::ApproachReport>,
    pub approach_ms: f64,
}

/// The largest `max_curve_distance` used when part of the network is far from the rest (a
/// stray curve): the automatic alignment stretches the template towards such a part, and a
/// looser limit then lets the approach drag the template onto it instead of naming it.
const STRAY_MAX_CURVE_DISTANCE: f64 = 0.25;

/// The lengths the fine stage measures against, fixed once the template is aligned.
#[derive(Clone, Copy, Debug)]
pub(super) struct Reach {
    /// The aligned template's bounding-box diagonal (the smaller of it and the given one when the
    /// network has a stray part).
    pub diag: f64,
    /// The `max_curve_distance` in force: the parameter, at most [`STRAY_MAX_CURVE_DISTANCE`]
    /// when the network has a stray part.
    pub factor: f64,
    /// Whether part of the network is far from the rest ([`curves::CurveNetwork::stray_parts`]).
    pub stray: bool,
}

impl Reach {
    pub fn new(params: &FitParams, aligned_diag: f64, given_diag: f64, stray: bool) -> Reach {
        if stray {
            Reach {
                diag: aligned_diag.min(given_diag),
                factor: params.max_curve_distance.min(STRAY_MAX_CURVE_DISTANCE),
                stray,
            }
        } else {
            Reach { diag: aligned_diag, factor: params.max_curve_distance, stray }
        }
    }

    /// The distance past which a curve vertex is an input error.
    pub fn limit(&self) -> f64 {
        self.factor * self.diag
    }
}

/// Fails, naming the curve, when a curve vertex is farther than the limit from its template vertex.
fn check_distances(distances: &[f64], net: &curves::CurveNetwork, reach: Reach) -> Result<()> {
    let (limit, template_diag, factor) = (reach.limit(), reach.diag, reach.factor);
    // The farthest point names the curve: with an automatic alignment one stray curve drags the
    // template towards it, and the first point over the limit is then on a good curve.
    let far = distances.iter().enumerate().filter(|(_, &d)| d > limit).max_by(|a, b| a.1.total_cmp(b.1));
    if let Some((p, &d)) = far {
        let c = net.curve_of_point[p];
        let mut curves: Vec<u32> = distances
            .iter()
            .enumerate()
            .filter(|(_, &d)| d > limit)
            .map(|(q, _)| net.curve_of_point[q])
            .collect();
        curves.sort_unstable();
        curves.dedup();
        // A part of the network far from the rest is the likely cause: name it first.
        let stray = if reach.stray { net.stray_parts() } else { Vec::new() };
        if let Some((sc, gap, size)) = stray.first() {
            return Err(Error::params(
                "curves",
                format!(
                    "curve {} is {gap:.4} away from the rest of the network, farther than the rest's \
                     size ({size:.4}), and the curves do not fit the template (point {:?} of curve {c} is \
                     {d:.4} from it after alignment, more than {factor} × the template's \
                     bounding-box diagonal): a stray curve? (curves of that part: {sc:?})",
                    sc[0], net.points[p]
                ),
            ));
        }
        let others = if curves.len() > 1 {
            format!(" ({} curves have points that far: {curves:?})", curves.len())
        } else {
            String::new()
        };
        return Err(Error::params(
            "curves",
            format!(
                "curve {c}: its point {:?} is {d:.4} from the template, more than \
                 max_curve_distance ({factor}) × the template's bounding-box diagonal ({template_diag:.4}) \
                 after alignment{others}; the curves do not lie on the template (check units, or give pairs)",
                net.points[p]
            ),
        ));
    }
    Ok(())
}

/// The fine stage proper, by matching rule.
#[allow(clippy::too_many_arguments)]
pub(super) fn fine_dispatch(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    net: &curves::CurveNetwork,
    coarse: &CoarseReport,
    params: &FitParams,
    reach: Reach,
    parents: &mut Vec<[(u32, f64); 3]>,
    search: insert::FootSearch,
    orientation: &mut Orientation,
    progress: &Progress,
) -> Result<Fine> {
    // The template's normals through the fine RBF, at every vertex the stage kept.
    match params.matching {
        Matching::Insert => {
            let (fine, gradients) =
                fine_fit_inserted(pos, tris, net, coarse, params, reach, parents, search, progress)?;
            orientation.sync(parents);
            if gradients.len() != pos.len() {
                return Err(Error::Internal(format!(
                    "fine stage: {} field gradients for {} vertices",
                    gradients.len(),
                    pos.len()
                )));
            }
            orientation.push_gradients(pos, &gradients, 1.0);
            Ok(fine)
        }
        Matching::NearestVertex => {
            let (fine, field) = fine_fit(pos, tris, net, coarse, params, reach, parents, progress)?;
            orientation.sync(parents);
            orientation.push_field(pos, std::sync::Arc::new(field), 1.0, progress)?;
            Ok(fine)
        }
    }
}

/// The fine stage with `Matching::Insert`: split the template at the curve vertices' feet, solve
/// the RBF once, and handle flips by subdividing the flagged faces under the *same* field (the
/// centres never change, so only the new midpoints are evaluated: no re-solve per round). Also
/// returns the field's gradient at every vertex before the move, from the same sums as the
/// values ([`Rbf::eval_with_gradients`]).
#[allow(clippy::too_many_arguments)]
fn fine_fit_inserted(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    net: &curves::CurveNetwork,
    coarse: &CoarseReport,
    params: &FitParams,
    reach: Reach,
    parents: &mut Vec<[(u32, f64); 3]>,
    search: insert::FootSearch,
    progress: &Progress,
) -> Result<(Fine, Vec<Gradient>)> {
    let pair_fixed = coarse.pair_fixed(&params.pairs);
    let clock = std::time::Instant::now();
    let mut steps_ms = [0.0; 4];
    let mut lap = |k: usize| {
        steps_ms[k] = clock.elapsed().as_secs_f64() * 1e3 - steps_ms.iter().sum::<f64>();
    };
    let before = tris.clone();
    let nv0 = pos.len();
    let ins = insert::insert_curve_points(
        pos,
        tris,
        net,
        &pair_fixed,
        params.end_snap * reach.diag,
        Some(search),
        progress,
    )?;
    for c in &ins.created_in[nv0..] {
        let (f, l) = c.ok_or_else(|| Error::Internal("inserted vertex without origin".into()))?;
        let t = before[f as usize];
        parents.push([(t[0], l[0]), (t[1], l[1]), (t[2], l[2])]);
    }
    drop(before);
    let vop = ins.vertex_of_point.clone();
    let distances: Vec<f64> = (0..vop.len()).map(|p| dist(net.points[p], pos[vop[p] as usize])).collect();
    check_distances(&distances, net, reach)?;
    let all_centres: Vec<Point3> = vop.iter().map(|&v| pos[v as usize]).collect();
    // Template vertices the insertion made at one place (a last resort: piled feet are spread,
    // see [`insert::pileup`]) are one centre; the others still land exactly on their points below.
    let kept = coincident::first_of_each_place(&all_centres, coincident::SAME_PLACE);
    let coincident_centres = vop.len() - kept.len();
    let centres: Vec<Point3> = kept.iter().map(|&p| all_centres[p]).collect();
    let values: Vec<Point3> = kept.iter().map(|&p| sub(net.points[p], all_centres[p])).collect();
    let name = |i: usize| {
        let p = kept[i];
        format!("curve {} point {p} (template vertex {})", net.curve_of_point[p], vop[p])
    };
    lap(0);
    let f = fit_rbf(centres, values, params, "fine", "curves", &name, progress)?;
    lap(1);
    let augmented = f.in_plane();
    let (disp, mut gradients) = f.eval_with_gradients(pos, progress)?;
    let mut moved: Vec<Point3> = pos.iter().zip(&disp).map(|(p, d)| add(*p, *d)).collect();
    for (p, &v) in vop.iter().enumerate() {
        moved[v as usize] = net.points[p]; // exact, not RBF round-off
    }
    lap(2);
    let mut scan = flips::detect_polled(pos, &moved, tris, progress)?;
    let mut flagged_per_round = vec![scan.flipped.len()];
    let (mut rounds, mut faces_added) = (1, 0);
    let budget = tris.len() / 2;
    while !scan.flipped.is_empty()
        && rounds <= params.max_flip_iterations
        && faces_added + 6 * scan.flipped.len() <= budget
    {
        progress.check()?;
        let (p0, t0, par0) = (pos.len(), tris.clone(), parents.len());
        let added = flips::subdivide(pos, tris, &scan.flipped, parents);
        let (d, g) = f.eval_with_gradients(&pos[p0..], progress)?;
        moved.extend(pos[p0..].iter().zip(d).map(|(p, d)| add(*p, d)));
        gradients.extend(g);
        let next = flips::detect_polled(pos, &moved, tris, progress)?;
        flagged_per_round.push(next.flipped.len());
        rounds += 1;
        if next.flipped.len() >= scan.flipped.len() {
            // No better under this field: undo the round (smaller faces fold the same way).
            pos.truncate(p0);
            moved.truncate(p0);
            gradients.truncate(p0);
            parents.truncate(par0);
            *tris = t0;
            break;
        }
        faces_added += added;
        scan = next;
    }
    lap(3);
    let n = distances.len().max(1) as f64;
    let fine = Fine {
        positions: moved,
        vertex_of_point: vop,
        report: FineReport {
            rounds,
            correspondence_conflicts: ins.stats.nudged,
            correspondence_distance_max: distances.iter().cloned().fold(0.0, f64::max),
            correspondence_distance_mean: distances.iter().sum::<f64>() / n,
            flagged_per_round,
            flagged_by_counter: scan.by_counter,
            flagged_by_orientation: scan.by_orientation,
            faces_added,
            flipped_faces: scan.flipped.len(),
            coincident_centres,
            augmented,
            matching: "insert",
            insertion: Some(ins.stats),
            steps_ms: Some(steps_ms),
            approach: None,
            approach_ms: 0.0,
        },
    };
    Ok((fine, gradients))
}

/// The template's UVs extended to the vertices the fit added (each a weighted combination of
/// older vertices, in creation order).
pub fn interpolate_uvs(uv: &[[f64; 2]], parents: &[[(u32, f64); 3]]) -> Vec<[f64; 2]> {
    let mut out = uv.to_vec();
    out.reserve(parents.len());
    for p in parents {
        let mut u = [0.0; 2];
        for &(v, w) in p {
            let q = out[v as usize];
            u[0] += w * q[0];
            u[1] += w * q[1];
        }
        out.push(u);
    }
    out
}

#[allow(clippy::too_many_arguments)]
fn fine_fit(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    net: &curves::CurveNetwork,
    coarse: &CoarseReport,
    params: &FitParams,
    reach: Reach,
    parents: &mut Vec<[(u32, f64); 3]>,
    progress: &Progress,
) -> Result<(Fine, Rbf)> {
    let pair_fixed = coarse.pair_fixed(&params.pairs);
    let nv0 = pos.len() - parents.len();
    let mut flagged_per_round = Vec::new();
    let mut faces_added = 0;
    let budget = tris.len(); // subdivision may at most double the face count
    let mut best: Option<(Fine, Vec<Point3>, Vec<[u32; 3]>, Rbf)> = None;
    for round in 0..=params.max_flip_iterations {
        progress.check()?;
        let corr = correspond::closest(pos, net, &pair_fixed, progress)?;
        check_distances(&corr.distances, net, reach)?;
        let vop = corr.vertex_of_point.clone();
        let centres: Vec<Point3> = vop.iter().map(|&v| pos[v as usize]).collect();
        let values: Vec<Point3> = (0..vop.len()).map(|p| sub(net.points[p], centres[p])).collect();
        let name =
            |i: usize| format!("curve {} point {i} (template vertex {})", net.curve_of_point[i], vop[i]);
        let f = fit_rbf(centres, values, params, "fine", "curves", &name, progress)?;
        let augmented = f.in_plane();
        let disp = f.eval_many(pos, progress)?;
        let mut moved: Vec<Point3> = pos.iter().zip(&disp).map(|(p, d)| add(*p, *d)).collect();
        for (p, &v) in vop.iter().enumerate() {
            moved[v as usize] = net.points[p]; // exact, not RBF round-off
        }
        let scan = flips::detect_polled(pos, &moved, tris, progress)?;
        flagged_per_round.push(scan.flipped.len());
        let n = corr.distances.len().max(1) as f64;
        let flagged = scan.flipped.clone();
        let fine = Fine {
            positions: moved,
            vertex_of_point: vop,
            report: FineReport {
                rounds: round + 1,
                correspondence_conflicts: corr.conflicts,
                correspondence_distance_max: corr.distances.iter().cloned().fold(0.0, f64::max),
                correspondence_distance_mean: corr.distances.iter().sum::<f64>() / n,
                flagged_per_round: Vec::new(),
                flagged_by_counter: scan.by_counter,
                flagged_by_orientation: scan.by_orientation,
                faces_added,
                flipped_faces: scan.flipped.len(),
                coincident_centres: 0,
                augmented,
                matching: "nearest_vertex",
                insertion: None,
                steps_ms: None,
                approach: None,
                approach_ms: 0.0,
            },
        };
        // Keep the round with the fewest flips; a round that does not improve stops the loop
        // (measured on homer: 52 → 23 → 37 → 98 → 375 flagged faces when it goes on, because the
        // new, smaller faces fold in the same steep part of the field).
        let matched_now = fine.vertex_of_point.clone();
        let improves = best.as_ref().is_none_or(|b| fine.report.flipped_faces < b.0.report.flipped_faces);
        if improves {
            best = Some((fine, pos.clone(), tris.clone(), f));
        }
        let done = flagged.is_empty()
            || !improves
            || round == params.max_flip_iterations
            || faces_added + 3 * flagged.len() * 2 > budget;
        if done {
            break;
        }
        // Subdivide the flagged faces and the stars of the matched vertices on them: a fold
        // usually comes from a curve vertex matched to a template vertex a whole edge away, and
        // the star's new edge midpoints give it a closer candidate in the next round.
        let split = flips::with_matched_stars(tris, &flagged, &matched_now);
        faces_added += flips::subdivide(pos, tris, &split, parents);
    }
    if let Some((mut fine, p, t, f)) = best {
        parents.truncate(p.len() - nv0);
        *pos = p;
        *tris = t;
        fine.report.flagged_per_round = flagged_per_round;
        return Ok((fine, f));
    }
    Err(Error::Internal("flip loop ended without a result".into()))
}

/// Stage 3: the approach levels, the refinement under dense curves, then the fine RBF by the
/// matching rule ([`fine_dispatch`]). `parents` gets the weighted parents of every vertex added.
#[allow(clippy::too_many_arguments)]
pub(super) fn fine_stage(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    parents: &mut Vec<[(u32, f64); 3]>,
    orientation: &mut Orientation,
    net: &curves::CurveNetwork,
    coarse: &CoarseReport,
    params: &FitParams,
    reach: Reach,
    progress: &Progress,
) -> Result<(Fine, refine::RefineReport)> {
    let clock = std::time::Instant::now();
    let pair_fixed = coarse.pair_fixed(&params.pairs);
    let levels = params.approach_levels as usize;
    let limit = reach.limit();
    let approach = approach::approach(
        pos,
        tris,
        parents,
        net,
        &pair_fixed,
        params.kernel,
        levels,
        limit,
        params.thin_rim_feet,
        orientation,
        progress,
    )?;
    let approach_ms = clock.elapsed().as_secs_f64() * 1e3;
    // Faces of the approached template under dense curves are split, so no face has to hold
    // many curve vertices (after the approach: feet of curves still far from a coarse surface
    // cluster where it is closest, which is no density of the curves).
    let budget = tris.len() + super::REFINE_FACES_PER_CURVE_VERTEX * net.points.len();
    let (dense, max) = (params.refine_dense_feet, params.refine_max_feet);
    // One closest-point search (a BVH over the approached template) for the refinement's
    // density check and the insertion's feet; the refinement replaces it when it splits.
    let mut search = insert::FootSearch::new_polled(pos, tris, progress)?;
    let mut refined =
        refine::refine_near_curves(pos, tris, net, &mut search, dense, max, budget, parents, progress)?;
    refined.ms = clock.elapsed().as_secs_f64() * 1e3 - approach_ms;
    let mut fine =
        fine_dispatch(pos, tris, net, coarse, params, reach, parents, search, orientation, progress)?;
    fine.report.approach = Some(approach);
    fine.report.approach_ms = approach_ms;
    Ok((fine, refined))
}
