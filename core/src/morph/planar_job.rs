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
use crate::job::{Artifact, Output, Progress, Stages};
use crate::mesh::{Mesh, Point3};
use crate::register::Similarity;

use super::domain::Prepared;
use super::metamesh::{self, Layer};
use super::planar::{self, DiskMap};
use super::plane_overlay::{self, DiskLayer};
use super::pseudo::{self, Domain};
use super::trimesh::{self, TriMesh};
use super::{input_name, output, report, Correspondence, MorphParams};

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

/// The planar pipeline on inputs prepared by [`super::domain::prepare`] (stages continue `stages`).
pub fn run(prep: Prepared, params: &MorphParams, progress: &Progress, mut stages: Stages) -> Result<Output> {
    let Prepared { meshes: inputs, vertex_maps: repair_maps, repair: repair_reports, reason, .. } = prep;
    let k_in = inputs.len();

    // 1. Validate: every input a disk.
    let (meshes, maps, conv, topo) = stages.run(progress, "validate", || {
        let (mut ms, mut maps, mut convs, mut topo) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (k, m) in inputs.iter().enumerate() {
            super::domain::check_vertex_limit(k, m, params.max_vertices)?;
            let (t, map, c) = TriMesh::from_mesh(m);
            let info = trimesh::topology(&t);
            if !planar::is_disk(&info) {
                return Err(Error::Topology(format!(
                    "{}: the morph uses the planar domain ({reason}), so every input must be a disk \
                     (connected, manifold, one boundary loop, genus 0); found {}{}",
                    input_name(k),
                    planar::describe(&info),
                    if params.repair {
                        " after repair"
                    } else if info.boundary_loops > 1
                        || info.components > 1
                        || planar::genus_of(&info).is_none()
                    {
                        " (`repair: true` mends holes, non-manifold parts and stray pieces)"
                    } else {
                        ""
                    }
                )));
            }
            ms.push(t);
            maps.push(super::domain::compose_vertex_maps(repair_maps[k].as_deref(), map));
            convs.push(c);
            topo.push(info);
        }
        Ok((ms, maps, convs, topo))
    })?;
    let features = super::map_features(&params.features, &maps, k_in)?;

    // 2. Normalise (as the spherical path), then orient each disk's normal to +z.
    let (normalised, frames_out, icp_reports, flipped) = stages.run(progress, "normalise", || {
        let (mut norm, frames, icp) = super::normalise(&meshes, params.registration, progress)?;
        let flipped: Vec<bool> = norm.iter_mut().map(orient_up).collect();
        Ok((norm, frames, icp, flipped))
    })?;

    // 3. Disk maps.
    let mut disks: Vec<DiskMap> = stages.run(progress, "parameterise", || {
        normalised
            .par_iter()
            .map(|m| planar::parameterise(m, params.planar_method))
            .collect::<Result<Vec<_>>>()
    })?;
    let param_reports: Vec<planar::PlanarReport> = disks.iter().map(|d| d.report.clone()).collect();
    for (k, r) in param_reports.iter().enumerate() {
        if r.foldovers > 0 {
            return Err(Error::numerical(
                "parameterise",
                format!("{}: {} flipped plane triangles remain", input_name(k), r.foldovers),
            ));
        }
    }

    // 4. Boundary correspondence and feature alignment.
    let align_rep = stages.run(progress, "align_features", || {
        let mut rep = planar::PlaneAlignReport {
            feature_points: features.len(),
            boundary_rotation: vec![0.0],
            rotation_rule: if features.is_empty() { "boundary_shape" } else { "features" }.into(),
            ..Default::default()
        };
        for k in 1..k_in {
            let phi = if features.is_empty() {
                None
            } else {
                let f0: Vec<u32> = features.iter().map(|f| f[0]).collect();
                let fk: Vec<u32> = features.iter().map(|f| f[k]).collect();
                planar::feature_rotation(&disks[0].plane, &f0, &disks[k].plane, &fk)
            };
            let phi = phi.unwrap_or_else(|| {
                planar::boundary_rotation(
                    &normalised[0].pos,
                    &disks[0].boundary,
                    &disks[0].angles,
                    &normalised[k].pos,
                    &disks[k].boundary,
                    &disks[k].angles,
                )
            });
            planar::rotate(&mut disks[k], phi);
            rep.boundary_rotation.push(phi);
        }
        if !features.is_empty() {
            let tris: Vec<&[[u32; 3]]> = normalised.iter().map(|m| &m.tris[..]).collect();
            let (folds, steps, before, after) = planar::align_features(
                &mut disks,
                &tris,
                &features,
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
    })?;
    if align_rep.foldovers > 0 {
        return Err(Error::numerical(
            "align_features",
            format!("{} flipped triangles after the planar warp", align_rep.foldovers),
        ));
    }

    // 5. Common boundary, then correspondence.
    let common = stages.run(progress, "common_boundary", || {
        let union = planar::union_angles(&disks);
        let mut out = Vec::with_capacity(k_in);
        for (k, (m, d)) in normalised.iter().zip(&disks).enumerate() {
            let c = planar::with_common_boundary(m, d, &union)?;
            let f = planar::foldovers(&c.plane, &c.tris);
            if f > 0 {
                return Err(Error::numerical(
                    "common_boundary",
                    format!("{}: {f} flipped triangles after inserting the common boundary", input_name(k)),
                ));
            }
            let mut c = c;
            if k > 0 {
                planar::jitter_interior(&mut c, k as u64);
            }
            out.push(c);
        }
        Ok(out)
    })?;
    let (layer, overlay_reps, pseudo_reps, fallback) = stages.run(progress, "metamesh", || {
        let layers: Vec<DiskLayer> = common
            .iter()
            .map(|c| DiskLayer {
                layer: Layer { sphere: c.plane.clone(), tris: c.tris.clone(), shapes: vec![c.pos.clone()] },
                bnd: c.bnd.clone(),
            })
            .collect();
        let mut acc = layers[0].clone();
        let (mut reps, mut preps) = (Vec::new(), Vec::new());
        let mut fallback: Option<String> = None;
        for l in &layers[1..] {
            acc = match params.correspondence {
                Correspondence::Overlay => match plane_overlay::overlay(&acc, l, progress) {
                    Ok((o, r)) => {
                        reps.push(r);
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
                    let (p, r) = pseudo::pseudo(
                        &acc.layer,
                        &l.layer,
                        Domain::Plane,
                        params.pseudo_max_depth,
                        progress,
                    )?;
                    preps.push(r);
                    let n = p.sphere.len();
                    DiskLayer { layer: p, bnd: vec![u32::MAX; n] }
                }
            };
        }
        Ok((acc.layer, reps, preps, fallback))
    })?;
    let exact = params.correspondence == Correspondence::Overlay && fallback.is_none();
    finish(
        stages,
        params,
        progress,
        Finish { layer: &layer, frames_out: &frames_out, normalised: &normalised, exact },
    )
    .map(|(mut report, meshes, artifacts)| {
        let per_input: Vec<serde_json::Value> = (0..k_in)
            .map(|k| {
                json!({
                    "input": k,
                    "vertices": meshes_len(&normalised[k]),
                    "faces": normalised[k].tris.len(),
                    "topology": topo[k],
                    "preparation": {"conversion": conv[k], "orientation_flipped": flipped[k]},
                    "parameterisation": param_reports[k],
                    "common_boundary_vertices_inserted": common[k].inserted,
                    "hausdorff_to_input": report["hausdorff_per_input"][k],
                })
            })
            .collect();
        let extra = json!({
            "domain": "planar",
            "domain_reason": reason,
            "angle_distortion": param_reports.iter().map(|r| r.angle_distortion).collect::<Vec<_>>(),
            "area_distortion": param_reports.iter().map(|r| r.area_distortion).collect::<Vec<_>>(),
            "foldovers": param_reports.iter().map(|r| r.foldovers).collect::<Vec<_>>(),
            "correspondence": match (params.correspondence, &fallback) {
                (Correspondence::Transfer, _) => "transfer",
                (Correspondence::Pseudo, _) => "pseudo",
                (_, Some(_)) => "transfer_fallback",
                _ => "overlay",
            },
            "correspondence_fallback": fallback,
            "overlays": overlay_reps,
            "pseudo_metamesh": pseudo_reps,
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
        });
        if let (Some(r), Some(e)) = (report.as_object_mut(), extra.as_object()) {
            for (k, v) in e {
                r.insert(k.clone(), v.clone());
            }
        }
        Output { meshes, artifacts, report }
    })
}

fn meshes_len(m: &TriMesh) -> usize {
    m.pos.len()
}

pub(super) struct Finish<'a> {
    pub layer: &'a Layer,
    pub frames_out: &'a [Similarity],
    pub normalised: &'a [TriMesh],
    /// Every metamesh face lies inside one face of every input (true overlay).
    pub exact: bool,
}

/// Interpolation, GLB (and frames ZIP), Hausdorff of the end frames: the common tail of the
/// planar path. Returns (report with stages, meshes, artifacts).
pub(super) fn finish(
    mut stages: Stages,
    params: &MorphParams,
    progress: &Progress,
    f: Finish<'_>,
) -> Result<(serde_json::Value, Vec<Mesh>, Vec<Artifact>)> {
    let k_in = f.normalised.len();
    let layer = f.layer;
    let back = f.frames_out[0].inverse();
    let shapes_out: Vec<Vec<Point3>> =
        layer.shapes.iter().map(|s| s.iter().map(|&p| back.apply(p)).collect()).collect();
    let (meshes, artifacts) = output::write_outputs(&mut stages, progress, params, &layer.tris, &shapes_out)?;
    let hausdorff = stages.run(progress, "report", || {
        Ok((0..k_in)
            .map(|k| {
                report::relative_hausdorff(
                    &layer.shapes[k],
                    &layer.tris,
                    &f.normalised[k].pos,
                    &f.normalised[k].tris,
                    !f.exact,
                )
            })
            .collect::<Vec<f64>>())
    })?;
    let report = json!({
        "inputs": k_in,
        "metamesh_vertices": layer.sphere.len(),
        "metamesh_faces": layer.tris.len(),
        "hausdorff_first_frame": hausdorff[0],
        "hausdorff_last_frame": hausdorff[k_in - 1],
        "hausdorff_per_input": hausdorff,
        "frames": params.frames,
        "frames_zip": params.frames_zip,
        "output_meshes": if params.blend_weights.is_some() { "blend" } else if params.output_frames { "frames" } else { "remeshed_inputs" },
        "total_ms": stages.total_ms(),
        "stages": stages.to_json(),
    });
    Ok((report, meshes, artifacts))
}
