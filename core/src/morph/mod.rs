//! The morph job (seeds 002/003): morph sequences between closed genus-0 meshes of different
//! connectivity.
//!
//! The domain (spherical: `sphere_job`, or planar for disks: [`planar_job`]) and, with `repair`,
//! the preparation of damaged inputs for it are decided first by [`domain`] (stage `repair`). The
//! steps both domains share (triangulate and check the inputs, normalise, the output tail) are
//! in `stages`.
//!
//! Spherical pipeline, one timed stage each: `validate` (closed, connected, manifold, genus 0; outward
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
mod sphere_job;
mod stages;
pub mod trimesh;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::job::{Output, Progress, Stages};
use crate::mesh::Mesh;

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
    let mut stages = Stages::new();
    // The domain, and with `repair` each input prepared for it (seed 003 §4.2), keeping track of
    // where each input vertex went so feature indices still mean the same vertex.
    let prep = domain::prepare(inputs, params, progress, &mut stages)?;
    match prep.domain {
        domain::Chosen::Planar => planar_job::run(prep, params, progress, stages),
        domain::Chosen::Spherical => sphere_job::run(prep, params, progress, stages),
    }
}
