//! Parameters of the smooth job (one schema for the CLI flags and the HTTP JSON body).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::laplacian::{MassKind, OperatorKind};
use crate::solve::SolverChoice;

/// Smoothing / fairing method (`--method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Explicit Laplacian flow `x ← x − λ·L̂x` (L̂ = operator with normalised rows).
    Laplacian,
    /// Taubin λ|μ: alternating shrinking (λ) and inflating (μ < −λ) explicit steps.
    #[default]
    Taubin,
    /// Backward-Euler diffusion `(D + h S) x = D x₀`, factored once and reused (Desbrun et al.).
    Implicit,
    /// Implicit mean-curvature flow: cotangent operator and mass re-assembled every step.
    Mcf,
    /// k-harmonic fairing of the selected region (`region`/`groups`), everything else fixed.
    Fair,
    /// Seed 004 shape inflation/exaggeration (eq. 3-8): a smoothing solve with |λ| applied
    /// backwards when λ < 0.
    Inflate,
    /// Seed 000 tangential flows: modified mean-curvature flow (tangential, projected back onto the
    /// current surface) then modified Laplacian flow (tangential, projected onto the input).
    Tangential,
    /// Seed 001 highlight-line fairing of a region (`region`, `region_faces`, `groups` or
    /// `region_all`): vertices move along their normals, each step a bound-constrained QP trading
    /// Willmore energy against the distance of the highlight lines to smooth (OGH) desired lines.
    Highlight,
}

/// What boundary vertices of open meshes do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum BoundaryMode {
    /// Boundary vertices do not move.
    #[default]
    Fixed,
    /// Boundary vertices use the surface operator as is (natural boundary condition).
    Free,
    /// Boundary loops are smoothed as 1-D curves (seed 004 eq. 4-3, corrected), scaled by
    /// `lambda_border`; in implicit methods the curves are solved first, then the interior.
    Curve,
}

/// Parameters of the `smooth` job. Every field is optional; method-dependent defaults are
/// listed per field and echoed in the report (`params`).
#[derive(Debug, Clone, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SmoothParams {
    /// Method (default `taubin`).
    pub method: Method,
    /// Number of steps. Defaults: laplacian/taubin 10, implicit 1, mcf 5, inflate 1, tangential 10
    /// (the Laplacian phase; see `mcf_iterations`), highlight 20 (at most; it stops at
    /// `convergence_threshold`). Ignored by `fair` (a single solve).
    pub iterations: Option<u32>,
    /// Explicit step factor λ (laplacian 0.5, taubin 0.5, tangential 0.5); for `inflate` the
    /// signed λ·dt of eq. 3-8 (default −1: negative inflates, positive smooths).
    pub lambda: Option<f64>,
    /// Taubin's negative factor μ (overrides `pass_band`); must satisfy −1 ≤ μ < −λ.
    pub mu: Option<f64>,
    /// Taubin pass-band frequency k_PB (default 0.1): μ = 1/(k_PB − 1/λ).
    pub pass_band: Option<f64>,
    /// Implicit time step h (implicit 1.0, mcf 1.0, tangential MCF phase 0.1). With
    /// `relative_time_step` (default) it is in units of the mean edge length squared for the
    /// area-scaled operators (`cotan`, `tqlbo`), so the same value smooths a model equally at any
    /// scale; otherwise it is absolute (length², the mean-curvature-flow time).
    pub time_step: Option<f64>,
    /// See `time_step` (default true).
    pub relative_time_step: Option<bool>,
    /// Laplace operator. Defaults: laplacian/taubin `uniform`, implicit/mcf/fair/tangential
    /// `cotan`, inflate `tqlbo_normalized`. (`mcf` is always cotangent.)
    pub operator: Option<OperatorKind>,
    /// Mass matrix of the `cotan` operator (default `voronoi`).
    pub mass: MassKind,
    /// Linear solver of implicit steps (default `auto`).
    pub solver: SolverChoice,
    /// Relative residual at which CG stops (default 1e-8).
    pub cg_tolerance: Option<f64>,
    /// Rescale the moving vertices about the input's vertex centroid after every step so the
    /// enclosed volume (cone volume from the centroid for open meshes) stays that of the input.
    pub preserve_volume: bool,
    /// Vertices that never move (hard constraints), by index.
    pub pinned: Vec<u32>,
    /// Faces groups (by name) whose vertices never move.
    pub pinned_groups: Vec<String>,
    /// Vertices that may move, by index; with `groups`, the selection (default: every vertex).
    /// `fair` requires a selection: it is the region that is faired.
    pub region: Vec<u32>,
    /// Face groups (by name) whose vertices may move (see `region`).
    pub groups: Vec<String>,
    /// Per-vertex influence in [0, 1] (soft constraints, seed 004's W_p); 0 = fixed.
    pub weights: Option<Vec<f64>>,
    /// Coordinates that may change, e.g. "xz" (default "xyz").
    pub axes: Option<String>,
    /// Boundary handling of open meshes (default `fixed`).
    pub boundary: BoundaryMode,
    /// Step factor of the boundary curve operator relative to the interior one (default 1).
    pub lambda_border: Option<f64>,
    /// Pin the endpoints of edges whose dihedral angle exceeds this many degrees (feature lines).
    pub feature_angle: Option<f64>,
    /// Order k of `fair` (1 = harmonic/membrane, 2 = biharmonic/thin plate, 3 = triharmonic;
    /// default 2).
    pub order: Option<u32>,
    /// `tangential`: iterations of the modified mean-curvature phase (default 5).
    pub mcf_iterations: Option<u32>,
    /// Compute the symmetric Hausdorff distance for the report (default true; costs two
    /// closest-point passes).
    pub hausdorff: Option<bool>,
    /// Report the mass-weighted mean |H| before and after (`mean_curvature_before/after`). Default:
    /// only for `inflate`, whose purpose it measures; elsewhere it costs about as much as the other
    /// report measures together (a per-vertex cotangent pass over both states).
    pub report_curvature: Option<bool>,
    /// `highlight`: faces whose vertices form the region R (with `region`/`groups`).
    pub region_faces: Vec<u32>,
    /// `highlight`: R = every vertex (the mesh boundary then acts as R's border).
    pub region_all: bool,
    /// `highlight`: unit normal Z of the light plane (default: area-weighted mean normal of R).
    #[schema(value_type = Option<Vec<f64>>)]
    pub light_normal: Option<[f64; 3]>,
    /// `highlight`: direction H of the linear lights, in the light plane (default: the coordinate
    /// axis along which R is longest, projected into the plane).
    #[schema(value_type = Option<Vec<f64>>)]
    pub light_direction: Option<[f64; 3]>,
    /// `highlight`: a point A₀ on the base light L₀ (default: centre of R's bounding box moved
    /// one box diagonal along the light normal).
    #[schema(value_type = Option<Vec<f64>>)]
    pub light_origin: Option<[f64; 3]>,
    /// `highlight`: distance s between neighbouring lights (default: the 5th–95th percentile
    /// range of the highlight distance over R / 16, i.e. about 16 lines across R).
    pub light_spacing: Option<f64>,
    /// `highlight`: ε of eq. 17, stop when max |xᵢ| / (mean edge length in R) < ε (default 0.001).
    pub convergence_threshold: Option<f64>,
    /// `highlight`: ω₁, weight of the Willmore (fairness) energy (default 1).
    pub fairness_weight: Option<f64>,
    /// `highlight`: ω₂, weight of the highlight-line difference energy (default 1).
    pub highlight_weight: Option<f64>,
    /// `highlight`: bound on each step as a fraction of the shortest incident edge (default and
    /// maximum 0.5, the paper's).
    pub max_step_fraction: Option<f64>,
    /// `highlight`: include the highlight lines before and after (polylines per light index) in the
    /// report under `highlight_lines`.
    pub highlight_lines: bool,
}

/// Hard cap on iterations (every loop has one).
pub const MAX_ITERATIONS: u32 = 100_000;

/// Parameters with every method default filled in.
#[derive(Debug, Clone, Serialize)]
pub struct Resolved {
    pub method: Method,
    pub iterations: u32,
    pub lambda: f64,
    pub mu: f64,
    pub time_step: f64,
    pub relative_time_step: bool,
    pub operator: OperatorKind,
    pub mass: MassKind,
    pub solver: SolverChoice,
    pub cg_tolerance: f64,
    pub preserve_volume: bool,
    pub axes: [bool; 3],
    pub boundary: BoundaryMode,
    pub lambda_border: f64,
    pub order: u32,
    pub mcf_iterations: u32,
    pub hausdorff: bool,
    pub report_curvature: bool,
}

fn finite(field: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::params(field, format!("must be a finite number, got {v}")))
    }
}

impl SmoothParams {
    /// Fills in the method defaults and validates ranges.
    pub fn resolve(&self) -> Result<Resolved> {
        let m = self.method;
        let iterations = self.iterations.unwrap_or(match m {
            Method::Laplacian | Method::Taubin | Method::Tangential => 10,
            Method::Implicit | Method::Inflate | Method::Fair => 1,
            Method::Mcf => 5,
            Method::Highlight => super::highlight::DEFAULT_ITERATIONS,
        });
        if iterations > MAX_ITERATIONS {
            return Err(Error::params("iterations", format!("at most {MAX_ITERATIONS}")));
        }
        let lambda = finite(
            "lambda",
            self.lambda.unwrap_or(match m {
                Method::Inflate => -1.0,
                _ => 0.5,
            }),
        )?;
        if matches!(m, Method::Laplacian | Method::Taubin | Method::Tangential)
            && !(lambda > 0.0 && lambda <= 1.0)
        {
            return Err(Error::params("lambda", format!("explicit steps need 0 < lambda ≤ 1, got {lambda}")));
        }
        let mu = match (self.mu, self.pass_band) {
            _ if m != Method::Taubin => 0.0,
            (Some(mu), _) => finite("mu", mu)?,
            (None, pb) => {
                let kpb = finite("pass_band", pb.unwrap_or(0.1))?;
                if !(kpb > 0.0 && kpb < 1.0 / lambda) {
                    return Err(Error::params(
                        "pass_band",
                        format!("need 0 < pass_band < 1/lambda, got {kpb}"),
                    ));
                }
                1.0 / (kpb - 1.0 / lambda)
            }
        };
        if m == Method::Taubin && !(mu < -lambda && mu >= -1.0) {
            return Err(Error::params("mu", format!("Taubin needs -1 ≤ mu < -lambda, got {mu}")));
        }
        let time_step = finite(
            "time_step",
            self.time_step.unwrap_or(match m {
                Method::Tangential => 0.1,
                _ => 1.0,
            }),
        )?;
        if time_step <= 0.0 {
            return Err(Error::params("time_step", "must be positive"));
        }
        let operator = match m {
            Method::Mcf => {
                if let Some(o) = self.operator {
                    if o != OperatorKind::Cotan {
                        return Err(Error::params("operator", "mcf is defined with the cotan operator"));
                    }
                }
                OperatorKind::Cotan
            }
            _ => self.operator.unwrap_or(match m {
                Method::Laplacian | Method::Taubin => OperatorKind::Uniform,
                Method::Inflate => OperatorKind::TqlboNormalized,
                _ => OperatorKind::Cotan,
            }),
        };
        let cg_tolerance = finite("cg_tolerance", self.cg_tolerance.unwrap_or(1e-8))?;
        if !(cg_tolerance > 0.0 && cg_tolerance < 1.0) {
            return Err(Error::params("cg_tolerance", "must be in (0, 1)"));
        }
        let axes = match &self.axes {
            None => [true; 3],
            Some(s) => {
                let mut a = [false; 3];
                for ch in s.chars() {
                    match ch.to_ascii_lowercase() {
                        'x' => a[0] = true,
                        'y' => a[1] = true,
                        'z' => a[2] = true,
                        _ => return Err(Error::params("axes", format!("letters x, y, z only, got {s:?}"))),
                    }
                }
                a
            }
        };
        let lambda_border = finite("lambda_border", self.lambda_border.unwrap_or(1.0))?;
        if lambda_border < 0.0 {
            return Err(Error::params("lambda_border", "must be ≥ 0"));
        }
        let order = self.order.unwrap_or(2);
        if !(1..=3).contains(&order) {
            return Err(Error::params("order", "fair supports order 1, 2 or 3"));
        }
        let mcf_iterations = self.mcf_iterations.unwrap_or(5);
        if mcf_iterations > MAX_ITERATIONS {
            return Err(Error::params("mcf_iterations", format!("at most {MAX_ITERATIONS}")));
        }
        if let Some(a) = self.feature_angle {
            if !(a.is_finite() && a > 0.0 && a < 180.0) {
                return Err(Error::params("feature_angle", "degrees in (0, 180)"));
            }
        }
        Ok(Resolved {
            method: m,
            iterations,
            lambda,
            mu,
            time_step,
            relative_time_step: self.relative_time_step.unwrap_or(true),
            operator,
            mass: self.mass,
            solver: self.solver,
            cg_tolerance,
            preserve_volume: self.preserve_volume,
            axes,
            boundary: self.boundary,
            lambda_border,
            order,
            mcf_iterations,
            hausdorff: self.hausdorff.unwrap_or(true),
            report_curvature: self.report_curvature.unwrap_or(m == Method::Inflate),
        })
    }
}
