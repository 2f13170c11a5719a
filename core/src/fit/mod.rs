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
//! 7. `turned_faces`: the faces the report's `flipped_faces` counts, repaired by local edits that
//!    add no fold (edge flips, vertex moves, edge splits: [`turned`]).
//!
//! The output mesh has one face group per region and carries the curves as vertex chains.
//!
//! Files: `params.rs` (the job's parameters), `coarse.rs` (stage 2 and the RBF fit with its named
//! errors), `fine.rs` (stage 3: `fine_stage`, by matching rule), `groups.rs` (region and template
//! group labels, the output's face groups), this file (the pipeline, [`run`]).

pub mod align;
pub mod approach;
pub mod cleanup;
mod coarse;
pub mod compact;
pub mod correspond;
pub mod curves;
pub mod degenerate;
pub mod ends;
pub mod field_refine;
mod fine;
pub mod flips;
pub mod groups;
pub mod insert;
pub mod kdtree;
pub mod orientation;
mod params;
pub mod partition;
pub mod rbf;
pub mod reference;
pub mod refine;
pub mod report;
pub mod retriangulate;
pub mod sheets;
pub mod smooth;
pub mod template;
pub mod testdata;
pub mod thin;
pub mod trimesh;
pub mod turned;
pub mod untangle;
pub mod uvs;

use crate::error::{Error, Result};
use crate::geometry::{add, dist, scale, Aabb};
use crate::job::{Output, Progress, Stages};
use crate::mesh::{Mesh, Point3};

pub use coarse::CoarseReport;
pub use fine::{interpolate_uvs, Fine, FineReport};
pub use params::{Alignment, CoplanarCentres, FitPair, FitParams, Matching};
pub use rbf::Kernel;

use coarse::coarse_alignment;

/// The refinement's face budget: this many faces per curve vertex, over the template's.
const REFINE_FACES_PER_CURVE_VERTEX: usize = 8;

/// Runs the whole fit. `inputs` = [template, curves]; the curves mesh carries polylines in
/// `Mesh::curves` (its faces, if any, are ignored).
pub fn run(inputs: Vec<Mesh>, params: &FitParams, progress: &Progress) -> Result<Output> {
    params.validate()?;
    let mut it = inputs.into_iter();
    let (Some(template), Some(curve_mesh), None) = (it.next(), it.next(), it.next()) else {
        return Err(Error::params("inputs", "fit takes exactly two meshes: template, curves"));
    };
    // Coincident vertices are welded (unwelded seams), then vertices in no face are removed
    // (both counted in the report); pairs are renumbered.
    let (mut template, mut weld_pairs) = (template, params.pairs.clone());
    // Faces with a repeated corner (collapsed edges) are mended or removed, and counted.
    let repeated_corners = template::drop_repeated_corners(&mut template);
    let welded = template::weld_coincident(&mut template, &mut weld_pairs);
    let (template, renumbered_pairs, unreferenced) = template::drop_unreferenced(template, &weld_pairs)?;
    let renumbered;
    let params = match renumbered_pairs {
        Some(pairs) => {
            renumbered = FitParams { pairs, ..params.clone() };
            &renumbered
        }
        None => params,
    };
    let mut stages = Stages::new();
    let options = curves::NetworkOptions {
        join_tolerance: params.join_tolerance,
        merge_tolerance: params.merge_tolerance,
        junction_tolerance: params.junction_tolerance,
    };
    let net = stages.run(progress, "curves", || curves::CurveNetwork::build(&curve_mesh, &options))?;
    if net.points.len() > params.max_curve_vertices as usize {
        return Err(Error::TooLarge {
            what: "curve vertices (RBF centres)".into(),
            limit: params.max_curve_vertices as u64,
            actual: net.points.len() as u64,
        });
    }
    // The template's triangles, fanned once: the working copy below starts from them, and the
    // face-growth base, the group transfer and the report measure them.
    let template_tris = crate::shapes::fan_triangles(&template.faces);
    let mut tris = stages.run(progress, "validate", || validated(&template, &template_tris))?;
    let given_diag = Aabb::of(&template.positions).map(|b| b.diagonal()).unwrap_or(0.0);
    let mut pos = template.positions.clone();
    // The template's normals, pushed forward by every map the coarse and fine stages apply: the
    // report's reference for turned faces ([`orientation`]).
    let mut orientation = orientation::Orientation::new(&template.positions, &template_tris);

    let mut coarse = stages.run(progress, "coarse", || {
        coarse_alignment(&mut pos, &tris, &net, params, &mut orientation, progress)
    })?;
    // Crossings and T-junctions the network joined are checked against the aligned template:
    // curves on two pieces, or on two sheets of a self-intersecting template, are not joined (the
    // network is built again).
    let net = stages.run(progress, "curves_on_sheets", || {
        let joined = net.stats.crossings_inserted
            + net.stats.crossings_at_vertices
            + net.stats.t_junctions
            + net.stats.ends_merged;
        if joined == 0 {
            return Ok(net);
        }
        let sheets = sheets::Sheets::new(&pos, &tris);
        let checked =
            curves::CurveNetwork::build_checked(&curve_mesh, &options, &|a, b| sheets.may_join(a, b))?;
        if checked.stats.crossings_on_two_sheets + checked.stats.ends_on_two_sheets == 0 {
            return Ok(net);
        }
        coarse.pair_curve_points = sheets::renumber_points(&net, &checked, &coarse.pair_curve_points);
        Ok(checked)
    })?;
    // Distances from here on (max_curve_distance, end snaps, the relative residual) are measured
    // on the aligned template: an alignment that scales (a template in metres, curves in
    // centimetres) must scale the limits with it, or curves 100× larger are refused as "far"
    // against the template's size before alignment. Except when part of the network is far from
    // the rest (a stray curve): the alignment then stretches the template towards it, and the
    // smaller size keeps the stray curve an error that names it.
    // The limit itself is loose (a sphere fitted to a bunny's sections has ears 0.26 of its
    // diagonal out after alignment), except towards a stray part: there it stays tight, or the
    // approach drags the template onto the stray curve.
    let aligned_diag = Aabb::of(&pos).map(|b| b.diagonal()).unwrap_or(0.0);
    let reach = fine::Reach::new(params, aligned_diag, given_diag, !net.stray_parts().is_empty());
    let template_diag = reach.diag;

    // Vertices added by the fine stage, as weighted combinations of older ones (vertex
    // `template.vertex_count() + i` has `parents[i]`): the template's UVs follow them.
    let mut parents: Vec<[(u32, f64); 3]> = Vec::new();
    let (fine, refined) = stages.run(progress, "fine", || {
        fine::fine_stage(
            &mut pos,
            &mut tris,
            &mut parents,
            &mut orientation,
            &net,
            &coarse,
            params,
            reach,
            progress,
        )
    })?;

    // Folds the fine deformation left (faces turned against the surface before it) are undone by
    // local edge flips and ring-mean moves of non-curve vertices.
    let mut mesh = trimesh::TriMesh::new(fine.positions.clone(), std::mem::take(&mut tris))?;
    // The stages after the fine one stop (too-large, naming the stage) past this many faces.
    let face_base = template_tris.len() + REFINE_FACES_PER_CURVE_VERTEX * net.points.len();
    mesh.set_face_limit((params.max_face_growth * face_base as f64).min(usize::MAX as f64 / 2.0) as usize);
    mesh.check_growth("fine")?;
    let untangle_fine = stages.run(progress, "untangle_fine", || {
        let reference = report::vertex_normals(&pos, &mesh.tris);
        let mut fixed = vec![false; pos.len()];
        for &v in &fine.vertex_of_point {
            fixed[v as usize] = true;
        }
        untangle::untangle_polled(&mut mesh, &reference, &fixed, &untangle::EdgeSet::default(), 8, progress)
    })?;
    let tris = mesh.live_triangles();

    // The template's own face groups, when it has several, are intersected with the regions.
    let labelling = groups::Labelling::new(&template, &template_tris, &tris, &pos, &parents);
    let keep_groups = labelling.keep_groups;
    let fine_positions = mesh.pos.clone();
    let mut reference_normals = report::vertex_normals(&fine_positions, &tris);
    let mut realised = stages.run(progress, "retriangulate", || {
        retriangulate::realise(&mut mesh, &net, &fine.vertex_of_point, params.snap_fraction, progress)
    })?;
    mesh.check_growth("retriangulate")?;
    let fine_parents = parents.len();
    parents.extend_from_slice(&realised.added);
    // Vertices split into crossed edges take the reference normal of their edge.
    for a in &realised.added {
        push_edge_normal(&mut reference_normals, a);
    }
    let mut curve_edges = chain_edges(&realised.chains);
    // Folds made by snapping vertices onto segments and by the re-triangulated strips, against the
    // fine surface; chain vertices stay fixed and curve edges locked.
    let untangle_retri = stages.run(progress, "untangle_retriangulated", || {
        // (Boundary vertices are never moved by the untangling either.) Folds between fixed
        // vertices may get a free vertex on one of their edges.
        untangle::untangle_with_splits(
            &mut mesh,
            &mut reference_normals,
            &realised.on_curve,
            &curve_edges,
            8,
            progress,
        )
    })?;
    mesh.check_growth("untangle_retriangulated")?;
    // Vertices those splits added: after the re-triangulation's in every per-vertex array (the
    // reference normals have them already, the normalised sum of their edge's ends).
    for a in &untangle_retri.added {
        parents.push(*a);
        realised.on_curve.push(false);
    }
    let retri_tris = mesh.live_triangles();
    let angles_retri = report::angle_stats(&mesh.pos, &retri_tris);
    // The unstaged passes over all faces between two stages poll too (each ~10–20 ms on the
    // headline; together they were most of the longest stretches without a poll, session 10).
    progress.check()?;
    let (region0, mut region_count) = stages
        .run(progress, "partition", || partition::regions_polled(&retri_tris, &curve_edges, progress))?;
    // Label of every face id: region × template group, kept by the clean-up.
    let group0 = labelling.groups_of(&retri_tris, mesh.pos.len());
    let mut labels = vec![u64::MAX; mesh.tris.len()];
    for ((f, &r), &g) in mesh.alive_faces().collect::<Vec<_>>().into_iter().zip(&region0).zip(&group0) {
        labels[f as usize] = ((r as u64) << 32) | g as u64;
    }
    // (A sort of the live faces' edges, not a hash lookup per vertex: ~3 % of the headline.)
    progress.check()?;
    let boundary = trimesh::boundary_vertices(mesh.pos.len(), &retri_tris);
    drop(retri_tris);
    let fixed: Vec<bool> = (0..mesh.pos.len()).map(|v| realised.on_curve[v] || boundary[v]).collect();
    let cleaned = stages.run(progress, "cleanup", || {
        if !params.cleanup {
            return Ok(cleanup::CleanupStats::default());
        }
        // The template as given (its own design; a similarity alignment keeps its angles).
        let template_floor = cleanup::template_floor(&template.positions, &template_tris);
        let mut curve_point = vec![false; mesh.pos.len()];
        for &v in &fine.vertex_of_point {
            curve_point[v as usize] = true;
        }
        let mut c = cleanup::Constraints {
            fixed: &fixed,
            locked: curve_edges.clone(),
            chain: cleanup::Constraints::chain_vertices(&realised.chains, &curve_point, &boundary),
            reference: &reference_normals,
            template_floor: &template_floor,
        };
        let s = cleanup::CleanupSettings { min_angle_deg: params.cleanup_min_angle_deg, max_passes: 8 };
        cleanup::clean(&mut mesh, &mut labels, &mut c, &s, progress)
    })?;
    // Vertices the clean-up removed stay in the arrays (faceless) until the output is built.
    let mut realised = realised;
    if !cleaned.removed_vertices.is_empty() {
        // Chain vertices the clean-up removed leave their chains (their neighbours are joined).
        leave_chains(&mut realised.chains, &cleaned.removed_vertices, mesh.pos.len());
        curve_edges = chain_edges(&realised.chains);
    }
    let mut out_tris = mesh.live_triangles();
    let mut region: Vec<u32> = mesh.alive_faces().map(|f| (labels[f as usize] >> 32) as u32).collect();
    // Template groups of the faces the clean-up made: the rule used for re-triangulated faces
    // (the clean-up never edits across a group border, but a face re-triangulation made across
    // one carries a majority label that is not the geometric truth for its pieces).
    let mut tg: Vec<u32> = if keep_groups && cleaned.flips + cleaned.collapses > 0 {
        labelling.groups_of(&out_tris, mesh.pos.len())
    } else {
        mesh.alive_faces().map(|f| labels[f as usize] as u32).collect()
    };
    progress.check()?;
    let angles_before = report::angle_stats(&mesh.pos, &out_tris);
    progress.check()?;
    let flipped_before_smoothing = untangle::count_flipped(&mesh.pos, &out_tris, &reference_normals);
    progress.check()?;
    let folds_before_smoothing = untangle::fold_stats(&mesh.pos, &out_tris);
    progress.check()?;
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
            let mut held = fixed.clone();
            let held_at_creases = if params.smooth_hold_creases_deg > 0.0 {
                let deg = params.smooth_hold_creases_deg;
                smooth::hold_template_creases(&mut held, &template.positions, &template_tris, deg)
            } else {
                0
            };
            let mut s = smooth::smooth(&mut out_pos, &out_tris, &held, &settings, progress)?;
            s.held_at_creases = held_at_creases;
            s.undone_for_flips =
                smooth::undo_new_flips(&mut out_pos, &mesh.pos, &out_tris, &reference_normals);
            Ok(s)
        })?;
    }
    // Smoothed vertices slid over the surface: their UVs are read where they now are.
    let smooth_uv_moves =
        if params.smooth && template.uvs.is_some() { uvs::relocate(&mesh, &out_pos) } else { Vec::new() };
    let smooth_moved: Vec<u32> =
        (0..out_pos.len() as u32).filter(|&v| out_pos[v as usize] != mesh.pos[v as usize]).collect();
    // Smoothing moves free vertices by tangential steps that can fold a face in a tight spot: the
    // same untangling, against the same reference, on the smoothed positions.
    let untangle_smoothed = if params.smooth {
        mesh.pos = out_pos;
        let s = stages.run(progress, "untangle_smoothed", || {
            untangle::untangle_polled(
                &mut mesh,
                &reference_normals,
                &realised.on_curve,
                &curve_edges,
                8,
                progress,
            )
        })?;
        out_pos = mesh.pos.clone();
        if s.edge_flips + s.sequence_flips > 0 {
            // Flipped edges are never curve edges, so regions are unchanged; the labels are
            // recomputed for the new face list.
            out_tris = mesh.live_triangles();
            (region, region_count, tg) =
                labelling.relabel(&out_tris, &curve_edges, out_pos.len(), tg, progress)?;
        }
        Some(s)
    } else {
        None
    };
    // Zero-area faces have no normal, so every fold test above passes them: flipped or collapsed
    // away where possible, counted and named in the report otherwise (`degenerate.after`, `left`).
    mesh.pos.clone_from(&out_pos);
    let degenerate = stages.run(progress, "degenerate", || {
        // Curve points and boundary vertices never move; other chain vertices only along their chain.
        let mut never_moved = boundary.clone();
        for &v in &fine.vertex_of_point {
            never_moved[v as usize] = true;
        }
        Ok(degenerate::remove_zero_area(
            &mut mesh,
            &mut degenerate::Constraints {
                fixed: &never_moved,
                on_chain: &realised.on_curve,
                curve_edges: &mut curve_edges,
            },
        ))
    })?;
    if !degenerate.removed_vertices.is_empty() {
        // A collapsed chain vertex leaves its chain (its neighbours were joined by the collapse).
        leave_chains(&mut realised.chains, &degenerate.removed_vertices, mesh.pos.len());
    }
    if degenerate.flips + degenerate.collapses > 0 {
        out_tris = mesh.live_triangles();
        (region, region_count, tg) =
            labelling.relabel(&out_tris, &curve_edges, out_pos.len(), tg, progress)?;
    }
    // The last repair, on the faces the report's count calls turned and only those (the stages
    // before judge against the surface's vertex normals, which at a sharp crease of small faces
    // follow the large ones: docs/benchmarks.md, flips17): curve vertices and the boundary fixed,
    // curve edges locked; an edit must lower the count where it acts and add no folded edge.
    // Every vertex the fit added takes its parents' maps first.
    orientation.sync(&parents);
    if orientation.len() != mesh.pos.len() {
        return Err(Error::Internal(format!(
            "fit: {} pushed-forward normals for {} vertices (a vertex added without parents)",
            orientation.len(),
            mesh.pos.len()
        )));
    }
    // Faces standing steeply against the count's reference (fins of three consecutive section
    // points, faces on edge after smoothing) are flipped flat first where that adds no folded
    // edge: the last repair cannot turn a fin the count calls turned when the fin across the
    // curve folds against it (session 20).
    let steep_flips = stages.run(progress, "steep_faces", || {
        orientation.cache_faces(&mesh.tris, progress)?;
        untangle::flip_steep(&mut mesh, &orientation, &curve_edges, progress)
    })?;
    let turned = stages.run(progress, "turned_faces", || {
        let mut fixed_now = fixed.clone();
        fixed_now.resize(mesh.pos.len(), true);
        turned::repair_counted(
            &mut mesh,
            &mut orientation,
            &reference_normals,
            &fixed_now,
            &curve_edges,
            progress,
        )
    })?;
    // Vertices its splits added (the orientation has them already): free, after every other in
    // each per-vertex array, their reference normal their edge's ends' sum.
    for a in &turned.added {
        parents.push(*a);
        realised.on_curve.push(false);
        push_edge_normal(&mut reference_normals, a);
    }
    mesh.check_growth("turned_faces")?;
    if turned.vertex_moves + turned.edge_splits > 0 {
        out_pos.clone_from(&mesh.pos);
    }
    // Whatever the pass changed (single flips, flip sequences, splits), the faces are read again
    // when they differ: a test of its counters here missed the sequences until session 20 and
    // dropped their flips from the output.
    let turned_tris = mesh.live_triangles();
    if turned_tris != out_tris {
        // Flipped and split edges are never curve edges: the regions are the same, relabelled for
        // the new face list.
        out_tris = turned_tris;
        (region, region_count, tg) =
            labelling.relabel(&out_tris, &curve_edges, out_pos.len(), tg, progress)?;
    }
    let angles_after = report::angle_stats(&out_pos, &out_tris);

    // Vertices removed by the clean-up leave the output; every per-vertex array is renumbered.
    let removed: Vec<u32> =
        cleaned.removed_vertices.iter().chain(&degenerate.removed_vertices).copied().collect();
    let keep_len = out_pos.len();
    let keep = compact::Renumber::new(keep_len, &removed);
    let out_tris: Vec<[u32; 3]> = out_tris.iter().map(|&t| keep.tri(t)).collect();
    for c in realised.chains.iter_mut() {
        keep.apply(c);
    }
    let mut vertex_of_point = fine.vertex_of_point.clone();
    keep.apply(&mut vertex_of_point);
    let reference_normals = keep.vec(&reference_normals);
    if orientation.len() != keep_len {
        return Err(Error::Internal(format!(
            "fit: {} pushed-forward normals for {keep_len} vertices (a vertex added without parents)",
            orientation.len()
        )));
    }
    let orientation = orientation.renumbered(&keep);
    let fine_positions = keep.vec(&fine_positions);
    let out_pos = keep.vec(&out_pos);

    // Output mesh: one group per region (per region × template group when the template had
    // groups), the curves as vertex chains.
    let (out_tris, faces, group_names) = groups::grouped_faces(
        out_tris,
        &region,
        region_count,
        keep_groups.then_some((tg.as_slice(), &template)),
    );
    let mut out = Mesh::new(out_pos, faces);
    out.uvs = template.uvs.as_ref().map(|uv| {
        // In the order the vertices were made and moved: fine-stage splits, fine untangling,
        // re-triangulation splits and moves, its untangling, smoothing, the last untangling.
        let mut uvs = interpolate_uvs(uv, &parents[..fine_parents]);
        uvs::apply_batches(&mut uvs, &untangle_fine.uv_batches);
        let mut uvs = interpolate_uvs(&uvs, &parents[fine_parents..]);
        uvs::apply(&mut uvs, &realised.uv_moves);
        uvs::apply_batches(&mut uvs, &untangle_retri.uv_batches);
        uvs::apply_batches(&mut uvs, std::slice::from_ref(&smooth_uv_moves));
        if let Some(s) = &untangle_smoothed {
            uvs::apply_batches(&mut uvs, &s.uv_batches);
        }
        uvs::apply_batches(&mut uvs, &turned.uv_batches);
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
            &orientation,
        ))
    })?;
    let folds = untangle::fold_stats(&out.positions, &out_tris);
    let fold_report = serde_json::json!({
        "fold_angle_deg": untangle::FOLD_ANGLE_DEG,
        "output": folds,
        "before_smoothing": folds_before_smoothing,
        "template": untangle::fold_stats(&template.positions, &template_tris),
    });
    // Every vertex moved over the surface (its UV re-read where it landed), in the numbering
    // before the clean-up: re-triangulation snaps, untangling, smoothing.
    let mut moved_vertices: Vec<u32> = realised.uv_moves.iter().map(|m| m.vertex).collect();
    let batches = [Some(&untangle_fine.uv_batches), Some(&untangle_retri.uv_batches)]
        .into_iter()
        .chain([untangle_smoothed.as_ref().map(|s| &s.uv_batches), Some(&turned.uv_batches)]);
    for b in batches.flatten() {
        moved_vertices.extend(b.iter().flatten().map(|m| m.vertex));
    }
    moved_vertices.extend_from_slice(&smooth_moved);
    moved_vertices.sort_unstable();
    moved_vertices.dedup();
    let mut report = serde_json::json!({
        "template_vertices": template.vertex_count() + unreferenced,
        "template_faces": template.face_count(),
        "template_triangles": template_tris.len(),
        "template_unreferenced_vertices_removed": unreferenced,
        "template_groups_kept": if keep_groups { template.groups.len() } else { 0 },
        "output_vertices": out.vertex_count(),
        "output_faces": out.face_count(),
        "curve_vertices": net.points.len(),
        "curve_segments": net.segments.len(),
        "curve_polylines": net.polylines.len(),
        "feature_points": net.feature_count(),
        "curve_vertices_welded": net.welded_vertices,
        "network": net.stats,
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
        "flipped_faces_before_smoothing": flipped_before_smoothing,
        "cleanup": cleaned,
        "moved_vertices": moved_vertices,
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
    // Reference-free: adjacent faces folded back onto each other (untangle::fold_stats). Added
    // after the literal, which is at serde_json's macro recursion limit.
    report["folded_edges"] = folds.folded_edges.into();
    report["flipped_faces_against_fine_surface"] = quality.flipped_faces_against_fine_surface.into();
    // Where the counted faces are (the first few, by centroid): a count alone does not say where to look.
    report["flipped_faces_at"] = serde_json::to_value(&quality.flipped_faces_at).unwrap_or_default();
    report["faces_inverted_by_maps"] = quality.faces_inverted_by_maps.into();
    report["template_vertices_welded"] = welded.into();
    report["template_repeated_corners"] = serde_json::to_value(&repeated_corners).unwrap_or_default();
    report["folds"] = fold_report;
    report["segments_as_edges_realisable"] = quality.segments_as_edges_realisable.into();
    report["segments_not_edges"] = serde_json::to_value(quality.segments_not_edges).unwrap_or_default();
    // The guard's measure: the most faces the mesh had after the fine stage, over its base.
    report["face_growth"] = serde_json::json!({
        "peak_faces": mesh.peak_faces(),
        "base": face_base,
        "ratio": mesh.peak_faces() as f64 / face_base.max(1) as f64,
        "limit": params.max_face_growth,
    });
    report["turned_faces"] = serde_json::to_value(&turned).unwrap_or_default();
    report["steep_faces_flipped"] = steep_flips.into();
    report["refine"] = serde_json::to_value(&refined).unwrap_or_default();
    report["zero_area_faces"] = serde_json::to_value(&degenerate).unwrap_or_default();
    Ok(Output { meshes: vec![out], report, ..Default::default() })
}

/// The template's triangles (`tris`, fanned from its faces), checked: some faces, an oriented
/// manifold (the error names the template's face, not the fanned triangle).
fn validated(template: &Mesh, tris: &[[u32; 3]]) -> Result<Vec<[u32; 3]>> {
    if tris.is_empty() {
        return Err(Error::params("template", "the template has no faces"));
    }
    let face_of: Vec<usize> = (0..template.faces.len())
        .flat_map(|i| std::iter::repeat_n(i, template.faces.arity(i).saturating_sub(2)))
        .collect();
    trimesh::check_oriented_manifold_faces(tris, Some(&face_of))?;
    Ok(tris.to_vec())
}

/// The chain edges of `chains`, each as (smaller, larger) vertex.
fn chain_edges(chains: &[Vec<u32>]) -> untangle::EdgeSet {
    let mut edges = untangle::EdgeSet::default();
    for c in chains {
        for p in c.windows(2) {
            edges.insert((p[0].min(p[1]), p[0].max(p[1])));
        }
    }
    edges
}

/// Takes the `removed` vertices (of `n`) out of the chains they were on: an edit that removed one
/// joined its two chain neighbours.
fn leave_chains(chains: &mut [Vec<u32>], removed: &[u32], n: usize) {
    let mut gone = vec![false; n];
    for &v in removed {
        gone[v as usize] = true;
    }
    for c in chains.iter_mut() {
        c.retain(|&v| !gone[v as usize]);
    }
}

/// Distance helper kept here for the report.
/// Appends the reference normal of a vertex added on an edge: its two ends' normals (`p`'s first
/// two parents) blended by their weights, normalised (the re-triangulation's and the last
/// repair's splits).
fn push_edge_normal(normals: &mut Vec<Point3>, p: &[(u32, f64); 3]) {
    let n = add(scale(normals[p[0].0 as usize], p[0].1), scale(normals[p[1].0 as usize], p[1].1));
    normals.push(crate::geometry::normalize(n));
}

pub(crate) fn point_segment_distance(p: Point3, a: Point3, b: Point3) -> f64 {
    dist(p, crate::geometry::closest_on_segment(p, a, b))
}
