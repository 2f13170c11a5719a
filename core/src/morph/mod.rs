//! The morph job (seeds 002/003): morph sequences between closed genus-0 meshes of different
//! connectivity.
//!
//! The domain (spherical, or planar for disks: [`planar_job`]) and, with `repair`, the preparation
//! of damaged inputs for it are decided first by [`domain`] (stage `repair`).
//!
//! Pipeline, one timed stage each: `validate` (closed, connected, manifold, genus 0; outward
//! orientation) → `normalise` (PCA frame with a deterministic sign rule, unit sphere; optional
//! point-to-plane ICP onto input 0) → `parameterise` (per input, [`param`]: recorded QEM
//! simplification, curvature-driven flattening or tetrahedron fallback, vertex splits,
//! fold-free relaxation) → `align_features` ([`align`]: stepwise CTPS C²a warp) → `metamesh`
//! ([`metamesh`]: true overlay of the spherical triangulations, both inputs reproduced exactly)
//! → `interpolate` → `glb` ([`glb`]) → `report` (Hausdorff distance of the end frames).
//!
//! Output: `artifacts[0]` is an animated GLB (base = input 0 on the metamesh, one morph target per
//! further input, an animation through them; media type model/gltf-binary). `meshes` holds the
//! metamesh in the shape of each input (input 0's coordinates; the others registered into them),
//! or, with `output_frames`, the interpolated frames, or with `blend_weights` one blended mesh.

pub mod align;
pub mod correspond;
pub mod domain;
mod face_pairs;
pub mod glb;
pub mod interpolate;
pub mod metamesh;
pub mod output;
pub mod overlay_degenerate;
pub mod param;
pub mod planar;
pub mod planar_job;
pub mod plane_overlay;
pub mod pseudo;
pub mod report;
pub mod simplify;
pub mod sphere_fallback;
pub mod trimesh;

use serde::{Deserialize, Serialize};
use serde_json::json;

use crate::error::{Error, Result};
use crate::geometry::signed_volume;
use crate::job::{Output, Progress, Stages};
use crate::mesh::{Faces, Mesh, Point3};
use crate::register::{self, Similarity};

use metamesh::Layer;
use trimesh::TriMesh;

/// How the inputs are brought into one frame before parameterising.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum Registration {
    /// PCA axes (sign by third moment) and unit-sphere scale, per input.
    #[default]
    Pca,
    /// PCA, then rigid point-to-plane ICP of each input onto input 0.
    PcaIcp,
    /// Keep the inputs where they are (one common scale for the internal work).
    None,
}

/// How the coarse working mesh is embedded on the sphere.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum ParamMethod {
    /// Seed 002's curvature-driven flattening + radial projection, tetrahedron fallback.
    #[default]
    CurvatureFlattening,
    /// Simplify to a tetrahedron and re-insert every vertex (Praun–Hoppe style).
    Tetrahedron,
}

/// How correspondence between the inputs is built.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum Correspondence {
    /// True overlay of the spherical triangulations: every input reproduced exactly.
    #[default]
    Overlay,
    /// Input 0's connectivity carried onto the others by barycentric coordinates (smaller output,
    /// the other inputs only approximated).
    Transfer,
    /// Seed 002's adaptive pseudo-metamesh: the target's embedding split 1-to-4 until each
    /// triangle holds at most one source vertex (the target reproduced exactly, the source
    /// approximated; usually fewer vertices than the overlay).
    Pseudo,
}

/// Parameters of the morph job.
#[derive(Debug, Clone, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields, default)]
pub struct MorphParams {
    /// Frames of the animation (keyframes in the GLB; meshes with `output_frames`), ≥ 2.
    pub frames: usize,
    /// Length of the whole animation in seconds, in [1e-3, 1e7] (keyframe times are f32 in the GLB).
    pub duration_seconds: f64,
    /// Feature points: each entry lists one vertex index per input (indices as in the input
    /// files), e.g. `[[12, 407], [88, 1093]]` for two inputs. Paired points meet on the sphere, so
    /// they travel onto each other during the morph.
    pub features: Vec<Vec<u32>>,
    pub registration: Registration,
    /// `auto` (input 0 decides; with `repair` by the rim rule in docs/api.md), `sphere` or `disk`.
    /// The report says which was used and why (`domain`, `domain_reason`).
    pub domain: domain::MorphDomain,
    /// Run the foundation's repair on each input first (non-manifold parts, small pieces, holes:
    /// all holes for the spherical domain, all but the outer boundary for the planar one).
    pub repair: bool,
    pub param_method: ParamMethod,
    /// Vertex count of the simplified working mesh that is embedded directly (seed 002 used 500–1,200).
    pub working_vertices: usize,
    /// Flattening rounds (It = 5·V moves each) before falling back to the tetrahedron.
    pub max_flatten_rounds: usize,
    /// Relaxation sweeps after each 30 % growth during vertex splits.
    pub relax_sweeps: usize,
    /// Relaxation sweeps on the full-resolution map.
    pub final_relax_sweeps: usize,
    /// Steps of the stepwise feature warp (seed 002 chose 15).
    pub feature_steps: usize,
    /// Support radius of the CTPS C²a warp on the unit sphere (chord length, 0 < r ≤ 2). The
    /// default 2 reaches the antipode: a global warp. With r = 1 the field falls to 0 within 60°
    /// of each feature, its gradient is steep and on homer ↔ a bent homer (12 pairs) the steps
    /// folded the map until the features stopped 0.10 rad apart; with r = 2 they meet (2e-8 rad).
    pub support_radius: f64,
    pub correspondence: Correspondence,
    /// Multi-morph: one output mesh at these weights (one per input, normalised to sum 1) in
    /// `meshes[0]`, instead of the remeshed inputs.
    pub blend_weights: Option<Vec<f64>>,
    /// Put the interpolated frames in `meshes` (instead of the remeshed inputs).
    pub output_frames: bool,
    /// Refuse inputs with more vertices than this (each).
    pub max_vertices: usize,
    /// Also return the frames as separate files in a ZIP (stored, one `frame_NNNN.glb` or
    /// `.obj` per frame) as the job's result file (`application/zip`); the animated GLB follows
    /// as the second artifact.
    pub frames_zip: Option<output::FrameFormat>,
    /// Interior weights of the planar (disk) parameterisation.
    pub planar_method: planar::PlanarMethod,
    /// `correspondence: pseudo`: most 1-to-4 subdivision levels per target triangle.
    pub pseudo_max_depth: u32,
    /// Spherical parameterisation: `auto` (progressive, with the guaranteed Tutte fallback when
    /// it fails or leaves a flipped triangle), `progressive` or `tutte` (the fallback alone).
    pub sphere_method: param::SphereMethod,
}

impl Default for MorphParams {
    fn default() -> Self {
        MorphParams {
            frames: 30,
            duration_seconds: 2.0,
            features: Vec::new(),
            registration: Registration::Pca,
            domain: domain::MorphDomain::Auto,
            repair: false,
            param_method: ParamMethod::CurvatureFlattening,
            working_vertices: 1000,
            max_flatten_rounds: 30,
            relax_sweeps: 3,
            final_relax_sweeps: 10,
            feature_steps: 15,
            support_radius: 2.0,
            correspondence: Correspondence::Overlay,
            blend_weights: None,
            output_frames: false,
            max_vertices: 2_000_000,
            frames_zip: None,
            planar_method: planar::PlanarMethod::Elrp,
            pseudo_max_depth: 8,
            sphere_method: param::SphereMethod::Auto,
        }
    }
}

impl MorphParams {
    fn check(&self, inputs: usize) -> Result<()> {
        if !(2..=10_000).contains(&self.frames) {
            return Err(Error::params("frames", format!("must be 2..=10000, got {}", self.frames)));
        }
        // The GLB stores keyframe times as f32, which must increase strictly: 1e300 s became
        // infinity (reported as a NaN vertex) and 1e-300 s made every time 0.
        if !(MIN_DURATION..=MAX_DURATION).contains(&self.duration_seconds) {
            return Err(Error::params(
                "duration_seconds",
                format!(
                    "must be {MIN_DURATION} to {MAX_DURATION:e} seconds (keyframe times are f32), got {}",
                    self.duration_seconds
                ),
            ));
        }
        if !(4..=100_000).contains(&self.working_vertices) {
            return Err(Error::params("working_vertices", "must be 4..=100000"));
        }
        if !(self.support_radius > 0.0 && self.support_radius <= 2.0) {
            return Err(Error::params("support_radius", "must be in (0, 2]"));
        }
        if self.pseudo_max_depth > 16 {
            return Err(Error::params("pseudo_max_depth", "must be ≤ 16"));
        }
        if self.feature_steps == 0 || self.feature_steps > 1000 {
            return Err(Error::params("feature_steps", "must be 1..=1000"));
        }
        if self.max_flatten_rounds > 1000 || self.relax_sweeps > 1000 || self.final_relax_sweeps > 1000 {
            return Err(Error::params("relax_sweeps", "iteration counts must be ≤ 1000"));
        }
        for (i, f) in self.features.iter().enumerate() {
            if f.len() != inputs {
                return Err(Error::params(
                    format!("features[{i}]"),
                    format!("lists {} vertices; one per input ({inputs}) is needed", f.len()),
                ));
            }
        }
        if let Some(w) = &self.blend_weights {
            if w.len() != inputs || w.iter().any(|x| !x.is_finite()) || w.iter().sum::<f64>().abs() < 1e-12 {
                return Err(Error::params(
                    "blend_weights",
                    format!("needs {inputs} finite weights with a non-zero sum"),
                ));
            }
        }
        Ok(())
    }
}

/// Shortest and longest animation (seconds): with up to 10,000 frames, the keyframe times stay
/// distinct and finite in f32.
const MIN_DURATION: f64 = 1e-3;
const MAX_DURATION: f64 = 1e7;

fn input_name(k: usize) -> String {
    match k {
        0 => "input 0 (source)".into(),
        1 => "input 1 (target)".into(),
        k => format!("input {k}"),
    }
}

/// Inputs: 2..16 meshes (source, target, more for a multi-morph).
pub fn run(inputs: Vec<Mesh>, params: &MorphParams, progress: &Progress) -> Result<Output> {
    params.check(inputs.len())?;
    let k_in = inputs.len();
    let mut stages = Stages::new();

    // 0. The domain, and with `repair` each input prepared for it (seed 003 §4.2), keeping track
    //    of where each input vertex went so feature indices still mean the same vertex.
    let prep = domain::prepare(inputs, params, progress, &mut stages)?;
    if prep.domain == domain::Chosen::Planar {
        return planar_job::run(prep, params, progress, stages);
    }
    let domain::Prepared { meshes: inputs, vertex_maps: repair_maps, repair: repair_reports, reason, .. } =
        prep;

    // 1. Validate.
    let (meshes, maps, conv_reports, topo) = stages.run(progress, "validate", || {
        let mut meshes = Vec::new();
        let mut maps = Vec::new();
        let mut convs = Vec::new();
        let mut topo = Vec::new();
        for (k, m) in inputs.iter().enumerate() {
            domain::check_vertex_limit(k, m, params.max_vertices)?;
            let (mut t, map, conv) = TriMesh::from_mesh(m);
            let info = trimesh::topology(&t);
            trimesh::require_sphere_like(&info, &input_name(k)).map_err(|e| match e {
                Error::Topology(m) => Error::Topology(format!("{m}; spherical domain: {reason}")),
                e => e,
            })?;
            let mut flipped = false;
            if signed_volume(&t.pos, &Faces::from_triangles(&t.tris)) < 0.0 {
                for tr in &mut t.tris {
                    tr.swap(1, 2);
                }
                flipped = true;
            }
            convs.push(json!({"conversion": conv, "orientation_flipped": flipped}));
            topo.push(info);
            meshes.push(t);
            maps.push(domain::compose_vertex_maps(repair_maps[k].as_deref(), map));
        }
        Ok((meshes, maps, convs, topo))
    })?;

    // Feature vertices, mapped to the triangulated inputs.
    let features = map_features(&params.features, &maps, k_in)?;

    // 2. Normalise.
    let (normalised, frames_out, icp_reports) =
        stages.run(progress, "normalise", || normalise(&meshes, params.registration, progress))?;

    // 3. Parameterise every input (in parallel: they are independent).
    let settings = param::ParamSettings {
        working_vertices: if params.param_method == ParamMethod::Tetrahedron {
            4
        } else {
            params.working_vertices
        },
        max_flatten_rounds: if params.param_method == ParamMethod::Tetrahedron {
            0
        } else {
            params.max_flatten_rounds
        },
        relax_sweeps: params.relax_sweeps,
        final_relax_sweeps: params.final_relax_sweeps,
        sphere_method: params.sphere_method,
        ..Default::default()
    };
    let maps_sph: Vec<param::SphereMap> = stages.run(progress, "parameterise", || {
        use rayon::prelude::*;
        normalised.par_iter().map(|m| param::parameterise(m, &settings, progress)).collect::<Result<Vec<_>>>()
    })?;
    for (k, m) in maps_sph.iter().enumerate() {
        if m.report.foldovers > 0 {
            return Err(Error::numerical(
                "parameterise",
                format!("{}: {} flipped spherical triangles remain", input_name(k), m.report.foldovers),
            ));
        }
    }
    let mut spheres: Vec<Vec<Point3>> = maps_sph.iter().map(|m| m.sphere.clone()).collect();

    // 4. Feature alignment.
    let align_rep = stages.run(progress, "align_features", || {
        let tris: Vec<&[[u32; 3]]> = normalised.iter().map(|m| &m.tris[..]).collect();
        align::align(
            &mut spheres,
            &tris,
            &features,
            &align::AlignSettings { steps: params.feature_steps, support_radius: params.support_radius },
            progress,
        )
    })?;
    if align_rep.foldovers > 0 {
        return Err(Error::numerical(
            "align_features",
            format!("{} flipped triangles after the warp", align_rep.foldovers),
        ));
    }

    // 5. Correspondence: chain overlays (or transfers) through the inputs.
    let (layer, overlay_reps, fallback, pseudo_reps, perturbation) =
        stages.run(progress, "metamesh", || {
            let layers: Vec<Layer> = normalised
                .iter()
                .zip(&spheres)
                .map(|(m, s)| Layer { sphere: s.clone(), tris: m.tris.clone(), shapes: vec![m.pos.clone()] })
                .collect();
            let mut acc = layers[0].clone();
            let mut reps = Vec::new();
            let mut fallback: Option<String> = None;
            let mut pseudo_reps = Vec::new();
            let mut perturbation = Vec::new();
            for l in &layers[1..] {
                acc = match params.correspondence {
                    Correspondence::Overlay => match overlay_degenerate::overlay(&acc, l, progress) {
                        Ok((o, r, angle)) => {
                            reps.push(r);
                            perturbation.push(angle);
                            o
                        }
                        Err(Error::Numerical { message, .. }) => {
                            fallback =
                                Some(format!("overlay failed ({message}); used the barycentric transfer"));
                            metamesh::transfer(&acc, l, progress)?
                        }
                        Err(e) => return Err(e),
                    },
                    Correspondence::Transfer => metamesh::transfer(&acc, l, progress)?,
                    Correspondence::Pseudo => {
                        let (p, r) = pseudo::pseudo(
                            &acc,
                            l,
                            pseudo::Domain::Sphere,
                            params.pseudo_max_depth,
                            progress,
                        )?;
                        pseudo_reps.push(r);
                        p
                    }
                };
            }
            Ok((acc, reps, fallback, pseudo_reps, perturbation))
        })?;

    // Back in input 0's coordinates.
    let back = frames_out[0].inverse();
    let shapes_out: Vec<Vec<Point3>> =
        layer.shapes.iter().map(|s| s.iter().map(|&p| back.apply(p)).collect()).collect();
    // 6–7. Interpolate, GLB (and the frames ZIP when asked for).
    let (out_meshes, artifacts) =
        output::write_outputs(&mut stages, progress, params, &layer.tris, &shapes_out)?;

    // 8. Report: how well the end frames reproduce the inputs (in the normalised frames).
    let hausdorff = stages.run(progress, "report", || {
        Ok((0..k_in)
            .map(|k| {
                report::relative_hausdorff(
                    &layer.shapes[k],
                    &layer.tris,
                    &normalised[k].pos,
                    &normalised[k].tris,
                    // Overlay faces lie inside input faces: their vertices bound the distance.
                    overlay_reps.len() + 1 < k_in || params.correspondence != Correspondence::Overlay,
                )
            })
            .collect::<Vec<f64>>())
    })?;

    let per_input: Vec<serde_json::Value> = (0..k_in)
        .map(|k| {
            json!({
                "input": k,
                "vertices": meshes[k].pos.len(),
                "faces": meshes[k].tris.len(),
                "topology": topo[k],
                "preparation": conv_reports[k],
                "parameterisation": maps_sph[k].report,
                "hausdorff_to_input": hausdorff[k],
            })
        })
        .collect();
    let report = json!({
        "inputs": k_in,
        "angle_distortion": maps_sph.iter().map(|m| m.report.angle_distortion).collect::<Vec<_>>(),
        "area_distortion": maps_sph.iter().map(|m| m.report.area_distortion).collect::<Vec<_>>(),
        "foldovers": maps_sph.iter().map(|m| m.report.foldovers).collect::<Vec<_>>(),
        "param_method": maps_sph.iter().map(|m| m.report.param_method.as_str()).collect::<Vec<_>>(),
        "param_fallback_reason": maps_sph.iter().map(|m| m.report.param_fallback_reason.clone()).collect::<Vec<_>>(),
        "metamesh_vertices": layer.sphere.len(),
        "metamesh_faces": layer.tris.len(),
        "correspondence": match (params.correspondence, &fallback) {
            (Correspondence::Transfer, _) => "transfer",
            (Correspondence::Pseudo, _) => "pseudo",
            (_, Some(_)) => "transfer_fallback",
            _ => "overlay",
        },
        "correspondence_fallback": fallback,
        "overlays": overlay_reps,
        // Radians the target's embedding was rotated so the overlay could be built (0: exact).
        "overlay_perturbation": perturbation,
        "pseudo_metamesh": pseudo_reps,
        "domain": "spherical",
        "domain_reason": reason,
        "frames_zip": params.frames_zip,
        "hausdorff_first_frame": hausdorff[0],
        "hausdorff_last_frame": hausdorff[k_in - 1],
        "hausdorff_per_input": hausdorff,
        "warnings": report::feature_warnings(align_rep.feature_points, align_rep.max_feature_gap_after, "rad"),
        "features": align_rep,
        "icp": icp_reports,
        "frames": params.frames,
        "output_meshes": if params.blend_weights.is_some() { "blend" } else if params.output_frames { "frames" } else { "remeshed_inputs" },
        "per_input": per_input,
        "repair": repair_reports,
        "total_ms": stages.total_ms(),
        "stages": stages.to_json(),
    });
    Ok(Output { meshes: out_meshes, artifacts, report })
}

/// Step 2 of both domains: every input in its PCA frame (with `Registration::None`, every input in
/// input 0's frame, so their relative placement is kept), then with `PcaIcp` rigid ICP of inputs
/// 1.. onto input 0. Returns the normalised meshes, each input's frame (input → normalised) and the
/// ICP results.
pub(crate) fn normalise(
    meshes: &[TriMesh],
    registration: Registration,
    progress: &Progress,
) -> Result<(Vec<TriMesh>, Vec<Similarity>, Vec<register::IcpResult>)> {
    let mut frames: Vec<Similarity> = Vec::new();
    for m in meshes {
        let f = if registration == Registration::None && !frames.is_empty() {
            frames[0]
        } else {
            register::pca_frame(&m.pos, &m.tris).to_normalised
        };
        frames.push(f);
    }
    let mut norm: Vec<TriMesh> = meshes
        .iter()
        .zip(&frames)
        .map(|(m, f)| TriMesh { pos: m.pos.iter().map(|&p| f.apply(p)).collect(), tris: m.tris.clone() })
        .collect();
    let mut icp = Vec::new();
    if registration == Registration::PcaIcp {
        let target = register::IcpTarget::new(&norm[0].pos, &norm[0].tris);
        for k in 1..norm.len() {
            progress.fraction(k as f64 / norm.len() as f64)?;
            let r = register::icp(&norm[k].pos, &target, 50);
            for p in &mut norm[k].pos {
                *p = r.transform.apply(*p);
            }
            frames[k] = r.transform.then_after(&frames[k]);
            icp.push(r);
        }
    }
    Ok((norm, frames, icp))
}

/// Feature vertices (input indices) mapped to the triangulated inputs.
fn map_features(features: &[Vec<u32>], maps: &[Vec<u32>], k_in: usize) -> Result<Vec<Vec<u32>>> {
    let mut out = Vec::with_capacity(features.len());
    for (i, f) in features.iter().enumerate() {
        let mut row = Vec::with_capacity(k_in);
        for k in 0..k_in {
            let v = f[k] as usize;
            let m = maps[k].get(v).copied().unwrap_or(u32::MAX);
            if m == u32::MAX {
                return Err(Error::params(
                    format!("features[{i}][{k}]"),
                    format!(
                        "vertex {v} of {} does not exist, is used by no face, or was removed by the repair",
                        input_name(k)
                    ),
                ));
            }
            row.push(m);
        }
        out.push(row);
    }
    Ok(out)
}
