//! The coarse stage: the user's pairs through an RBF (eq. 2.6–2.10), or PCA + ICP, and the RBF
//! fit with its named errors and coplanar policy (shared with the fine stage).

use serde::Serialize;

use crate::error::{Error, Result};
use crate::geometry::{add, dist, sub, Aabb};
use crate::job::Progress;
use crate::mesh::Point3;

use super::orientation::{mat_mul, Orientation};
use super::{align, curves, kdtree, rbf, Alignment, CoplanarCentres, FitPair, FitParams};

/// What the coarse stage did (serialised into the report).
#[derive(Debug, Clone, Serialize)]
pub struct CoarseReport {
    /// "pairs" (coarse RBF through the pairs), "pairs_similarity" (pairs on one line, with
    /// `coplanar_centres = "augment"`: similarity from the pairs + ICP + warp), "pca_icp"
    /// (no pairs: PCA + ICP + warp) or "none".
    pub method: &'static str,
    /// Curve vertex each pair snapped to, per pair.
    pub pair_curve_points: Vec<u32>,
    pub pair_snap_distance_max: f64,
    /// PCA + ICP final RMS distance of curve points to template vertices.
    pub icp_rms: Option<f64>,
    /// The smooth (affine, then quadratic) warp fitted after the ICP (`pca_icp` only).
    pub warp: Option<align::WarpReport>,
    /// `pca_icp`: the distinct poses (rotations > 20° apart) the search kept, the chosen one
    /// first; the contenders were warped and the one whose warp ends closest to the curves chosen.
    pub candidates: Vec<CandidateReport>,
    /// `pca_icp`: the runner-up pose fits the curves about as well as the chosen one
    /// (score within [`AMBIGUOUS_RATIO`]) although it is turned far from it: typical of a
    /// nearly symmetric template (a flat figure and its mirror image). The result may be the
    /// wrong one of the two; give pairs.
    pub ambiguous: bool,
    /// Why `ambiguous` is set, in words, for the user.
    pub warning: Option<String>,
    /// `pca_icp`: the chosen pose against the template as placed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub placed: Option<PlacedReport>,
}

/// The automatic alignment's pose against the template as it was given. A template that lay on
/// the curves (`on_curves`) and was turned far (`turned_deg`) may have been placed on purpose:
/// `alignment: "none"` keeps it. No warning: a symmetric template (a sphere) is turned among
/// equally good poses all the time (68 of `sweep_unseen`'s rows), and the poses' scores do not say
/// which turns matter.
#[derive(Debug, Clone, Serialize)]
pub struct PlacedReport {
    /// RMS distance of the curve points to the template's nearest vertices as placed, over the
    /// template's bounding-box diagonal.
    pub rms_relative: f64,
    /// The curves lay on the template as placed (`rms_relative` ≤ [`align::PLACED_NEAR`]); the
    /// pose as placed was then one of the search's starts.
    pub on_curves: bool,
    /// Rotation of the chosen pose from the pose as placed, degrees.
    pub turned_deg: f64,
    /// Its scale.
    pub scale: f64,
    /// How far it moved the template's centre, over the template's bounding-box diagonal.
    pub moved_relative: f64,
}

impl PlacedReport {
    fn new(rms_relative: f64, template: &[Point3], chosen: &align::Similarity) -> PlacedReport {
        let bb = Aabb::of(template);
        let diag = bb.map_or(0.0, |b| b.diagonal()).max(f64::MIN_POSITIVE);
        let centre = bb.map_or([0.0; 3], |b| b.center());
        PlacedReport {
            rms_relative,
            on_curves: rms_relative <= align::PLACED_NEAR,
            turned_deg: align::rotation_angle_deg(&chosen.r, &align::Similarity::PLACED.r),
            scale: chosen.s,
            moved_relative: dist(chosen.apply(centre), centre) / diag,
        }
    }
}

/// One pose tried by the automatic alignment.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateReport {
    /// RMS distance of the curve points to their nearest template vertices after the ICP.
    pub icp_rms: f64,
    /// The next three are `None` for a pose not warped (its ICP score was far behind).
    /// RMS distance of all curve points to the surface after the smooth warp (none trimmed).
    pub warp_rms: Option<f64>,
    /// Open template: RMS distance of the curve ends to the template's boundary after the warp
    /// (each capped at 5% of the curves' bounding-box diagonal).
    pub end_gap: Option<f64>,
    /// The choosing score: √(warp_rms² + end_gap²), smallest wins.
    pub score: Option<f64>,
    /// Rotation from the chosen pose, degrees.
    pub angle_deg: f64,
}

/// A runner-up whose score is within this factor of the winner's makes the choice ambiguous
/// (see [`CoarseReport::ambiguous`]).
pub const AMBIGUOUS_RATIO: f64 = 1.25;

impl CoarseReport {
    /// (curve point, template vertex) of every user pair, the points the later stages hold fixed.
    pub fn pair_fixed(&self, pairs: &[FitPair]) -> Vec<(u32, u32)> {
        self.pair_curve_points.iter().zip(pairs).map(|(&p, pr)| (p, pr.template_vertex)).collect()
    }
}

/// Iterations per degree of the smooth warp after the ICP (each: one closest-point pass).
const WARP_ITERATIONS: u32 = 30;

pub(super) fn coarse_alignment(
    pos: &mut [Point3],
    tris: &[[u32; 3]],
    net: &curves::CurveNetwork,
    params: &FitParams,
    orientation: &mut Orientation,
    progress: &Progress,
) -> Result<CoarseReport> {
    let use_pairs = match params.alignment {
        Alignment::Pairs => true,
        Alignment::Auto => !params.pairs.is_empty(),
        _ => false,
    };
    if use_pairs {
        let (fixed, snap_max) = snap_pairs(&params.pairs, pos.len(), net, params.max_curve_distance)?;
        if params.coplanar_centres == CoplanarCentres::Augment && pairs_on_a_line(pos, &fixed, net) {
            return pairs_similarity(pos, tris, net, &fixed, snap_max, orientation, progress);
        }
        let centres: Vec<Point3> = fixed.iter().map(|&(_, v)| pos[v as usize]).collect();
        let values: Vec<Point3> =
            fixed.iter().map(|&(p, v)| sub(net.points[p as usize], pos[v as usize])).collect();
        let name = |i: usize| format!("pairs[{i}] (template vertex {})", params.pairs[i].template_vertex);
        let f = fit_rbf(centres, values, params, "coarse", "pairs", &name, progress)?;
        let disp = f.eval_many(pos, progress)?;
        orientation.push(pos, |_, p| plus_identity(f.gradient(p)));
        for (p, d) in pos.iter_mut().zip(disp) {
            *p = add(*p, d);
        }
        for &(p, v) in &fixed {
            pos[v as usize] = net.points[p as usize];
        }
        return Ok(CoarseReport {
            method: "pairs",
            pair_curve_points: fixed.iter().map(|x| x.0).collect(),
            pair_snap_distance_max: snap_max,
            icp_rms: None,
            warp: None,
            candidates: vec![],
            ambiguous: false,
            warning: None,
            placed: None,
        });
    }
    if matches!(params.alignment, Alignment::None) {
        return Ok(CoarseReport {
            method: "none",
            pair_curve_points: vec![],
            pair_snap_distance_max: 0.0,
            icp_rms: None,
            warp: None,
            candidates: vec![],
            ambiguous: false,
            warning: None,
            placed: None,
        });
    }
    automatic(pos, tris, net, orientation, progress)
}

/// I + g: the Jacobian of x ↦ x + s(x) from the field's gradient g.
pub(super) fn plus_identity(g: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut j = g;
    for (k, row) in j.iter_mut().enumerate() {
        row[k] += 1.0;
    }
    j
}

/// No pairs: PCA + similarity ICP, then the smooth warp from every contender pose (ICP score
/// close to the best); the pose whose warp ends closest to the curves wins.
///
/// The ICP score alone cannot tell a nearly symmetric template from its mirror pose (both put
/// every curve point near some template vertex), and on a flat template curves lying inside the
/// outline fit anywhere. What tells poses apart is where the curves leave the template: the
/// choosing score is the RMS distance of *all* curve points to the warped surface (the warp's
/// own fit trims exactly the points that run off the template) and, on an open template, the
/// RMS distance of the curve ends to its rim (sections of an open surface end on its boundary;
/// each end's gap is capped at [`END_GAP_CAP`] of the curves' size, so a curve that really
/// stops inside the surface weighs the same in every pose). A runner-up within
/// [`AMBIGUOUS_RATIO`] of the winner is reported as an ambiguity rather than hidden.
fn automatic(
    pos: &mut [Point3],
    tris: &[[u32; 3]],
    net: &curves::CurveNetwork,
    orientation: &mut Orientation,
    progress: &Progress,
) -> Result<CoarseReport> {
    let rim = Rim::new(tris, net, progress)?;
    // The ends' rim matches only for curves in one plane ([`PLANAR_CURVES`]).
    let no_ends: Vec<Point3> = Vec::new();
    let planar = rbf::spread_ratios(&net.points)[0] < PLANAR_CURVES;
    let ends =
        align::RimEnds { edges: &rim.edges, ends: if planar { &rim.ends } else { &no_ends }, cap: rim.cap };
    let search = align::pca_icp_candidates(pos, &net.points, 30, 3, progress)?;
    let candidates = search.candidates;
    let mut tried: Vec<(align::Candidate, Option<(Vec<Point3>, align::WarpReport, f64, Option<f64>)>)> =
        Vec::new();
    // The contenders' scores with the warp of the curve points alone, when the rim term changes
    // anything ([`plain_scores`]).
    let plain = if planar { plain_scores(pos, tris, net, &rim, &candidates, progress)? } else { Vec::new() };
    for c in candidates {
        let warped = if c.contender {
            let mut p: Vec<Point3> = pos.iter().map(|&x| c.sim.apply(x)).collect();
            let w = warp_to_curves(&mut p, tris, net, Some(&ends), progress)?;
            let gap = rim.end_gap(&p);
            let score = (w.rms_all_after.powi(2) + gap.unwrap_or(0.0).powi(2)).sqrt();
            Some((p, w, score, gap))
        } else {
            None
        };
        tried.push((c, warped));
    }
    let score = |t: &(align::Candidate, Option<(Vec<Point3>, align::WarpReport, f64, Option<f64>)>)| {
        t.1.as_ref().map_or(f64::INFINITY, |w| w.2)
    };
    tried.sort_by(|a, b| score(a).total_cmp(&score(b)));
    let Some((chosen, Some((warped, warp, best, _)))) = tried.first().cloned() else {
        return Err(Error::Internal("automatic alignment found no pose".into()));
    };
    // (Before the template moves: against where it was given.)
    let placed = PlacedReport::new(search.placed_rms_relative, pos, &chosen.sim);
    // The template's normals through the chosen similarity and its warp.
    let sim = chosen.sim.jacobian();
    orientation.push(pos, |_, p| mat_mul(&warp.map.jacobian(chosen.sim.apply(p)), &sim));
    pos.copy_from_slice(&warped);
    let candidates: Vec<CandidateReport> = tried
        .iter()
        .map(|(c, w)| CandidateReport {
            icp_rms: c.icp_rms,
            warp_rms: w.as_ref().map(|w| w.1.rms_all_after),
            end_gap: w.as_ref().and_then(|w| w.3),
            score: w.as_ref().map(|w| w.2),
            angle_deg: align::rotation_angle_deg(&c.sim.r, &chosen.sim.r),
        })
        .collect();
    let runner_up = tried.get(1).map(score).unwrap_or(f64::INFINITY);
    let ambiguous =
        runner_up <= AMBIGUOUS_RATIO * best || (plain.len() > 1 && plain[1] <= AMBIGUOUS_RATIO * plain[0]);
    let warning = ambiguous.then(|| {
        format!(
            "automatic alignment is ambiguous: a pose turned {:.0}° from the chosen one fits the curves almost \
             as well (score {:.3e} vs {:.3e}); the template may be placed the wrong way round (e.g. as its \
             mirror image): give correspondence pairs",
            candidates[1].angle_deg, runner_up, best
        )
    });
    Ok(CoarseReport {
        method: "pca_icp",
        pair_curve_points: vec![],
        pair_snap_distance_max: 0.0,
        icp_rms: Some(chosen.icp_rms),
        warp: Some(warp),
        candidates,
        ambiguous,
        warning,
        placed: Some(placed),
    })
}

/// The contenders' scores (as in [`automatic`]) after the warp without the curve ends' rim
/// matches, best first; empty when the template has no rim or the network no ends (the warp is
/// then the same; the caller skips it for curves off one plane, which get no rim matches). Why: the rim matches let one pose's warp follow the curves far better than
/// another's, also when every contender is wrong: woody's bent sections (`fit_align.rs`), whose
/// contenders are all turned 40–180° from the truth, scored 1.35× apart with them and within
/// 1.25× without. An ambiguity either warp sees is reported (session 12, fit-raw).
fn plain_scores(
    pos: &[Point3],
    tris: &[[u32; 3]],
    net: &curves::CurveNetwork,
    rim: &Rim,
    candidates: &[align::Candidate],
    progress: &Progress,
) -> Result<Vec<f64>> {
    if rim.edges.is_empty() || rim.ends.is_empty() {
        return Ok(Vec::new());
    }
    let mut scores = Vec::new();
    for c in candidates.iter().filter(|c| c.contender) {
        let mut p: Vec<Point3> = pos.iter().map(|&x| c.sim.apply(x)).collect();
        let w = warp_to_curves(&mut p, tris, net, None, progress)?;
        scores.push((w.rms_all_after.powi(2) + rim.end_gap(&p).unwrap_or(0.0).powi(2)).sqrt());
    }
    scores.sort_by(f64::total_cmp);
    Ok(scores)
}

/// The smooth warp of a placed template towards the curve points ([`align::warp_icp`]), with the
/// curves' median segment as the trim floor's spacing and the rim matches of `ends`, if any.
fn warp_to_curves(
    pos: &mut [Point3],
    tris: &[[u32; 3]],
    net: &curves::CurveNetwork,
    ends: Option<&align::RimEnds>,
    progress: &Progress,
) -> Result<align::WarpReport> {
    let spacing = super::approach::median_segment(net);
    align::warp_icp(pos, tris, &net.points, spacing, ends, WARP_ITERATIONS, progress)
}

/// Curves whose smallest spread is under this share of the largest lie in one plane: the warp then
/// matches their ends to the rim ([`align::RimEnds`]). Why only then: curves in the plane of a flat
/// template lie on it wherever it sits in that plane, every closest-point match is ~0 and only the
/// ends tell the pose (woody and alligator raw under their own sections). Curves off that plane
/// (sweep_fit's bent sections of the same meshes) do carry normal distances; there the rim matches
/// moved woody's row, whose every contender is a wrong pose, from 10 to 9 of 11 regions at every
/// weight tried (1/10–1/3) (session 12, fit-raw).
const PLANAR_CURVES: f64 = 1e-3;

/// Each curve end's gap to the rim is capped at this × the curves' bounding-box diagonal (see
/// [`automatic`]).
pub const END_GAP_CAP: f64 = 0.05;

/// Template faces counted between two polls by [`Rim::new`].
const RIM_POLL_FACES: usize = 16_384;

/// The template's boundary edges and the curve ends, for the end-to-rim term of [`automatic`].
struct Rim {
    edges: Vec<(u32, u32)>,
    ends: Vec<Point3>,
    cap: f64,
}

impl Rim {
    /// Polls every [`RIM_POLL_FACES`] faces (the edge count was ~50 ms of CPU without a poll on
    /// a 96k-vertex template).
    fn new(tris: &[[u32; 3]], net: &curves::CurveNetwork, progress: &Progress) -> Result<Rim> {
        let mut count: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        for (f, t) in tris.iter().enumerate() {
            progress.check_every(f, RIM_POLL_FACES)?;
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        progress.check()?;
        let mut edges: Vec<(u32, u32)> = count.into_iter().filter(|x| x.1 == 1).map(|x| x.0).collect();
        edges.sort_unstable();
        let all: Vec<Point3> =
            (0..net.points.len()).filter(|&p| net.degree[p] == 1).map(|p| net.points[p]).collect();
        // A spread subset bounds the cost (ends × rim edges) on networks with many loose ends.
        let ends = all.iter().step_by(all.len().div_ceil(200).max(1)).copied().collect();
        let cap = END_GAP_CAP * Aabb::of(&net.points).map_or(0.0, |b| b.diagonal());
        Ok(Rim { edges, ends, cap })
    }

    /// RMS of the capped end-to-rim distances; `None` on a closed template or without ends.
    fn end_gap(&self, pos: &[Point3]) -> Option<f64> {
        if self.edges.is_empty() || self.ends.is_empty() {
            return None;
        }
        let sum: f64 = self
            .ends
            .iter()
            .map(|&e| {
                self.edges
                    .iter()
                    .map(|&(a, b)| super::point_segment_distance(e, pos[a as usize], pos[b as usize]))
                    .fold(self.cap, f64::min)
                    .powi(2)
            })
            .sum();
        Some((sum / self.ends.len() as f64).sqrt())
    }
}

/// Pairs too few or too close to one line (on either side) for the coarse RBF, even with the
/// normal augmentation: on a flat template the normals add the one direction the plane lacks,
/// but pairs along one line of it leave the direction across the line free, and the RBF's
/// affine part extrapolates without bound there (measured: woody's 4 pairs, all on one section,
/// put the curves 0.33 × the diagonal off the template).
fn pairs_on_a_line(pos: &[Point3], fixed: &[(u32, u32)], net: &curves::CurveNetwork) -> bool {
    let centres: Vec<Point3> = fixed.iter().map(|&(_, v)| pos[v as usize]).collect();
    let targets: Vec<Point3> = fixed.iter().map(|&(p, _)| net.points[p as usize]).collect();
    fixed.len() >= 2
        && (fixed.len() < 4
            || rbf::spread_ratios(&centres)[1] < 0.05
            || rbf::spread_ratios(&targets)[1] < 0.05)
}

/// The fallback for [`pairs_on_a_line`]: a similarity from the pairs, completed by ICP against
/// the curves (the pairs weighted in), then the smooth warp. The fine stage still lands every
/// pair's template vertex exactly on its curve vertex.
fn pairs_similarity(
    pos: &mut [Point3],
    tris: &[[u32; 3]],
    net: &curves::CurveNetwork,
    fixed: &[(u32, u32)],
    snap_max: f64,
    orientation: &mut Orientation,
    progress: &Progress,
) -> Result<CoarseReport> {
    let pairs: Vec<(Point3, Point3)> =
        fixed.iter().map(|&(p, v)| (pos[v as usize], net.points[p as usize])).collect();
    let (sim, rms) = align::pairs_icp(pos, &net.points, &pairs, 30, progress)?;
    orientation.push(pos, |_, _| sim.jacobian());
    for p in pos.iter_mut() {
        *p = sim.apply(*p);
    }
    let before_warp = pos.to_vec();
    let warp = warp_to_curves(pos, tris, net, None, progress)?;
    orientation.push(&before_warp, |_, p| warp.map.jacobian(p));
    Ok(CoarseReport {
        method: "pairs_similarity",
        pair_curve_points: fixed.iter().map(|x| x.0).collect(),
        pair_snap_distance_max: snap_max,
        icp_rms: Some(rms),
        warp: Some(warp),
        candidates: vec![],
        ambiguous: false,
        warning: None,
        placed: None,
    })
}

/// Validates the pairs and snaps each curve point to its nearest curve vertex. A point farther
/// than `max_distance` × the curves' bounding-box diagonal from every curve vertex is an error (a
/// typo or a point in other units would otherwise pull the template onto the wrong vertex).
fn snap_pairs(
    pairs: &[FitPair],
    nv: usize,
    net: &curves::CurveNetwork,
    max_distance: f64,
) -> Result<(Vec<(u32, u32)>, f64)> {
    let tree = kdtree::KdTree::new(&net.points);
    let limit = max_distance * Aabb::of(&net.points).map_or(0.0, |b| b.diagonal());
    let mut out: Vec<(u32, u32)> = Vec::with_capacity(pairs.len());
    let mut snap_max = 0.0f64;
    for (i, p) in pairs.iter().enumerate() {
        if p.template_vertex as usize >= nv {
            return Err(Error::params(
                format!("pairs[{i}].template_vertex"),
                format!("vertex {} does not exist (the template has {nv} vertices)", p.template_vertex),
            ));
        }
        if !p.curve_point.iter().all(|c| c.is_finite()) {
            return Err(Error::params(format!("pairs[{i}].curve_point"), "coordinate is NaN or infinite"));
        }
        // A point so far away that its squared distance overflows (1e300) has no nearest vertex
        // in the tree: it is as far as can be, the same error ("far from every curve vertex").
        let nearest = tree.nearest(p.curve_point).filter(|&(_, d2)| d2.sqrt() <= limit);
        let Some((cp, d2)) = nearest else {
            let d = net.points.iter().map(|&q| dist(q, p.curve_point)).fold(f64::INFINITY, f64::min);
            return Err(Error::params(
                format!("pairs[{i}].curve_point"),
                format!(
                    "{:?} is {d:.4e} from the nearest curve vertex, more than max_curve_distance ({}) \
                     × the curves' bounding-box diagonal ({limit:.4} in all): give a point on the curves",
                    p.curve_point, max_distance
                ),
            ));
        };
        snap_max = snap_max.max(d2.sqrt());
        if let Some(j) = out.iter().position(|&(_, v)| v == p.template_vertex) {
            return Err(Error::params(
                format!("pairs[{i}].template_vertex"),
                format!("pairs[{j}] and pairs[{i}] use the same template vertex {}", p.template_vertex),
            ));
        }
        if let Some(j) = out.iter().position(|&(c, _)| c == cp) {
            return Err(Error::params(
                format!("pairs[{i}].curve_point"),
                format!("pairs[{j}] and pairs[{i}] snap to the same curve vertex {cp}"),
            ));
        }
        out.push((cp, p.template_vertex));
    }
    Ok((out, snap_max))
}

/// RBF through the centres with the named-error checks and the coplanar policy.
pub(super) fn fit_rbf(
    centres: Vec<Point3>,
    values: Vec<Point3>,
    params: &FitParams,
    stage: &str,
    field: &str,
    name: &dyn Fn(usize) -> String,
    progress: &Progress,
) -> Result<rbf::Rbf> {
    use rbf::Degenerate;
    // The targets matter as much as the centres: template vertices picked near a straight or flat
    // curve set are only *nearly* collinear/coplanar, which passes the exact check but leaves the
    // affine part undetermined (the fit then explodes). So both sets are tested, with a looser
    // threshold on the targets.
    let targets: Vec<Point3> = centres.iter().zip(&values).map(|(c, v)| add(*c, *v)).collect();
    let [flat, thin] = rbf::spread_ratios(&targets);
    if centres.len() >= 4 && thin < 1e-3 {
        return Err(Error::params(
            field,
            format!(
                "the {} {stage} RBF targets lie on one line (spread ratio {thin:.1e}): a single straight curve \
                 cannot define a deformation; add curves that span the surface",
                centres.len()
            ),
        ));
    }
    let check = match rbf::check_centres(&centres) {
        Ok(()) if centres.len() >= 4 && flat < 1e-3 => Err(Degenerate::Coplanar(flat)),
        other => other,
    };
    match check {
        Ok(()) => {}
        Err(Degenerate::TooFew(n)) => {
            return Err(Error::params(
                field,
                format!("the {stage} RBF needs at least 4 non-coplanar centres, got {n}"),
            ))
        }
        Err(Degenerate::Duplicate(i, j)) => {
            return Err(Error::params(
                field,
                format!(
                "{} and {} are at the same position: duplicate RBF centres make the {stage} system singular",
                name(i),
                name(j)
            ),
            ))
        }
        Err(Degenerate::Coplanar(ratio)) => {
            if params.coplanar_centres == CoplanarCentres::Reject {
                return Err(Error::params(
                    field,
                    format!(
                        "all {} {stage} RBF centres lie on one plane (spread ratio {ratio:.1e}): the system is singular; \
                         give non-coplanar {field} or set coplanar_centres = \"augment\"",
                        centres.len()
                    ),
                ));
            }
            // The seed's remedy was centres offset along the vertex normals; see
            // [`rbf::Rbf::fit_in_plane`] for why the in-plane polynomial replaces it.
            return rbf::Rbf::fit_in_plane_polled(&centres, &values, params.kernel, stage, progress).map_err(
                |e| {
                    Error::params(
                        field,
                        format!("{stage} RBF centres are degenerate even in their plane: {e}"),
                    )
                },
            );
        }
    }
    rbf::Rbf::fit_polled(&centres, &values, params.kernel, stage, progress)
}
