//! The fit job (seed 000, "Template Based Mesh Fitting Through a Set of Curves"): deform a
//! template mesh so that it passes through a network of curves, then make the curves mesh edges,
//! label the regions they enclose and smooth with the curves held fixed.
//!
//! Pipeline (one timed stage each, see [`run`]):
//! 1. `curves`: weld the polylines into a network ([`curves`]).
//! 2. `coarse`: initial alignment, from the user's pairs by RBF (eq. 2.6–2.10), else PCA + ICP
//!    ([`align`]), or none.
//! 3. `fine`: closest-point correspondences ([`correspond`]) and an RBF through every curve vertex
//!    ([`rbf`]); faces that would flip are subdivided and the step repeated ([`flips`]).
//! 4. `retriangulate`: every curve segment becomes a chain of mesh edges ([`retriangulate`]).
//! 5. `partition`: faces labelled by region ([`partition`]).
//! 6. `smooth`: tangential flows with the curves fixed ([`smooth`]).
//!
//! The output mesh has one face group per region and carries the curves as vertex chains.

pub mod align;
pub mod approach;
pub mod cleanup;
pub mod compact;
pub mod correspond;
pub mod curves;
pub mod ends;
pub mod flips;
pub mod groups;
pub mod insert;
pub mod kdtree;
pub mod partition;
pub mod rbf;
pub mod report;
pub mod retriangulate;
pub mod smooth;
pub mod testdata;
pub mod trimesh;
pub mod untangle;
pub mod uvs;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::geometry::{add, dist, scale, sub, Aabb};
use crate::job::{Output, Progress, Stages};
use crate::mesh::{Faces, Mesh, Point3};

pub use rbf::Kernel;

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
    /// Add centres offset along the template's vertex normals that move with their base centre
    /// (the seed's remedy, §2.2.2).
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
    /// A curve vertex farther than this × the template's bounding-box diagonal from every template
    /// vertex (after alignment) is an error.
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
    /// Iterations of the modified mean-curvature flow.
    pub mcf_iterations: u32,
    /// Fraction of the way to the cotangent-weighted ring mean per mean-curvature step (0..1].
    pub mcf_step: f64,
    /// Iterations of the modified (tangential, back-projected) Laplacian flow.
    pub laplacian_iterations: u32,
    /// Largest number of RBF centres (curve vertices) accepted: the dense solve is O(n³).
    pub max_curve_vertices: u32,
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
            max_curve_distance: 0.25,
            end_snap: 0.05,
            max_flip_iterations: 4,
            approach_levels: 3,
            snap_fraction: 0.3,
            cleanup: true,
            cleanup_min_angle_deg: 15.0,
            smooth: true,
            mcf_iterations: 10,
            mcf_step: 0.5,
            laplacian_iterations: 20,
            max_curve_vertices: 8000,
        }
    }
}

impl FitParams {
    fn validate(&self) -> Result<()> {
        let bad = |f: &str, m: &str| Err(Error::params(f, m));
        if !(self.join_tolerance.is_finite() && self.join_tolerance >= 0.0 && self.join_tolerance < 0.1) {
            return bad("join_tolerance", "must be in [0, 0.1)");
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
        if !(self.mcf_step.is_finite() && self.mcf_step > 0.0 && self.mcf_step <= 1.0) {
            return bad("mcf_step", "must be in (0, 1]");
        }
        if !(self.cleanup_min_angle_deg.is_finite() && (0.0..=50.0).contains(&self.cleanup_min_angle_deg)) {
            return bad("cleanup_min_angle_deg", "must be in [0, 50]");
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

/// Runs the whole fit. `inputs` = [template, curves]; the curves mesh carries polylines in
/// `Mesh::curves` (its faces, if any, are ignored).
pub fn run(inputs: Vec<Mesh>, params: &FitParams, progress: &Progress) -> Result<Output> {
    params.validate()?;
    let mut it = inputs.into_iter();
    let (Some(template), Some(curve_mesh), None) = (it.next(), it.next(), it.next()) else {
        return Err(Error::params("inputs", "fit takes exactly two meshes: template, curves"));
    };
    let mut stages = Stages::new();
    let net = stages
        .run(progress, "curves", || curves::CurveNetwork::from_mesh(&curve_mesh, params.join_tolerance))?;
    if net.points.len() > params.max_curve_vertices as usize {
        return Err(Error::TooLarge {
            what: "curve vertices (RBF centres)".into(),
            limit: params.max_curve_vertices as u64,
            actual: net.points.len() as u64,
        });
    }
    let mut tris = stages.run(progress, "validate", || {
        let tris = crate::shapes::fan_triangles(&template.faces);
        if tris.is_empty() {
            return Err(Error::params("template", "the template has no faces"));
        }
        // Fails early, naming the face, on a non-manifold or inconsistently oriented template.
        trimesh::check_oriented_manifold(&tris)?;
        Ok(tris)
    })?;
    let template_diag = Aabb::of(&template.positions).map(|b| b.diagonal()).unwrap_or(0.0);
    let mut pos = template.positions.clone();

    let coarse =
        stages.run(progress, "coarse", || coarse_alignment(&mut pos, &tris, &net, params, progress))?;

    // Vertices added by the fine stage, as weighted combinations of older ones (vertex
    // `template.vertex_count() + i` has `parents[i]`): the template's UVs follow them.
    let mut parents: Vec<[(u32, f64); 3]> = Vec::new();
    let fine = stages.run(progress, "fine", || {
        let clock = std::time::Instant::now();
        let pair_fixed: Vec<(u32, u32)> = coarse
            .pair_curve_points
            .iter()
            .zip(&params.pairs)
            .map(|(&p, pr)| (p, pr.template_vertex))
            .collect();
        let levels = params.approach_levels as usize;
        let limit = params.max_curve_distance * template_diag;
        let approach =
            approach::approach(&mut pos, &tris, &net, &pair_fixed, params.kernel, levels, limit, progress)?;
        let approach_ms = clock.elapsed().as_secs_f64() * 1e3;
        let mut fine =
            fine_dispatch(&mut pos, &mut tris, &net, &coarse, params, template_diag, &mut parents, progress)?;
        fine.report.approach = Some(approach);
        fine.report.approach_ms = approach_ms;
        Ok(fine)
    })?;

    // Folds the fine deformation left (faces turned against the surface before it) are undone by
    // local edge flips and ring-mean moves of non-curve vertices.
    let mut mesh = trimesh::TriMesh::new(fine.positions.clone(), std::mem::take(&mut tris))?;
    let untangle_fine = stages.run(progress, "untangle_fine", || {
        let reference = report::vertex_normals(&pos, &mesh.tris);
        let mut fixed = vec![false; pos.len()];
        for &v in &fine.vertex_of_point {
            fixed[v as usize] = true;
        }
        Ok(untangle::untangle(&mut mesh, &reference, &fixed, &untangle::EdgeSet::default(), 8))
    })?;
    let tris = mesh.live_triangles();

    // The template's own face groups, when it has several, are intersected with the regions.
    let keep_groups = template.groups.len() > 1
        && template.faces.iter().map(|f| f.len().saturating_sub(2)).sum::<usize>()
            == crate::shapes::fan_triangles(&template.faces).len();
    let fine_groups = if keep_groups {
        let template_tris = crate::shapes::fan_triangles(&template.faces);
        let template_groups: Vec<u32> = (0..template.faces.len())
            .flat_map(|i| {
                std::iter::repeat_n(template.faces.group(i), template.faces.arity(i).saturating_sub(2))
            })
            .collect();
        groups::after_refinement(
            &tris,
            &pos,
            &template_tris,
            &template_groups,
            template.vertex_count(),
            &parents,
        )
    } else {
        Vec::new()
    };
    let fine_tris = if keep_groups { tris.clone() } else { Vec::new() };
    let fine_positions = mesh.pos.clone();
    let mut reference_normals = report::vertex_normals(&fine_positions, &tris);
    let realised = stages.run(progress, "retriangulate", || {
        retriangulate::realise(&mut mesh, &net, &fine.vertex_of_point, params.snap_fraction, progress)
    })?;
    parents.extend_from_slice(&realised.added);
    // Vertices split into crossed edges take the reference normal of their edge.
    for a in &realised.added {
        let n = add(
            scale(reference_normals[a[0].0 as usize], a[0].1),
            scale(reference_normals[a[1].0 as usize], a[1].1),
        );
        reference_normals.push(crate::geometry::normalize(n));
    }
    let mut curve_edges = untangle::EdgeSet::default();
    for c in &realised.chains {
        for p in c.windows(2) {
            curve_edges.insert((p[0].min(p[1]), p[0].max(p[1])));
        }
    }
    // Folds made by snapping vertices onto segments and by the re-triangulated strips, against the
    // fine surface; chain vertices stay fixed and curve edges locked.
    let untangle_retri = stages.run(progress, "untangle_retriangulated", || {
        // (Boundary vertices are never moved by the untangling either.)
        Ok(untangle::untangle(&mut mesh, &reference_normals, &realised.on_curve, &curve_edges, 8))
    })?;
    let retri_tris = mesh.live_triangles();
    let angles_retri = report::angle_stats(&mesh.pos, &retri_tris);
    let (region0, mut region_count) =
        stages.run(progress, "partition", || Ok(partition::regions(&retri_tris, &curve_edges)))?;
    // Label of every face id: region × template group, kept by the clean-up.
    let group0 = if keep_groups {
        groups::after_retriangulation(&fine_tris, &fine_groups, &retri_tris, mesh.pos.len())
    } else {
        vec![0; retri_tris.len()]
    };
    let mut labels = vec![u64::MAX; mesh.tris.len()];
    for ((f, &r), &g) in mesh.alive_faces().collect::<Vec<_>>().into_iter().zip(&region0).zip(&group0) {
        labels[f as usize] = ((r as u64) << 32) | g as u64;
    }
    drop(retri_tris);
    let boundary: Vec<bool> = (0..mesh.pos.len() as u32).map(|v| mesh.is_boundary_vertex(v)).collect();
    let fixed: Vec<bool> = (0..mesh.pos.len()).map(|v| realised.on_curve[v] || boundary[v]).collect();
    let cleaned = stages.run(progress, "cleanup", || {
        if !params.cleanup {
            return Ok(cleanup::CleanupStats::default());
        }
        let mut curve_point = vec![false; mesh.pos.len()];
        for &v in &fine.vertex_of_point {
            curve_point[v as usize] = true;
        }
        let mut c = cleanup::Constraints {
            fixed: &fixed,
            locked: curve_edges.clone(),
            chain: cleanup::Constraints::chain_vertices(&realised.chains, &curve_point, &boundary),
            reference_normals: &reference_normals,
        };
        let s = cleanup::CleanupSettings { min_angle_deg: params.cleanup_min_angle_deg, max_passes: 8 };
        cleanup::clean(&mut mesh, &mut labels, &mut c, &s, progress)
    })?;
    // Vertices the clean-up removed stay in the arrays (faceless) until the output is built.
    let mut realised = realised;
    if !cleaned.removed_vertices.is_empty() {
        // Chain vertices the clean-up removed leave their chains (their neighbours are joined).
        let mut gone = vec![false; mesh.pos.len()];
        for &v in &cleaned.removed_vertices {
            gone[v as usize] = true;
        }
        for c in realised.chains.iter_mut() {
            c.retain(|&v| !gone[v as usize]);
        }
        curve_edges.clear();
        for c in &realised.chains {
            for p in c.windows(2) {
                curve_edges.insert((p[0].min(p[1]), p[0].max(p[1])));
            }
        }
    }
    let mut out_tris = mesh.live_triangles();
    let mut region: Vec<u32> = mesh.alive_faces().map(|f| (labels[f as usize] >> 32) as u32).collect();
    // Template groups of the faces the clean-up made: the rule used for re-triangulated faces
    // (the clean-up never edits across a group border, but a face re-triangulation made across
    // one carries a majority label that is not the geometric truth for its pieces).
    let mut tg: Vec<u32> = if keep_groups && cleaned.flips + cleaned.collapses > 0 {
        groups::after_retriangulation(&fine_tris, &fine_groups, &out_tris, mesh.pos.len())
    } else {
        mesh.alive_faces().map(|f| labels[f as usize] as u32).collect()
    };
    let angles_before = report::angle_stats(&mesh.pos, &out_tris);
    let mut out_pos = mesh.pos.clone();
    let mut smoothing = smooth::SmoothStats::default();
    if params.smooth {
        let settings = smooth::SmoothSettings {
            mcf_iterations: params.mcf_iterations,
            mcf_step: params.mcf_step,
            laplacian_iterations: params.laplacian_iterations,
            // Smoothing does not make a face the clean-up accepts into one it would treat.
            min_angle_floor_deg: params.cleanup_min_angle_deg,
        };
        smoothing = stages.run(progress, "smooth", || {
            smooth::smooth(&mut out_pos, &out_tris, &fixed, &settings, progress)
        })?;
    }
    // Smoothing moves free vertices by tangential steps that can fold a face in a tight spot: the
    // same untangling, against the same reference, on the smoothed positions.
    let untangle_smoothed = if params.smooth {
        mesh.pos = out_pos;
        let s = stages.run(progress, "untangle_smoothed", || {
            Ok(untangle::untangle(&mut mesh, &reference_normals, &realised.on_curve, &curve_edges, 8))
        })?;
        out_pos = mesh.pos.clone();
        if s.edge_flips > 0 {
            // Flipped edges are never curve edges, so regions are unchanged; the labels are
            // recomputed for the new face list.
            out_tris = mesh.live_triangles();
            (region, region_count) = partition::regions(&out_tris, &curve_edges);
            if keep_groups {
                tg = groups::after_retriangulation(&fine_tris, &fine_groups, &out_tris, out_pos.len());
            }
        }
        Some(s)
    } else {
        None
    };
    let angles_after = report::angle_stats(&out_pos, &out_tris);

    // Vertices removed by the clean-up leave the output; every per-vertex array is renumbered.
    let keep = compact::Renumber::new(out_pos.len(), &cleaned.removed_vertices);
    let out_tris: Vec<[u32; 3]> = out_tris.iter().map(|&t| keep.tri(t)).collect();
    for c in realised.chains.iter_mut() {
        keep.apply(c);
    }
    let mut vertex_of_point = fine.vertex_of_point.clone();
    keep.apply(&mut vertex_of_point);
    let reference_normals = keep.vec(&reference_normals);
    let fine_positions = keep.vec(&fine_positions);
    let out_pos = keep.vec(&out_pos);

    // Output mesh: one group per region (per region × template group when the template had
    // groups), the curves as vertex chains.
    let mut faces = Faces::with_capacity(out_tris.len(), out_tris.len() * 3);
    let mut group_names: Vec<String> = (0..region_count).map(|i| format!("region_{i}")).collect();
    if keep_groups {
        let mut id: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        group_names.clear();
        for ((t, &r), &g) in out_tris.iter().zip(&region).zip(&tg) {
            let gid = *id.entry((r, g)).or_insert_with(|| {
                group_names.push(format!("region_{r}/{}", template.group_name(g)));
                (group_names.len() - 1) as u32
            });
            faces.push(t, gid);
        }
    } else {
        for (t, &g) in out_tris.iter().zip(&region) {
            faces.push(t, g);
        }
    }
    let mut out = Mesh::new(out_pos, faces);
    out.uvs = template.uvs.as_ref().map(|uv| {
        let mut uvs = interpolate_uvs(uv, &parents);
        uvs::apply(&mut uvs, &realised.uv_moves);
        keep.vec(&uvs)
    });
    out.groups = group_names;
    out.curves = report::polyline_chains(&net, &realised.chains);

    let quality = stages.run(progress, "quality", || {
        Ok(report::Quality::measure(
            &out,
            &net,
            &vertex_of_point,
            &realised,
            &out_tris,
            &fine_positions,
            &reference_normals,
        ))
    })?;
    let report = serde_json::json!({
        "template_vertices": template.vertex_count(),
        "template_faces": template.face_count(),
        "template_triangles": crate::shapes::fan_triangles(&template.faces).len(),
        "template_groups_kept": if keep_groups { template.groups.len() } else { 0 },
        "output_vertices": out.vertex_count(),
        "output_faces": out.face_count(),
        "curve_vertices": net.points.len(),
        "curve_segments": net.segments.len(),
        "curve_polylines": net.polylines.len(),
        "feature_points": net.feature_count(),
        "curve_vertices_welded": net.welded_vertices,
        "alignment": coarse,
        "fine": fine.report,
        "retriangulation": realised.stats,
        "untangle": { "fine": untangle_fine, "retriangulated": untangle_retri, "smoothed": untangle_smoothed },
        "regions": region_count,
        "curve_residual_max": quality.curve_residual_max,
        "curve_residual_mean": quality.curve_residual_mean,
        "curve_residual_max_relative": quality.curve_residual_max / template_diag.max(f64::MIN_POSITIVE),
        "chain_deviation_max": quality.chain_deviation_max,
        "segments_as_edges": quality.segments_as_edges,
        "flipped_faces": quality.flipped_faces,
        "flipped_faces_after_fine": fine.report.flipped_faces,
        "cleanup": cleaned,
        "moved_vertices": realised.uv_moves.iter().map(|m| m.vertex).collect::<Vec<_>>(),
        "smoothing": smoothing,
        "min_angle_deg_after_retriangulation": angles_retri.min_deg,
        "mean_min_angle_deg_after_retriangulation": angles_retri.mean_min_deg,
        "faces_below_10deg_after_retriangulation": angles_retri.below_10,
        "min_angle_deg_before_smoothing": angles_before.min_deg,
        "min_angle_deg_after_smoothing": angles_after.min_deg,
        "mean_min_angle_deg_before_smoothing": angles_before.mean_min_deg,
        "mean_min_angle_deg_after_smoothing": angles_after.mean_min_deg,
        "faces_below_10deg_before_smoothing": angles_before.below_10,
        "faces_below_10deg_after_smoothing": angles_after.below_10,
        "smoothed": params.smooth,
        "total_ms": stages.total_ms(),
        "stages": stages.to_json(),
    });
    Ok(Output { meshes: vec![out], report, ..Default::default() })
}

/// What the coarse stage did (serialised into the report).
#[derive(Debug, Clone, Serialize)]
pub struct CoarseReport {
    /// "pairs", "pca_icp" or "none".
    pub method: &'static str,
    /// Curve vertex each pair snapped to, per pair.
    pub pair_curve_points: Vec<u32>,
    pub pair_snap_distance_max: f64,
    /// PCA + ICP final RMS distance of curve points to template vertices.
    pub icp_rms: Option<f64>,
}

fn coarse_alignment(
    pos: &mut [Point3],
    tris: &[[u32; 3]],
    net: &curves::CurveNetwork,
    params: &FitParams,
    progress: &Progress,
) -> Result<CoarseReport> {
    let use_pairs = match params.alignment {
        Alignment::Pairs => true,
        Alignment::Auto => !params.pairs.is_empty(),
        _ => false,
    };
    if use_pairs {
        let (fixed, snap_max) = snap_pairs(&params.pairs, pos.len(), net)?;
        let centres: Vec<Point3> = fixed.iter().map(|&(_, v)| pos[v as usize]).collect();
        let values: Vec<Point3> =
            fixed.iter().map(|&(p, v)| sub(net.points[p as usize], pos[v as usize])).collect();
        let name = |i: usize| format!("pairs[{i}] (template vertex {})", params.pairs[i].template_vertex);
        let f = fit_rbf(
            pos,
            tris,
            centres,
            values,
            &fixed.iter().map(|x| x.1).collect::<Vec<_>>(),
            params,
            "coarse",
            "pairs",
            &name,
        )?;
        let disp = f.eval_many(pos, progress)?;
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
        });
    }
    if matches!(params.alignment, Alignment::None) {
        return Ok(CoarseReport {
            method: "none",
            pair_curve_points: vec![],
            pair_snap_distance_max: 0.0,
            icp_rms: None,
        });
    }
    let (sim, rms) = align::pca_icp(pos, &net.points, 30, progress)?;
    for p in pos.iter_mut() {
        *p = sim.apply(*p);
    }
    Ok(CoarseReport {
        method: "pca_icp",
        pair_curve_points: vec![],
        pair_snap_distance_max: 0.0,
        icp_rms: Some(rms),
    })
}

/// Validates the pairs and snaps each curve point to its nearest curve vertex.
fn snap_pairs(pairs: &[FitPair], nv: usize, net: &curves::CurveNetwork) -> Result<(Vec<(u32, u32)>, f64)> {
    let tree = kdtree::KdTree::new(&net.points);
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
        let (cp, d2) =
            tree.nearest(p.curve_point).ok_or_else(|| Error::Internal("empty curve network".into()))?;
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
#[allow(clippy::too_many_arguments)]
fn fit_rbf(
    pos: &[Point3],
    tris: &[[u32; 3]],
    mut centres: Vec<Point3>,
    mut values: Vec<Point3>,
    centre_vertices: &[u32],
    params: &FitParams,
    stage: &str,
    field: &str,
    name: &dyn Fn(usize) -> String,
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
            augment(pos, tris, &mut centres, &mut values, centre_vertices);
            if let Err(d) = rbf::check_centres(&centres) {
                return Err(Error::params(
                    field,
                    format!("{stage} RBF centres stay degenerate after augmentation: {d:?}"),
                ));
            }
        }
    }
    rbf::Rbf::fit(&centres, &values, params.kernel, stage)
}

/// Adds, for up to 8 spread-out centres, two points offset along the template vertex normal by
/// ± 10% of the centres' extent, carrying the same displacement (they move rigidly with their base).
fn augment(
    pos: &[Point3],
    tris: &[[u32; 3]],
    centres: &mut Vec<Point3>,
    values: &mut Vec<Point3>,
    centre_vertices: &[u32],
) {
    let n = centres.len();
    let h = 0.1 * Aabb::of(centres).map(|b| b.diagonal()).unwrap_or(1.0);
    let mut normal = vec![[0.0; 3]; pos.len()];
    for t in tris {
        let fnm = crate::geometry::triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
        for &v in t {
            normal[v as usize] = add(normal[v as usize], fnm);
        }
    }
    let k = n.min(8);
    for j in 0..k {
        let i = j * n / k;
        let nm = crate::geometry::normalize(normal[centre_vertices[i] as usize]);
        if nm == [0.0; 3] {
            continue;
        }
        for sgn in [1.0, -1.0] {
            centres.push(add(centres[i], crate::geometry::scale(nm, sgn * h)));
            values.push(values[i]);
        }
    }
}

/// The fine stage's result.
pub struct Fine {
    pub positions: Vec<Point3>,
    pub vertex_of_point: Vec<u32>,
    pub report: FineReport,
}

#[derive(Debug, Clone, Serialize)]
pub struct FineReport {
    pub rounds: u32,
    pub correspondence_conflicts: usize,
    pub correspondence_distance_max: f64,
    pub correspondence_distance_mean: f64,
    /// Faces flagged per round (flip counter ∪ orientation test).
    pub flagged_per_round: Vec<usize>,
    pub flagged_by_counter: usize,
    pub flagged_by_orientation: usize,
    /// Faces added by local subdivision.
    pub faces_added: usize,
    /// Faces still flipped by the last round (goal 0).
    pub flipped_faces: usize,
    pub augmented: bool,
    /// "insert" or "nearest_vertex".
    pub matching: &'static str,
    /// What the insertion did (matching = insert).
    pub insertion: Option<insert::InsertStats>,
    /// Milliseconds per step of the fine stage (matching = insert): insert, solve, evaluate, flips.
    pub steps_ms: Option<[f64; 4]>,
    /// The multi-level approach to the curves before the exact fit (see [`approach`]).
    pub approach: Option<approach::ApproachReport>,
    pub approach_ms: f64,
}

/// Fails, naming the curve, when a curve vertex is farther than the limit from its template vertex.
fn check_distances(
    distances: &[f64],
    net: &curves::CurveNetwork,
    params: &FitParams,
    template_diag: f64,
) -> Result<()> {
    let limit = params.max_curve_distance * template_diag;
    if let Some((p, d)) = distances.iter().enumerate().find(|(_, &d)| d > limit) {
        let c = net.curve_of_point[p];
        return Err(Error::params(
            "curves",
            format!(
                "curve {c}: its point {:?} is {d:.4} from the template, more than \
                 max_curve_distance ({}) × the template's bounding-box diagonal ({template_diag:.4}) \
                 after alignment; the curves do not lie on the template (check units, or give pairs)",
                net.points[p], params.max_curve_distance
            ),
        ));
    }
    Ok(())
}

/// The fine stage proper, by matching rule.
#[allow(clippy::too_many_arguments)]
fn fine_dispatch(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    net: &curves::CurveNetwork,
    coarse: &CoarseReport,
    params: &FitParams,
    template_diag: f64,
    parents: &mut Vec<[(u32, f64); 3]>,
    progress: &Progress,
) -> Result<Fine> {
    match params.matching {
        Matching::Insert => {
            fine_fit_inserted(pos, tris, net, coarse, params, template_diag, parents, progress)
        }
        Matching::NearestVertex => fine_fit(pos, tris, net, coarse, params, template_diag, parents, progress),
    }
}

/// The fine stage with `Matching::Insert`: split the template at the curve vertices' feet, solve
/// the RBF once, and handle flips by subdividing the flagged faces under the *same* field (the
/// centres never change, so only the new midpoints are evaluated: no re-solve per round).
#[allow(clippy::too_many_arguments)]
fn fine_fit_inserted(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    net: &curves::CurveNetwork,
    coarse: &CoarseReport,
    params: &FitParams,
    template_diag: f64,
    parents: &mut Vec<[(u32, f64); 3]>,
    progress: &Progress,
) -> Result<Fine> {
    let pair_fixed: Vec<(u32, u32)> =
        coarse.pair_curve_points.iter().zip(&params.pairs).map(|(&p, pr)| (p, pr.template_vertex)).collect();
    let clock = std::time::Instant::now();
    let mut steps_ms = [0.0; 4];
    let mut lap = |k: usize| {
        steps_ms[k] = clock.elapsed().as_secs_f64() * 1e3 - steps_ms.iter().sum::<f64>();
    };
    let before = tris.clone();
    let nv0 = pos.len();
    let ins =
        insert::insert_curve_points(pos, tris, net, &pair_fixed, params.end_snap * template_diag, progress)?;
    for c in &ins.created_in[nv0..] {
        let (f, l) = c.ok_or_else(|| Error::Internal("inserted vertex without origin".into()))?;
        let t = before[f as usize];
        parents.push([(t[0], l[0]), (t[1], l[1]), (t[2], l[2])]);
    }
    drop(before);
    let vop = ins.vertex_of_point.clone();
    let distances: Vec<f64> = (0..vop.len()).map(|p| dist(net.points[p], pos[vop[p] as usize])).collect();
    check_distances(&distances, net, params, template_diag)?;
    let centres: Vec<Point3> = vop.iter().map(|&v| pos[v as usize]).collect();
    let values: Vec<Point3> = (0..vop.len()).map(|p| sub(net.points[p], centres[p])).collect();
    let name = |i: usize| format!("curve {} point {i} (template vertex {})", net.curve_of_point[i], vop[i]);
    let before_aug = centres.len();
    lap(0);
    let f = fit_rbf(pos, tris, centres, values, &vop, params, "fine", "curves", &name)?;
    lap(1);
    let augmented = f.centre_count() > before_aug;
    let disp = f.eval_many(pos, progress)?;
    let mut moved: Vec<Point3> = pos.iter().zip(&disp).map(|(p, d)| add(*p, *d)).collect();
    for (p, &v) in vop.iter().enumerate() {
        moved[v as usize] = net.points[p]; // exact, not RBF round-off
    }
    lap(2);
    let mut scan = flips::detect(pos, &moved, tris);
    let mut flagged_per_round = vec![scan.flipped.len()];
    let (mut rounds, mut faces_added) = (1, 0);
    let budget = tris.len() / 2;
    while !scan.flipped.is_empty()
        && rounds <= params.max_flip_iterations
        && faces_added + 6 * scan.flipped.len() <= budget
    {
        progress.check()?;
        let (p0, t0, par0) = (pos.len(), tris.clone(), parents.len());
        let added = flips::subdivide(pos, tris, &scan.flipped, parents);
        let d = f.eval_many(&pos[p0..], progress)?;
        moved.extend(pos[p0..].iter().zip(d).map(|(p, d)| add(*p, d)));
        let next = flips::detect(pos, &moved, tris);
        flagged_per_round.push(next.flipped.len());
        rounds += 1;
        if next.flipped.len() >= scan.flipped.len() {
            // No better under this field: undo the round (smaller faces fold the same way).
            pos.truncate(p0);
            moved.truncate(p0);
            parents.truncate(par0);
            *tris = t0;
            break;
        }
        faces_added += added;
        scan = next;
    }
    lap(3);
    let n = distances.len().max(1) as f64;
    Ok(Fine {
        positions: moved,
        vertex_of_point: vop,
        report: FineReport {
            rounds,
            correspondence_conflicts: ins.stats.nudged,
            correspondence_distance_max: distances.iter().cloned().fold(0.0, f64::max),
            correspondence_distance_mean: distances.iter().sum::<f64>() / n,
            flagged_per_round,
            flagged_by_counter: scan.by_counter,
            flagged_by_orientation: scan.by_orientation,
            faces_added,
            flipped_faces: scan.flipped.len(),
            augmented,
            matching: "insert",
            insertion: Some(ins.stats),
            steps_ms: Some(steps_ms),
            approach: None,
            approach_ms: 0.0,
        },
    })
}

/// The template's UVs extended to the vertices the fit added (each a weighted combination of
/// older vertices, in creation order).
pub fn interpolate_uvs(uv: &[[f64; 2]], parents: &[[(u32, f64); 3]]) -> Vec<[f64; 2]> {
    let mut out = uv.to_vec();
    out.reserve(parents.len());
    for p in parents {
        let mut u = [0.0; 2];
        for &(v, w) in p {
            let q = out[v as usize];
            u[0] += w * q[0];
            u[1] += w * q[1];
        }
        out.push(u);
    }
    out
}

#[allow(clippy::too_many_arguments)]
fn fine_fit(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    net: &curves::CurveNetwork,
    coarse: &CoarseReport,
    params: &FitParams,
    template_diag: f64,
    parents: &mut Vec<[(u32, f64); 3]>,
    progress: &Progress,
) -> Result<Fine> {
    let pair_fixed: Vec<(u32, u32)> =
        coarse.pair_curve_points.iter().zip(&params.pairs).map(|(&p, pr)| (p, pr.template_vertex)).collect();
    let nv0 = pos.len() - parents.len();
    let mut flagged_per_round = Vec::new();
    let mut faces_added = 0;
    let budget = tris.len(); // subdivision may at most double the face count
    let mut best: Option<(Fine, Vec<Point3>, Vec<[u32; 3]>)> = None;
    for round in 0..=params.max_flip_iterations {
        progress.check()?;
        let corr = correspond::closest(pos, net, &pair_fixed, progress)?;
        check_distances(&corr.distances, net, params, template_diag)?;
        let vop = corr.vertex_of_point.clone();
        let centres: Vec<Point3> = vop.iter().map(|&v| pos[v as usize]).collect();
        let values: Vec<Point3> = (0..vop.len()).map(|p| sub(net.points[p], centres[p])).collect();
        let name =
            |i: usize| format!("curve {} point {i} (template vertex {})", net.curve_of_point[i], vop[i]);
        let before_aug = centres.len();
        let f = fit_rbf(pos, tris, centres, values, &vop, params, "fine", "curves", &name)?;
        let augmented = f.centre_count() > before_aug;
        let disp = f.eval_many(pos, progress)?;
        let mut moved: Vec<Point3> = pos.iter().zip(&disp).map(|(p, d)| add(*p, *d)).collect();
        for (p, &v) in vop.iter().enumerate() {
            moved[v as usize] = net.points[p]; // exact, not RBF round-off
        }
        let scan = flips::detect(pos, &moved, tris);
        flagged_per_round.push(scan.flipped.len());
        let n = corr.distances.len().max(1) as f64;
        let flagged = scan.flipped.clone();
        let fine = Fine {
            positions: moved,
            vertex_of_point: vop,
            report: FineReport {
                rounds: round + 1,
                correspondence_conflicts: corr.conflicts,
                correspondence_distance_max: corr.distances.iter().cloned().fold(0.0, f64::max),
                correspondence_distance_mean: corr.distances.iter().sum::<f64>() / n,
                flagged_per_round: Vec::new(),
                flagged_by_counter: scan.by_counter,
                flagged_by_orientation: scan.by_orientation,
                faces_added,
                flipped_faces: scan.flipped.len(),
                augmented,
                matching: "nearest_vertex",
                insertion: None,
                steps_ms: None,
                approach: None,
                approach_ms: 0.0,
            },
        };
        // Keep the round with the fewest flips; a round that does not improve stops the loop
        // (measured on homer: 52 → 23 → 37 → 98 → 375 flagged faces when it goes on, because the
        // new, smaller faces fold in the same steep part of the field).
        let matched_now = fine.vertex_of_point.clone();
        let improves = best.as_ref().is_none_or(|b| fine.report.flipped_faces < b.0.report.flipped_faces);
        if improves {
            best = Some((fine, pos.clone(), tris.clone()));
        }
        let done = flagged.is_empty()
            || !improves
            || round == params.max_flip_iterations
            || faces_added + 3 * flagged.len() * 2 > budget;
        if done {
            break;
        }
        // Subdivide the flagged faces and the stars of the matched vertices on them: a fold
        // usually comes from a curve vertex matched to a template vertex a whole edge away, and
        // the star's new edge midpoints give it a closer candidate in the next round.
        let split = flips::with_matched_stars(tris, &flagged, &matched_now);
        faces_added += flips::subdivide(pos, tris, &split, parents);
    }
    if let Some((mut fine, p, t)) = best {
        parents.truncate(p.len() - nv0);
        *pos = p;
        *tris = t;
        fine.report.flagged_per_round = flagged_per_round;
        return Ok(fine);
    }
    Err(Error::Internal("flip loop ended without a result".into()))
}

/// Distance helper kept here for the report.
pub(crate) fn point_segment_distance(p: Point3, a: Point3, b: Point3) -> f64 {
    let ab = sub(b, a);
    let l2 = crate::geometry::norm2(ab);
    let t = if l2 > 0.0 { (crate::geometry::dot(sub(p, a), ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    dist(p, add(a, crate::geometry::scale(ab, t)))
}
