//! The fit job's parameters: the one schema shared by the CLI, HTTP and OpenAPI, with its
//! defaults and validation.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::mesh::Point3;

use super::rbf::Kernel;

/// A user correspondence: this template vertex goes to (the curve vertex nearest to) this point.
#[derive(Debug, Clone, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FitPair {
    pub template_vertex: u32,
    #[schema(value_type = Vec<f64>)]
    pub curve_point: Point3,
}

/// How the template is first brought onto the curves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum Alignment {
    /// `pairs` when pairs are given, else `pca_icp`.
    #[default]
    Auto,
    /// Coarse RBF through the user's pairs (the seed's method; needs ≥ 4 non-coplanar pairs).
    Pairs,
    /// PCA of template vs curve points, then similarity ICP.
    PcaIcp,
    /// Use the template where it is.
    None,
}

/// How curve vertices get their template vertices before the fine RBF.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum Matching {
    /// Split the template at each curve vertex's closest surface point (local refinement; one
    /// template vertex per curve vertex whatever the curve density). The RBF is solved once.
    #[default]
    Insert,
    /// The seed's §2.1 rule: the nearest existing template vertex, feature points first; flips
    /// are handled by subdividing and re-matching (one RBF solve per round).
    NearestVertex,
}

/// What to do when the RBF centres are all on one plane (the system is then singular).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum CoplanarCentres {
    /// Fail with an error naming the stage.
    #[default]
    Reject,
    /// Fit the RBF with its polynomial part affine in the centres' plane only (see
    /// `fit::rbf::Rbf::fit_in_plane`). The name is the seed's (§2.2.2: augment the centres along
    /// the normals); that remedy fails when the normals lie in the plane, as for a section.
    Augment,
}

#[derive(Debug, Clone, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields, default)]
pub struct FitParams {
    /// Template vertex ↔ curve point pairs for the coarse deformation.
    pub pairs: Vec<FitPair>,
    pub alignment: Alignment,
    /// Radial function of both RBF levels.
    pub kernel: Kernel,
    /// How curve vertices are matched to template vertices for the fine RBF.
    pub matching: Matching,
    pub coplanar_centres: CoplanarCentres,
    /// Curve endpoints closer than this × the curves' bounding-box diagonal are one vertex.
    pub join_tolerance: f64,
    /// Consecutive curve points closer than this × the median curve segment length are merged
    /// (a feature point keeps its position); the report's `network.near_duplicates_merged`
    /// counts them (0 disables).
    pub merge_tolerance: f64,
    /// Curve ends within this × a segment's length of another polyline's segment are joined to
    /// it (T-junction), and segments that cross with a gap below this × the shorter one's length
    /// get a shared vertex (0 disables); counted in the report's `network`.
    pub junction_tolerance: f64,
    /// A curve vertex farther than this × the template's bounding-box diagonal from every template
    /// vertex (after alignment) is an error. At most 0.25 when part of the network is farther from
    /// the rest than the rest's size (a stray curve, named in the error). The default leaves room
    /// for templates of another shape: an icosphere against a bunny's sections has curve points
    /// 0.26 of its diagonal out after alignment, which the approach then reaches.
    pub max_curve_distance: f64,
    /// A curve end (a curve vertex joined to one other) within this × the template's bounding-box
    /// diagonal of an open template's boundary is matched on the boundary, so the curve cuts
    /// through to the rim (0 disables). Used by `matching = "insert"`.
    pub end_snap: f64,
    /// Cap on detect-flips / subdivide / re-fit rounds.
    pub max_flip_iterations: u32,
    /// Levels of the approach to the curves before the exact fine fit (RBFs through ¼, 1/16,
    /// 1/64 … of the curve vertices, sparsest first; 0 = fit in one step as the seed does).
    pub approach_levels: u32,
    /// A segment crossing an edge within this fraction of its length from a vertex snaps the
    /// vertex onto the segment (0 disables; at most 0.5).
    pub snap_fraction: f64,
    /// Run the sliver clean-up after re-triangulation (edge flips, then collapses of free vertices).
    pub cleanup: bool,
    /// Faces whose smallest angle is below this (degrees) are treated by the clean-up.
    pub cleanup_min_angle_deg: f64,
    /// Run the smoothing stage.
    pub smooth: bool,
    /// Smoothing holds every template vertex on a crease of the template (an edge whose faces'
    /// normals differ by more than this, in degrees) where the fit put it (0 disables). Tangential
    /// steps slide vertices off a crease or a tip and the chords then cut it: on a template simplified
    /// from the surface the curves come from, smoothing without this left the surface 2–7× farther
    /// from that surface than the unsmoothed fit (docs/benchmarks.md, session 22). Off by default:
    /// at 30° it turned one more face in two truth tests (homer bent with pairs, the raw cow).
    pub smooth_hold_creases_deg: f64,
    /// Iterations of the modified mean-curvature flow.
    pub mcf_iterations: u32,
    /// Fraction of the way to the cotangent-weighted ring mean per mean-curvature step (0..1].
    pub mcf_step: f64,
    /// Iterations of the modified (tangential, back-projected) Laplacian flow.
    pub laplacian_iterations: u32,
    /// Largest number of RBF centres (curve vertices) accepted: the dense solve is O(n³).
    pub max_curve_vertices: u32,
    /// Before the fine stage, the curve vertices whose closest points (feet) fall in a template
    /// face with more than this many feet are "dense", and the template is split 1→4 around them
    /// (repeatedly) so coarse templates can carry dense curves (0 disables; the report's `refine`
    /// says what was split).
    pub refine_dense_feet: u32,
    /// The refinement ends when no face holds more than this many dense feet (≥ 1).
    pub refine_max_feet: u32,
    /// The fit stops with a `too-large` error, naming the stage, when its mesh grows past this ×
    /// (template triangles + 8 × curve vertices) faces (a template that cannot follow the curves
    /// keeps splitting: minutes of work for a useless result). Fits measured use at most ~1.2×.
    pub max_face_growth: f64,
    /// Approach levels move the feet of curve points lying midway between two sheets of a thin
    /// template to its rim (`fit::thin`; report `fine.approach.rim_feet`). Off by default: it
    /// helps some thin cases and hurts others (docs/benchmarks.md, "Thin shapes", session 8).
    pub thin_rim_feet: bool,
}

impl Default for FitParams {
    fn default() -> Self {
        FitParams {
            pairs: Vec::new(),
            alignment: Alignment::Auto,
            kernel: Kernel::Linear,
            matching: Matching::Insert,
            coplanar_centres: CoplanarCentres::Reject,
            join_tolerance: 1e-6,
            merge_tolerance: 1e-3,
            junction_tolerance: 0.25,
            max_curve_distance: 0.5,
            end_snap: 0.05,
            max_flip_iterations: 4,
            approach_levels: 3,
            snap_fraction: 0.3,
            cleanup: true,
            cleanup_min_angle_deg: 15.0,
            smooth: true,
            mcf_iterations: 10,
            mcf_step: 0.5,
            smooth_hold_creases_deg: 0.0,
            laplacian_iterations: 20,
            max_curve_vertices: 8000,
            refine_dense_feet: 8,
            refine_max_feet: 1,
            max_face_growth: 4.0,
            thin_rim_feet: false,
        }
    }
}

impl FitParams {
    pub(super) fn validate(&self) -> Result<()> {
        let bad = |f: &str, m: &str| Err(Error::params(f, m));
        if !(self.join_tolerance.is_finite() && self.join_tolerance >= 0.0 && self.join_tolerance < 0.1) {
            return bad("join_tolerance", "must be in [0, 0.1)");
        }
        if !(self.merge_tolerance.is_finite() && (0.0..0.5).contains(&self.merge_tolerance)) {
            return bad("merge_tolerance", "must be in [0, 0.5)");
        }
        if !(self.junction_tolerance.is_finite() && (0.0..=1.0).contains(&self.junction_tolerance)) {
            return bad("junction_tolerance", "must be in [0, 1]");
        }
        if !(self.max_curve_distance.is_finite() && self.max_curve_distance > 0.0) {
            return bad("max_curve_distance", "must be > 0");
        }
        if !(self.end_snap.is_finite() && (0.0..=0.5).contains(&self.end_snap)) {
            return bad("end_snap", "must be in [0, 0.5]");
        }
        if !(self.snap_fraction.is_finite() && (0.0..=0.5).contains(&self.snap_fraction)) {
            return bad("snap_fraction", "must be in [0, 0.5]");
        }
        if !(self.smooth_hold_creases_deg.is_finite()
            && (0.0..=180.0).contains(&self.smooth_hold_creases_deg))
        {
            return bad("smooth_hold_creases_deg", "must be in [0, 180]");
        }
        if !(self.mcf_step.is_finite() && self.mcf_step > 0.0 && self.mcf_step <= 1.0) {
            return bad("mcf_step", "must be in (0, 1]");
        }
        if !(self.cleanup_min_angle_deg.is_finite() && (0.0..=50.0).contains(&self.cleanup_min_angle_deg)) {
            return bad("cleanup_min_angle_deg", "must be in [0, 50]");
        }
        if self.refine_dense_feet > 1000 {
            return bad("refine_dense_feet", "must be ≤ 1000 (0 disables the refinement)");
        }
        if self.refine_max_feet == 0 || self.refine_max_feet > self.refine_dense_feet.max(1) {
            return bad("refine_max_feet", "must be in [1, refine_dense_feet]");
        }
        if !(self.max_face_growth.is_finite() && self.max_face_growth > 0.0) {
            return bad("max_face_growth", "must be a finite number > 0");
        }
        if self.approach_levels > 6 {
            return bad("approach_levels", "must be ≤ 6");
        }
        if self.max_flip_iterations > 20 {
            return bad("max_flip_iterations", "must be ≤ 20");
        }
        if self.mcf_iterations + self.laplacian_iterations > 10_000 {
            return bad("mcf_iterations", "mcf_iterations + laplacian_iterations must be ≤ 10000");
        }
        if matches!(self.alignment, Alignment::Pairs) && self.pairs.is_empty() {
            return bad("pairs", "alignment = \"pairs\" needs at least 4 pairs");
        }
        Ok(())
    }
}
