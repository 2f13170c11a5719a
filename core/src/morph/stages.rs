//! The steps both morph domains share ([`super::sphere_job`], [`super::planar_job`]): every input
//! triangulated and its topology checked, the normalisation, feature indices mapped to the
//! triangulated inputs, the name of the correspondence that was used, and the common tail
//! (interpolation, GLB, Hausdorff distance of the end frames).

use serde_json::json;

use crate::error::{Error, Result};
use crate::job::{Artifact, Progress, Stages};
use crate::mesh::{Mesh, Point3};
use crate::register::{self, Similarity};

use super::domain;
use super::metamesh::{Layer, OverlayReport};
use super::pseudo::PseudoReport;
use super::trimesh::{self, Conversion, TopologyInfo, TriMesh};
use super::{input_name, output, report, Correspondence, MorphParams, Registration};

/// Every input as a triangle mesh, with where each input vertex went and what the conversion did.
pub(super) struct Triangulated {
    pub meshes: Vec<TriMesh>,
    /// Input vertex → triangulated vertex (`u32::MAX`: gone), through the repair when it ran.
    pub maps: Vec<Vec<u32>>,
    pub conversions: Vec<Conversion>,
    pub topology: Vec<TopologyInfo>,
}

/// Step 1 of both domains: every input under the vertex limit (checked again here because the
/// repair may have added vertices), triangulated, and its topology accepted by
/// `accept(k, topology)`, the domain's own rule.
pub(super) fn triangulate_inputs(
    inputs: &[Mesh],
    repair_maps: &[Option<Vec<u32>>],
    max_vertices: usize,
    accept: impl Fn(usize, &TopologyInfo) -> Result<()>,
) -> Result<Triangulated> {
    let mut out =
        Triangulated { meshes: Vec::new(), maps: Vec::new(), conversions: Vec::new(), topology: Vec::new() };
    for (k, m) in inputs.iter().enumerate() {
        domain::check_vertex_limit(k, m, max_vertices)?;
        let (t, map, conversion) = TriMesh::from_mesh(m);
        let info = trimesh::topology(&t);
        accept(k, &info)?;
        out.meshes.push(t);
        out.maps.push(domain::compose_vertex_maps(repair_maps[k].as_deref(), map));
        out.conversions.push(conversion);
        out.topology.push(info);
    }
    Ok(out)
}

/// Step 2 of both domains: every input in its PCA frame (with `Registration::None`, every input in
/// input 0's frame, so their relative placement is kept), then with `PcaIcp` rigid ICP of inputs
/// 1.. onto input 0. Returns the normalised meshes, each input's frame (input → normalised) and the
/// ICP results.
pub(super) fn normalise(
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
pub(super) fn map_features(features: &[Vec<u32>], maps: &[Vec<u32>], k_in: usize) -> Result<Vec<Vec<u32>>> {
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
/// The metamesh of all inputs and how it was built (either domain).
pub(super) struct Chain {
    pub layer: Layer,
    pub overlays: Vec<OverlayReport>,
    /// Set when an overlay failed and the barycentric transfer stood in for it.
    pub fallback: Option<String>,
    pub pseudo: Vec<PseudoReport>,
    /// Per spherical overlay, radians the target's embedding was rotated so it could be built
    /// (0: exact); empty on the planar domain.
    pub perturbation: Vec<f64>,
}

impl Chain {
    pub fn start(first: Layer) -> Chain {
        Chain {
            layer: first,
            overlays: Vec::new(),
            fallback: None,
            pseudo: Vec::new(),
            perturbation: Vec::new(),
        }
    }

    /// Every metamesh face lies inside one face of every input (a true overlay at every step).
    pub fn exact(&self, asked: Correspondence) -> bool {
        asked == Correspondence::Overlay && self.fallback.is_none()
    }
}

/// The part of a `per_input` report row both domains share; `domain_specific` (an object) adds
/// the parameterisation and whatever else the domain measured for input `k`.
/// The feature alignment must not fold the parameterisation: a warp that flipped `foldovers`
/// triangles is a numerical failure of the `align_features` stage (`warp` names which warp).
pub(super) fn reject_warp_foldovers(foldovers: usize, warp: &str) -> Result<()> {
    if foldovers > 0 {
        return Err(Error::numerical(
            "align_features",
            format!("{foldovers} flipped triangles after {warp}"),
        ));
    }
    Ok(())
}

pub(super) fn per_input_row(
    inputs: &Triangulated,
    k: usize,
    orientation_flipped: bool,
    hausdorff: &serde_json::Value,
    domain_specific: serde_json::Value,
) -> serde_json::Value {
    let mut row = json!({
        "input": k,
        "vertices": inputs.meshes[k].pos.len(),
        "faces": inputs.meshes[k].tris.len(),
        "topology": inputs.topology[k],
        "preparation": {"conversion": inputs.conversions[k], "orientation_flipped": orientation_flipped},
        "hausdorff_to_input": hausdorff[k],
    });
    merge_report(&mut row, domain_specific);
    row
}

/// The report's `correspondence`: what was asked for, or `transfer_fallback` when an overlay
/// failed and the barycentric transfer stood in for it.
pub(super) fn correspondence_name(asked: Correspondence, fallback: &Option<String>) -> &'static str {
    match (asked, fallback) {
        (Correspondence::Transfer, _) => "transfer",
        (Correspondence::Pseudo, _) => "pseudo",
        (_, Some(_)) => "transfer_fallback",
        _ => "overlay",
    }
}

/// Adds the members of `extra` (an object) to `report` (an object), replacing equal keys.
pub(super) fn merge_report(report: &mut serde_json::Value, extra: serde_json::Value) {
    if let (Some(r), serde_json::Value::Object(e)) = (report.as_object_mut(), extra) {
        r.extend(e);
    }
}

pub(super) struct Finish<'a> {
    pub layer: &'a Layer,
    pub frames_out: &'a [Similarity],
    pub normalised: &'a [TriMesh],
    /// Every metamesh face lies inside one face of every input (true overlay).
    pub exact: bool,
}

/// Interpolation, GLB (and frames ZIP), Hausdorff of the end frames: the common tail of both
/// domains. Returns (report with stages, meshes, artifacts).
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
        (0..k_in)
            .map(|k| {
                report::relative_hausdorff(
                    &layer.shapes[k],
                    &layer.tris,
                    &f.normalised[k].pos,
                    &f.normalised[k].tris,
                    !f.exact,
                    progress,
                )
            })
            .collect::<Result<Vec<f64>>>()
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
