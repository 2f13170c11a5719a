//! The morph pipeline on the spherical domain, for closed genus-0 inputs.
//!
//! Stages (each timed): `validate` (closed, connected, manifold, genus 0; outward orientation) →
//! `normalise` ([`super::stages::normalise`]) → `parameterise` (per input, [`super::param`]) →
//! `align_features` ([`super::align`]: stepwise CTPS C²a warp) → `metamesh` (overlays, or
//! transfers / pseudo-metameshes, chained through the inputs) → `interpolate` → `glb`
//! (→ `frames_zip`) → `report`.
//!
//! The domain is chosen, and with `repair` the inputs are prepared, by [`super::domain`] before
//! this runs.

use rayon::prelude::*;
use serde_json::json;

use crate::error::{Error, Result};
use crate::geometry::signed_volume;
use crate::job::{Output, Progress, Stages};
use crate::mesh::{Faces, Point3};

use super::align::{self, AlignReport};
use super::domain::Prepared;
use super::metamesh::{self, Layer};
use super::param::{self, SphereMap};
use super::pseudo;
use super::stages::{self, Chain, Finish, Triangulated};
use super::trimesh::{self, TriMesh};
use super::{input_name, overlay_degenerate, report, Correspondence, MorphParams, ParamMethod};

/// The spherical pipeline on inputs prepared by [`super::domain::prepare`] (stages continue
/// `stages`).
pub(super) fn run(
    prep: Prepared,
    params: &MorphParams,
    progress: &Progress,
    mut stages: Stages,
) -> Result<Output> {
    let Prepared { meshes: inputs, vertex_maps, repair: repair_reports, reason, .. } = prep;
    let k_in = inputs.len();

    let (inputs, flipped) = stages.run(progress, "validate", || {
        let mut t = stages::triangulate_inputs(&inputs, &vertex_maps, params.max_vertices, |k, info| {
            trimesh::require_sphere_like(info, &input_name(k)).map_err(|e| match e {
                Error::Topology(m) => Error::Topology(format!("{m}; spherical domain: {reason}")),
                e => e,
            })
        })?;
        let flipped: Vec<bool> = t.meshes.iter_mut().map(orient_outward).collect();
        Ok((t, flipped))
    })?;
    let features = stages::map_features(&params.features, &inputs.maps, k_in)?;
    let (normalised, frames_out, icp_reports) = stages
        .run(progress, "normalise", || stages::normalise(&inputs.meshes, params.registration, progress))?;

    let maps_sph = stages.run(progress, "parameterise", || parameterise(&normalised, params, progress))?;
    reject_spherical_foldovers(&maps_sph)?;

    let mut spheres: Vec<Vec<Point3>> = maps_sph.iter().map(|m| m.sphere.clone()).collect();
    let align_rep = stages.run(progress, "align_features", || {
        align_features(&mut spheres, &normalised, &features, params, progress)
    })?;
    stages::reject_warp_foldovers(align_rep.foldovers, "the warp")?;

    let chain = stages.run(progress, "metamesh", || correspond(&normalised, &spheres, params, progress))?;

    // Overlay faces lie inside input faces, so their vertices bound the distance; otherwise the
    // Hausdorff distance is sampled.
    let exact = chain.exact(params.correspondence);
    let (mut report, meshes, artifacts) = stages::finish(
        stages,
        params,
        progress,
        Finish { layer: &chain.layer, frames_out: &frames_out, normalised: &normalised, exact },
    )?;
    let per_input = per_input_report(&inputs, &flipped, &maps_sph, &report["hausdorff_per_input"]);
    stages::merge_report(
        &mut report,
        json!({
            "angle_distortion": maps_sph.iter().map(|m| m.report.angle_distortion).collect::<Vec<_>>(),
            "area_distortion": maps_sph.iter().map(|m| m.report.area_distortion).collect::<Vec<_>>(),
            "foldovers": maps_sph.iter().map(|m| m.report.foldovers).collect::<Vec<_>>(),
            "param_method": maps_sph.iter().map(|m| m.report.param_method.as_str()).collect::<Vec<_>>(),
            "param_fallback_reason": maps_sph.iter().map(|m| m.report.param_fallback_reason.clone()).collect::<Vec<_>>(),
            "correspondence": stages::correspondence_name(params.correspondence, &chain.fallback),
            "correspondence_fallback": chain.fallback,
            "overlays": chain.overlays,
            // Radians the target's embedding was rotated so the overlay could be built (0: exact).
            "overlay_perturbation": chain.perturbation,
            "pseudo_metamesh": chain.pseudo,
            "domain": "spherical",
            "domain_reason": reason,
            "warnings": report::feature_warnings(align_rep.feature_points, align_rep.max_feature_gap_after, "rad"),
            "features": align_rep,
            "icp": icp_reports,
            "per_input": per_input,
            "repair": repair_reports,
        }),
    );
    Ok(Output { meshes, artifacts, report })
}

/// Turns a closed mesh's faces so its signed volume is positive (normals outward); true if it
/// had to.
fn orient_outward(t: &mut TriMesh) -> bool {
    if signed_volume(&t.pos, &Faces::from_triangles(&t.tris)) >= 0.0 {
        return false;
    }
    for tr in &mut t.tris {
        tr.swap(1, 2);
    }
    true
}

/// Every input mapped to the unit sphere (in parallel: they are independent). The tetrahedron
/// method is the general path with nothing to simplify and no flattening rounds.
fn parameterise(normalised: &[TriMesh], params: &MorphParams, progress: &Progress) -> Result<Vec<SphereMap>> {
    let tetrahedron = params.param_method == ParamMethod::Tetrahedron;
    let settings = param::ParamSettings {
        working_vertices: if tetrahedron { 4 } else { params.working_vertices },
        max_flatten_rounds: if tetrahedron { 0 } else { params.max_flatten_rounds },
        relax_sweeps: params.relax_sweeps,
        final_relax_sweeps: params.final_relax_sweeps,
        sphere_method: params.sphere_method,
        ..Default::default()
    };
    normalised.par_iter().map(|m| param::parameterise(m, &settings, progress)).collect()
}

/// A sphere map with flipped triangles would make the overlay meaningless: refuse it, naming the
/// input.
fn reject_spherical_foldovers(maps: &[SphereMap]) -> Result<()> {
    for (k, m) in maps.iter().enumerate() {
        if m.report.foldovers > 0 {
            return Err(Error::numerical(
                "parameterise",
                format!("{}: {} flipped spherical triangles remain", input_name(k), m.report.foldovers),
            ));
        }
    }
    Ok(())
}

/// Warps the spheres so the feature vertices of every input meet input 0's.
fn align_features(
    spheres: &mut [Vec<Point3>],
    normalised: &[TriMesh],
    features: &[Vec<u32>],
    params: &MorphParams,
    progress: &Progress,
) -> Result<AlignReport> {
    let tris: Vec<&[[u32; 3]]> = normalised.iter().map(|m| &m.tris[..]).collect();
    align::align(
        spheres,
        &tris,
        features,
        &align::AlignSettings { steps: params.feature_steps, support_radius: params.support_radius },
        progress,
    )
}

/// Chains the correspondence through the inputs: input 0 with input 1, that result with
/// input 2, and so on, each step an overlay (the barycentric transfer when the overlay fails
/// numerically), a transfer or a pseudo-metamesh, as `params.correspondence` asks.
fn correspond(
    normalised: &[TriMesh],
    spheres: &[Vec<Point3>],
    params: &MorphParams,
    progress: &Progress,
) -> Result<Chain> {
    let layers: Vec<Layer> = normalised
        .iter()
        .zip(spheres)
        .map(|(m, s)| Layer { sphere: s.clone(), tris: m.tris.clone(), shapes: vec![m.pos.clone()] })
        .collect();
    let mut chain = Chain::start(layers[0].clone());
    for l in &layers[1..] {
        chain.layer = match params.correspondence {
            Correspondence::Overlay => match overlay_degenerate::overlay(&chain.layer, l, progress) {
                Ok((o, r, angle)) => {
                    chain.overlays.push(r);
                    chain.perturbation.push(angle);
                    o
                }
                Err(Error::Numerical { message, .. }) => {
                    chain.fallback =
                        Some(format!("overlay failed ({message}); used the barycentric transfer"));
                    metamesh::transfer(&chain.layer, l, progress)?
                }
                Err(e) => return Err(e),
            },
            Correspondence::Transfer => metamesh::transfer(&chain.layer, l, progress)?,
            Correspondence::Pseudo => {
                let (p, r) = pseudo::pseudo(
                    &chain.layer,
                    l,
                    pseudo::Domain::Sphere,
                    params.pseudo_max_depth,
                    progress,
                )?;
                chain.pseudo.push(r);
                p
            }
        };
    }
    Ok(chain)
}

/// The report's `per_input` rows.
fn per_input_report(
    inputs: &Triangulated,
    flipped: &[bool],
    maps: &[SphereMap],
    hausdorff: &serde_json::Value,
) -> Vec<serde_json::Value> {
    (0..inputs.meshes.len())
        .map(|k| {
            stages::per_input_row(
                inputs,
                k,
                flipped[k],
                hausdorff,
                json!({"parameterisation": maps[k].report}),
            )
        })
        .collect()
}
