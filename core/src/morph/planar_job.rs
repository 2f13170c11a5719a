//! The morph pipeline on the planar domain, for disk-like inputs (one boundary loop, genus 0).
//!
//! Stages (each timed): `validate` (every input a disk) → `normalise` (as the spherical path:
//! PCA frame, optional ICP; then each input's faces oriented so its mean normal is +z in its
//! normalised frame, which makes the boundary correspondences of all inputs of one handedness) →
//! `parameterise` ([`super::planar`]: ELRP, Tutte fallback, flip check) → `align_features`
//! (boundary rotation onto input 0, then the planar CTPS C²a warp) → `common_boundary` →
//! `metamesh` (planar overlay, or the pseudo-metamesh / transfer) → `interpolate` → `glb`
//! (→ `frames_zip`) → `report`.
//!
//! The domain is chosen, and with `repair` the inputs are prepared (every hole but the outer
//! boundary filled), by [`super::domain`] before this runs.

use rayon::prelude::*;
use serde_json::json;

use crate::error::{Error, Result};
use crate::geometry::{add, triangle_cross};
use crate::job::{Output, Progress, Stages};

use super::domain::Prepared;
use super::metamesh::{self, Layer};
use super::planar::{self, CommonDisk, DiskMap, PlanarReport, PlaneAlignReport};
use super::plane_overlay::{self, DiskLayer};
use super::pseudo::{self, Domain};
use super::stages::{self, Chain, Finish, Triangulated};
use super::trimesh::{TopologyInfo, TriMesh};
use super::{input_name, Correspondence, MorphParams};

/// The planar pipeline on inputs prepared by [`super::domain::prepare`] (stages continue `stages`).
pub fn run(prep: Prepared, params: &MorphParams, progress: &Progress, mut stages: Stages) -> Result<Output> {
    let Prepared { meshes: inputs, vertex_maps, repair: repair_reports, reason, .. } = prep;
    let k_in = inputs.len();

    let inputs = stages.run(progress, "validate", || {
        stages::triangulate_inputs(&inputs, &vertex_maps, params.max_vertices, |k, info| {
            require_disk(k, info, &reason, params.repair)
        })
    })?;
    let features = stages::map_features(&params.features, &inputs.maps, k_in)?;

    // Normalise (as the spherical path), then orient each disk's normal to +z.
    let (normalised, frames_out, icp_reports, flipped) = stages.run(progress, "normalise", || {
        let (mut norm, frames, icp) = stages::normalise(&inputs.meshes, params.registration, progress)?;
        let flipped: Vec<bool> = norm.iter_mut().map(orient_up).collect();
        Ok((norm, frames, icp, flipped))
    })?;

    let mut disks: Vec<DiskMap> = stages.run(progress, "parameterise", || {
        normalised
            .par_iter()
            .map(|m| planar::parameterise(m, params.planar_method))
            .collect::<Result<Vec<_>>>()
    })?;
    let param_reports: Vec<PlanarReport> = disks.iter().map(|d| d.report.clone()).collect();
    reject_plane_foldovers(&param_reports)?;

    let align_rep = stages.run(progress, "align_features", || {
        align_disks(&mut disks, &normalised, &features, params, progress)
    })?;
    stages::reject_warp_foldovers(align_rep.foldovers, "the planar warp")?;

    let common = stages.run(progress, "common_boundary", || common_boundary(&normalised, &disks))?;
    let chain = stages.run(progress, "metamesh", || correspond(&common, params, progress))?;

    // Overlay faces lie inside input faces, so their vertices bound the distance; otherwise the
    // Hausdorff distance is sampled.
    let exact = chain.exact(params.correspondence);
    let (mut report, meshes, artifacts) = stages::finish(
        stages,
        params,
        progress,
        Finish { layer: &chain.layer, frames_out: &frames_out, normalised: &normalised, exact },
    )?;
    let per_input =
        per_input_report(&inputs, &flipped, &param_reports, &common, &report["hausdorff_per_input"]);
    stages::merge_report(
        &mut report,
        json!({
            "domain": "planar",
            "domain_reason": reason,
            "angle_distortion": param_reports.iter().map(|r| r.angle_distortion).collect::<Vec<_>>(),
            "area_distortion": param_reports.iter().map(|r| r.area_distortion).collect::<Vec<_>>(),
            "foldovers": param_reports.iter().map(|r| r.foldovers).collect::<Vec<_>>(),
            "correspondence": stages::correspondence_name(params.correspondence, &chain.fallback),
            "correspondence_fallback": chain.fallback,
            "overlays": chain.overlays,
            "pseudo_metamesh": chain.pseudo,
            "common_boundary_vertices": common[0].bnd.iter().filter(|&&b| b != u32::MAX).count(),
            "warnings": super::report::feature_warnings(
                align_rep.feature_points,
                align_rep.max_feature_gap_after,
                "(unit-disk lengths)",
            ),
            "features": align_rep,
            "icp": icp_reports,
            "repair": repair_reports,
            "per_input": per_input,
        }),
    );
    Ok(Output { meshes, artifacts, report })
}

/// `Topology` unless input `k` is a disk, saying what it is instead and, without `repair`,
/// whether the repair would mend it.
fn require_disk(k: usize, info: &TopologyInfo, reason: &str, repaired: bool) -> Result<()> {
    if planar::is_disk(info) {
        return Ok(());
    }
    let hint = if repaired {
        " after repair"
    } else if info.boundary_loops > 1 || info.components > 1 || planar::genus_of(info).is_none() {
        " (`repair: true` mends holes, non-manifold parts and stray pieces)"
    } else {
        ""
    };
    Err(Error::Topology(format!(
        "{}: the morph uses the planar domain ({reason}), so every input must be a disk \
         (connected, manifold, one boundary loop, genus 0); found {}{hint}",
        input_name(k),
        planar::describe(info),
    )))
}

/// Turns the faces so the mesh's area-weighted mean normal points to +z; true if it had to.
fn orient_up(m: &mut TriMesh) -> bool {
    let n = m.tris.iter().fold([0.0; 3], |s, t| {
        add(s, triangle_cross(m.pos[t[0] as usize], m.pos[t[1] as usize], m.pos[t[2] as usize]))
    });
    if n[2] < 0.0 {
        for t in &mut m.tris {
            t.swap(1, 2);
        }
        true
    } else {
        false
    }
}

/// A disk map with flipped triangles would make the overlay meaningless: refuse it, naming the
/// input.
fn reject_plane_foldovers(reports: &[PlanarReport]) -> Result<()> {
    for (k, r) in reports.iter().enumerate() {
        if r.foldovers > 0 {
            return Err(Error::numerical(
                "parameterise",
                format!("{}: {} flipped plane triangles remain", input_name(k), r.foldovers),
            ));
        }
    }
    Ok(())
}

/// Rotates every disk onto input 0's (by the features when they fix a rotation, else by the
/// boundary shape), then warps the disks so the feature vertices meet.
fn align_disks(
    disks: &mut [DiskMap],
    normalised: &[TriMesh],
    features: &[Vec<u32>],
    params: &MorphParams,
    progress: &Progress,
) -> Result<PlaneAlignReport> {
    let mut rep = PlaneAlignReport {
        feature_points: features.len(),
        boundary_rotation: vec![0.0],
        rotation_rule: if features.is_empty() { "boundary_shape" } else { "features" }.into(),
        ..Default::default()
    };
    for k in 1..disks.len() {
        let phi = rotation_onto_input0(disks, normalised, features, k);
        planar::rotate(&mut disks[k], phi);
        rep.boundary_rotation.push(phi);
    }
    if !features.is_empty() {
        let tris: Vec<&[[u32; 3]]> = normalised.iter().map(|m| &m.tris[..]).collect();
        let (folds, steps, before, after) = planar::align_features(
            disks,
            &tris,
            features,
            params.feature_steps,
            params.support_radius,
            progress,
        )?;
        rep.foldovers = folds;
        rep.warp_steps = steps;
        rep.max_feature_gap_before = before;
        rep.max_feature_gap_after = after;
    }
    Ok(rep)
}

/// The angle that turns disk `k` onto disk 0: from the features when there are any and they fix
/// it, else from the boundary shapes.
fn rotation_onto_input0(disks: &[DiskMap], normalised: &[TriMesh], features: &[Vec<u32>], k: usize) -> f64 {
    let by_features = if features.is_empty() {
        None
    } else {
        let f0: Vec<u32> = features.iter().map(|f| f[0]).collect();
        let fk: Vec<u32> = features.iter().map(|f| f[k]).collect();
        planar::feature_rotation(&disks[0].plane, &f0, &disks[k].plane, &fk)
    };
    by_features.unwrap_or_else(|| {
        planar::boundary_rotation(
            &normalised[0].pos,
            &disks[0].boundary,
            &disks[0].angles,
            &normalised[k].pos,
            &disks[k].boundary,
            &disks[k].angles,
        )
    })
}

/// Every disk with the union of all inputs' boundary angles as its rim, so the overlay sees one
/// common boundary. Inputs after the first get their interior jittered (a deterministic seed per
/// input) so no two inputs' interior vertices coincide exactly.
fn common_boundary(normalised: &[TriMesh], disks: &[DiskMap]) -> Result<Vec<CommonDisk>> {
    let union = planar::union_angles(disks);
    let mut out = Vec::with_capacity(disks.len());
    for (k, (m, d)) in normalised.iter().zip(disks).enumerate() {
        let mut c = planar::with_common_boundary(m, d, &union)?;
        let f = planar::foldovers(&c.plane, &c.tris);
        if f > 0 {
            return Err(Error::numerical(
                "common_boundary",
                format!("{}: {f} flipped triangles after inserting the common boundary", input_name(k)),
            ));
        }
        if k > 0 {
            planar::jitter_interior(&mut c, k as u64);
        }
        out.push(c);
    }
    Ok(out)
}

/// Chains the correspondence through the disks: input 0 with input 1, that result with input
/// 2, and so on, each step a planar overlay (the barycentric transfer when the overlay fails
/// numerically), a transfer or a pseudo-metamesh, as `params.correspondence` asks.
fn correspond(common: &[CommonDisk], params: &MorphParams, progress: &Progress) -> Result<Chain> {
    let layers: Vec<DiskLayer> = common
        .iter()
        .map(|c| DiskLayer {
            layer: Layer { sphere: c.plane.clone(), tris: c.tris.clone(), shapes: vec![c.pos.clone()] },
            bnd: c.bnd.clone(),
        })
        .collect();
    let mut acc = layers[0].clone();
    let (mut overlays, mut pseudo_reps, mut fallback) = (Vec::new(), Vec::new(), None);
    for l in &layers[1..] {
        acc = match params.correspondence {
            Correspondence::Overlay => match plane_overlay::overlay(&acc, l, progress) {
                Ok((o, r)) => {
                    overlays.push(r);
                    o
                }
                Err(Error::Numerical { message, .. }) => {
                    fallback = Some(format!("overlay failed ({message}); used the barycentric transfer"));
                    DiskLayer { layer: metamesh::transfer(&acc.layer, &l.layer, progress)?, bnd: acc.bnd }
                }
                Err(e) => return Err(e),
            },
            Correspondence::Transfer => {
                DiskLayer { layer: metamesh::transfer(&acc.layer, &l.layer, progress)?, bnd: acc.bnd }
            }
            Correspondence::Pseudo => {
                let (p, r) =
                    pseudo::pseudo(&acc.layer, &l.layer, Domain::Plane, params.pseudo_max_depth, progress)?;
                pseudo_reps.push(r);
                let n = p.sphere.len();
                DiskLayer { layer: p, bnd: vec![u32::MAX; n] }
            }
        };
    }
    Ok(Chain { layer: acc.layer, overlays, fallback, pseudo: pseudo_reps, perturbation: Vec::new() })
}

/// The report's `per_input` rows.
fn per_input_report(
    inputs: &Triangulated,
    flipped: &[bool],
    param_reports: &[PlanarReport],
    common: &[CommonDisk],
    hausdorff: &serde_json::Value,
) -> Vec<serde_json::Value> {
    (0..inputs.meshes.len())
        .map(|k| {
            let specific = json!({
                "parameterisation": param_reports[k],
                "common_boundary_vertices_inserted": common[k].inserted,
            });
            stages::per_input_row(inputs, k, flipped[k], hausdorff, specific)
        })
        .collect()
}
