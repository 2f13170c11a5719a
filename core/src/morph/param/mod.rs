//! Spherical parameterisation of a closed genus-0 mesh (seed 002 §4.2), in three steps:
//!
//! 1. simplify with recorded half-edge collapses to a working size ([`crate::morph::simplify`]);
//! 2. embed the working mesh by curvature-driven flattening (eq. IV.61–IV.62: the vertex of largest
//!    |K_s| moves to its neighbours' barycentre, It = 5·V moves a round) until it is star-shaped
//!    about its centre (every face seen from the centre with positive orientation — the
//!    visibility check), then project radially (eq. IV.63). If flattening does not reach a
//!    star shape within `max_flatten_rounds`, simplify further down to a tetrahedron, which embeds
//!    trivially (Praun–Hoppe), and say so in the report;
//! 3. undo the collapses one by one (vertex splits), placing each returning vertex at the valid
//!    candidate of a lattice over its old 1-ring that maximises the worst triangle shape
//!    (seed 002 Fig. IV.29), so the map stays an embedding by construction.
//!
//! Between levels, and at the end, a relaxation pass moves each vertex towards the normalised
//! mean-value-weighted average of its neighbours (weights from the 3D mesh, which lowers angle
//! distortion), accepting only moves that flip no triangle.
//!
//! Orientation of a spherical triangle (a, b, c): sign of det(a, b, c) (seed 003 eq. 3.5); all
//! faces of an outward-oriented input must come out positive.
//!
//! The code follows those steps: this file holds the entry point (the choice between the
//! progressive map and the guaranteed Tutte fallback of [`crate::morph::sphere_fallback`]), the
//! settings and report types and the shared measures (orientation, foldovers, distortion);
//! [`progressive`] the progressive map (steps 1–3 and its retries), [`vertex_split`] the placement
//! of a returning vertex inside the kernel of its star, [`relax`] the fold-free mean-value
//! relaxation.

mod progressive;
mod relax;
mod vertex_split;

pub(crate) use relax::relax;

use crate::error::{Error, Result};
use crate::geometry::{corner_angle, cross, dot, triangle_area};
use crate::job::Progress;
use crate::mesh::Point3;

use super::trimesh::TriMesh;

/// det(a, b, c): positive for a counter-clockwise (outward) spherical triangle.
#[inline]
pub fn orient(a: Point3, b: Point3, c: Point3) -> f64 {
    dot(cross(a, b), c)
}

/// The edge of `t` opposite its corner `v`, ordered so that (v, a, b) runs as `t` does. `t` is
/// always one of `v`'s faces (from a vertex–face list); corner 0 stands in if it is not.
#[inline]
fn opposite_edge(t: [u32; 3], v: u32) -> (u32, u32) {
    let k = t.iter().position(|&x| x == v).unwrap_or(0);
    (t[(k + 1) % 3], t[(k + 2) % 3])
}

/// Which spherical parameterisation is used.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, utoipa::ToSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum SphereMethod {
    /// The progressive map (flattening + vertex splits); the Tutte fallback when it fails or
    /// leaves a flipped triangle (the report says so and why).
    #[default]
    Auto,
    /// Only the progressive map (fails with a numerical problem if it cannot embed).
    Progressive,
    /// Only the guaranteed fallback: Tutte embedding of the mesh minus one vertex, inverse
    /// stereographic projection, Möbius normalisation, fold-free relaxation
    /// ([`crate::morph::sphere_fallback`]).
    Tutte,
}

/// Settings of the parameterisation (a subset of the job parameters).
#[derive(Clone, Debug)]
pub struct ParamSettings {
    pub working_vertices: usize,
    pub max_flatten_rounds: usize,
    pub relax_sweeps: usize,
    pub final_relax_sweeps: usize,
    pub sphere_method: SphereMethod,
    /// Fold-free relaxation sweeps after the fallback's Tutte map.
    pub fallback_relax_sweeps: usize,
    /// Test hook: the progressive path reports a numerical failure without trying (to test the
    /// fallback's wiring on inputs where the progressive path works).
    #[doc(hidden)]
    pub inject_progressive_failure: bool,
}

impl Default for ParamSettings {
    fn default() -> Self {
        ParamSettings {
            working_vertices: 1000,
            max_flatten_rounds: 30,
            relax_sweeps: 3,
            final_relax_sweeps: 10,
            sphere_method: SphereMethod::Auto,
            fallback_relax_sweeps: crate::morph::sphere_fallback::FallbackSettings::default().relax_sweeps,
            inject_progressive_failure: false,
        }
    }
}

/// A spherical embedding of a mesh: one unit vector per vertex.
#[derive(Clone, Debug)]
pub struct SphereMap {
    pub sphere: Vec<Point3>,
    pub report: ParamReport,
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ParamReport {
    /// "progressive" (flattening or tetrahedron, then vertex splits) or "fallback_tutte" (the
    /// guaranteed construction of [`crate::morph::sphere_fallback`]).
    pub param_method: String,
    /// Why the Tutte fallback was used (the progressive path's failure, or that it was asked for).
    pub param_fallback_reason: Option<String>,
    /// When flattening failed and the progressive map was kept after comparing it with the Tutte
    /// map: both maps' AD/SD.
    pub param_comparison: Option<String>,
    /// What the Tutte fallback did, when it ran.
    pub tutte: Option<crate::morph::sphere_fallback::FallbackReport>,
    /// How the coarse map of the progressive path was made: "curvature_flattening" or
    /// "tetrahedron" (when flattening did not reach a star shape); "tutte" for the fallback.
    pub method: String,
    pub working_vertices: usize,
    pub flatten_rounds: usize,
    /// Why the fallback was used, if it was.
    pub fallback_reason: Option<String>,
    pub vertex_splits: usize,
    /// Vertex splits that found no valid position at first and succeeded after smoothing the
    /// neighbourhood of the split vertex.
    pub local_repairs: usize,
    /// Faces of the final map with det ≤ 0 (must be 0).
    pub foldovers: usize,
    /// AD, seed 002 eq. IV.64 (radians): mean |angle in 3D − angle of the spherical chord triangle|.
    pub angle_distortion: f64,
    /// SD, seed 002 eq. IV.65: Σ |relative 3D area − relative chord-triangle area|, in [0, 2].
    pub area_distortion: f64,
    /// Earlier attempts that failed (settings and reason), when the first did not succeed.
    pub retries: Vec<String>,
    /// Wall time of the sub-steps, in run order.
    pub timings_ms: Vec<(String, f64)>,
}

/// Parameterises by `s.sphere_method`: the progressive map, with the guaranteed Tutte fallback
/// when it fails or leaves a flipped triangle (`auto`), or one of the two alone. Every result's
/// `foldovers` is counted with the exact orientation test.
pub fn parameterise(mesh: &TriMesh, s: &ParamSettings, progress: &Progress) -> Result<SphereMap> {
    match s.sphere_method {
        SphereMethod::Progressive => progressive::progressive(mesh, s, progress),
        SphereMethod::Tutte => tutte_fallback(mesh, s, "sphere_method: tutte".into(), Vec::new(), progress),
        SphereMethod::Auto => match progressive::progressive(mesh, s, progress) {
            // Flattening failed: the coarse map came from the Tutte map of the working mesh or a
            // tetrahedron, and on shapes with long protrusions (the cow's legs) the vertex splits
            // from there end far from the full-resolution Tutte map (cow: AD 0.99/SD 1.67 against
            // 0.34/0.89). Compute that too and keep the lower AD + SD.
            Ok(m) if m.report.foldovers == 0 && m.report.fallback_reason.is_some() => {
                let mut why = m.report.fallback_reason.clone().unwrap_or_default();
                if !m.report.retries.is_empty() {
                    why = format!("{why} (a retry, after: {})", m.report.retries.join("; "));
                }
                match tutte_fallback(mesh, s, String::new(), m.report.retries.clone(), progress) {
                    Ok(mut t) if t.report.foldovers == 0 => {
                        let (pa, pd) = (m.report.angle_distortion, m.report.area_distortion);
                        let (ta, td) = (t.report.angle_distortion, t.report.area_distortion);
                        let cmp = format!(
                            "{why}; progressive map ({} start) AD {pa:.3} SD {pd:.3}, Tutte map AD {ta:.3} SD {td:.3}",
                            m.report.method
                        );
                        if ta + td < pa + pd {
                            t.report.param_fallback_reason = Some(format!("{cmp}: kept the Tutte map"));
                            Ok(t)
                        } else {
                            let mut m = m;
                            m.report.param_comparison = Some(format!("{cmp}: kept the progressive map"));
                            Ok(m)
                        }
                    }
                    Ok(_) | Err(Error::Numerical { .. }) => Ok(m),
                    Err(e) => Err(e),
                }
            }
            Ok(m) if m.report.foldovers == 0 => Ok(m),
            Ok(m) => tutte_fallback(
                mesh,
                s,
                format!("the progressive map left {} flipped triangles", m.report.foldovers),
                m.report.retries,
                progress,
            ),
            Err(Error::Numerical { message, .. }) => {
                let why = format!("the progressive map failed: {message}");
                tutte_fallback(mesh, s, why.clone(), Vec::new(), progress).map_err(|e| match e {
                    Error::Numerical { message: m, .. } => {
                        Error::numerical("parameterise", format!("{why}; the Tutte fallback failed too: {m}"))
                    }
                    e => e,
                })
            }
            Err(e) => Err(e),
        },
    }
}

/// The guaranteed map ([`crate::morph::sphere_fallback`]) with its report.
fn tutte_fallback(
    mesh: &TriMesh,
    s: &ParamSettings,
    reason: String,
    retries: Vec<String>,
    progress: &Progress,
) -> Result<SphereMap> {
    let clock = std::time::Instant::now();
    let fs = crate::morph::sphere_fallback::FallbackSettings {
        relax_sweeps: s.fallback_relax_sweeps,
        ..Default::default()
    };
    let (sphere, fr) = crate::morph::sphere_fallback::parameterise(mesh, &fs, progress)?;
    let (ad, sd) = distortion(&mesh.pos, &sphere, &mesh.tris);
    let rep = ParamReport {
        param_method: "fallback_tutte".into(),
        param_fallback_reason: Some(reason),
        tutte: Some(fr),
        method: "tutte".into(),
        working_vertices: mesh.pos.len(),
        foldovers: count_foldovers(&sphere, &mesh.tris),
        angle_distortion: ad,
        area_distortion: sd,
        retries,
        timings_ms: vec![("tutte_fallback".into(), (clock.elapsed().as_secs_f64() * 1e6).round() / 1e3)],
        ..Default::default()
    };
    Ok(SphereMap { sphere, report: rep })
}

/// Faces whose chord triangle is not strictly positive, decided exactly.
pub fn count_foldovers(sphere: &[Point3], tris: &[[u32; 3]]) -> usize {
    crate::morph::sphere_fallback::count_foldovers_exact(sphere, tris)
}

/// AD and SD of seed 002 eq. IV.64–IV.65 between the 3D mesh and its spherical chord triangles.
pub fn distortion(pos: &[Point3], sphere: &[Point3], tris: &[[u32; 3]]) -> (f64, f64) {
    let mut ad = 0.0;
    let (mut a3, mut a2) = (0.0, 0.0);
    let areas: Vec<(f64, f64)> = tris
        .iter()
        .map(|t| {
            let p = t.map(|v| pos[v as usize]);
            let q = t.map(|v| sphere[v as usize]);
            for k in 0..3 {
                let a = corner_angle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
                let b = corner_angle(q[k], q[(k + 1) % 3], q[(k + 2) % 3]);
                ad += (a - b).abs();
            }
            let x = (triangle_area(p[0], p[1], p[2]), triangle_area(q[0], q[1], q[2]));
            a3 += x.0;
            a2 += x.1;
            x
        })
        .collect();
    let sd = areas.iter().map(|&(x, y)| (x / a3.max(1e-300) - y / a2.max(1e-300)).abs()).sum();
    (ad / (3.0 * tris.len().max(1) as f64), sd)
}
