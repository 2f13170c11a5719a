//! Every job stops at a cancel, wherever it comes: cancelled at its k-th poll of
//! `Progress::check` (k spread over the whole run, first and last included) each job returns
//! `Error::Cancelled`, never a result or another error. And the report stages that used to run
//! on after a cancel (smooth `metrics`, repair `validate_output`, morph `report`) poll inside
//! themselves, not only on entry, so a cancel takes effect within one poll's work. Counting polls
//! instead of timing keeps this deterministic; the latencies in release are measured by
//! `core/examples/cancel_latency.rs` (docs/benchmarks.md → Cancellation).

use std::sync::{Arc, Mutex};

use meshwork_core::fit::testdata::ellipsoid_sections;
use meshwork_core::job::{self, JobKind};
use meshwork_core::mesh::Mesh;
use meshwork_core::shapes::{icosphere, triangle_grid};
use meshwork_core::{Error, Progress};
use serde_json::{json, Value};

/// Runs the job to completion; returns the total number of polls and, per stage in run order,
/// the polls made inside it after its entry check.
fn polls(kind: JobKind, inputs: &[Mesh], params: &Value) -> (u64, Vec<(String, u64)>) {
    let (total, per_stage, _) = polls_and_report(kind, inputs, params);
    (total, per_stage)
}

/// [`polls`] and the job's report.
fn polls_and_report(kind: JobKind, inputs: &[Mesh], params: &Value) -> (u64, Vec<(String, u64)>, Value) {
    let p = Progress::new();
    let marks: Arc<Mutex<Vec<(String, u64)>>> = Arc::default();
    {
        let (marks, q) = (marks.clone(), p.clone());
        p.set_listener(move |stage, _| {
            let mut m = marks.lock().unwrap();
            if m.last().map(|l| l.0.as_str()) != Some(stage) {
                m.push((stage.to_string(), q.checks()));
            }
        });
    }
    let out = job::run(kind, inputs.to_vec(), params.clone(), &p)
        .unwrap_or_else(|e| panic!("{kind:?} {params}: {e}"));
    let total = p.checks();
    let marks = marks.lock().unwrap().clone();
    let mut per_stage = Vec::new();
    for (i, (name, start)) in marks.iter().enumerate() {
        let end = marks.get(i + 1).map_or(total, |m| m.1);
        per_stage.push((name.clone(), end - start - 1));
    }
    (total, per_stage, out.report)
}

/// Cancels the job at up to 12 polls spread over its run (the first and the last included) and
/// asserts each run returns `Cancelled`.
fn cancels_everywhere(what: &str, kind: JobKind, inputs: &[Mesh], params: Value) {
    let (total, _) = polls(kind, inputs, &params);
    assert!(total >= 1, "{what}: no poll");
    let mut ks: Vec<u64> = (0..12).map(|i| 1 + i * (total - 1) / 11).collect();
    ks.dedup();
    for k in ks {
        let p = Progress::new();
        p.cancel_at_check(k);
        match job::run(kind, inputs.to_vec(), params.clone(), &p) {
            Err(Error::Cancelled) => {}
            Err(e) => panic!("{what}: cancelled at poll {k} of {total}, got the error {e}"),
            Ok(_) => panic!("{what}: cancelled at poll {k} of {total}, but it returned a result"),
        }
    }
}

/// Inner polls of `stage` (panics when the stage did not run).
fn stage_polls(per_stage: &[(String, u64)], stage: &str) -> u64 {
    per_stage.iter().find(|s| s.0 == stage).unwrap_or_else(|| panic!("no stage {stage} in {per_stage:?}")).1
}

/// Each face with its own three vertices (a soup: the repair welds it), with two faces dropped
/// (two holes to fill).
fn soup_with_holes(m: &Mesh) -> Mesh {
    let tris = meshwork_core::shapes::fan_triangles(&m.faces);
    let mut pos = Vec::new();
    let mut out = Vec::new();
    for (i, t) in tris.iter().enumerate() {
        if i == 7 || i == tris.len() / 2 {
            continue;
        }
        let b = pos.len() as u32;
        pos.extend(t.iter().map(|&v| m.positions[v as usize]));
        out.push([b, b + 1, b + 2]);
    }
    Mesh::from_triangles(pos, &out)
}

/// A grid with a bump: a surface with highlight lines to fair.
fn bumped_grid() -> Mesh {
    let mut m = triangle_grid(24, 24, 1.0 / 24.0);
    for p in m.positions.iter_mut() {
        let r2 = (p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2);
        p[2] = 0.05 * (-r2 / 0.04).exp();
    }
    m
}

#[test]
fn every_job_returns_cancelled_wherever_it_is_cancelled() {
    let sphere = icosphere(3, 1.0);
    cancels_everywhere("validate", JobKind::Validate, &[sphere.clone()], json!({}));
    cancels_everywhere("convert", JobKind::Convert, &[sphere.clone()], json!({}));
    cancels_everywhere("repair", JobKind::Repair, &[soup_with_holes(&sphere)], json!({}));
    for m in ["laplacian", "taubin", "implicit", "mcf", "inflate", "tangential"] {
        let params = json!({ "method": m, "iterations": 3 });
        cancels_everywhere(&format!("smooth {m}"), JobKind::Smooth, &[sphere.clone()], params);
    }
    let cap: Vec<u32> =
        (0..sphere.vertex_count() as u32).filter(|&v| sphere.positions[v as usize][2] > 0.3).collect();
    cancels_everywhere(
        "smooth fair",
        JobKind::Smooth,
        &[sphere.clone()],
        json!({"method": "fair", "region": cap}),
    );
    cancels_everywhere(
        "smooth highlight",
        JobKind::Smooth,
        &[bumped_grid()],
        json!({"method": "highlight", "region_all": true, "iterations": 2, "light_normal": [0, 0, 1],
               "light_direction": [1, 0, 0], "light_origin": [0, 0, 3], "light_spacing": 0.1}),
    );
    let curves = ellipsoid_sections([1.4, 1.15, 0.9], 4);
    cancels_everywhere("fit", JobKind::Fit, &[icosphere(2, 1.0), curves], json!({}));
    cancels_everywhere(
        "morph",
        JobKind::Morph,
        &[icosphere(1, 1.0), icosphere(2, 1.0)],
        json!({"frames": 2}),
    );
}

/// The stages that ran on after a cancel (130–700 ms on 100k vertices) now poll inside: a
/// 20k-triangle smooth `metrics` (measures, BVH builds, Hausdorff queries in chunks of 4096
/// points), each pass of repair's output validation, the morph's Hausdorff per input.
#[test]
fn report_stages_poll_inside() {
    let big = icosphere(5, 1.0); // 10,242 vertices, 20,480 triangles
    let (_, s) = polls(JobKind::Smooth, &[big.clone()], &json!({"method": "laplacian", "iterations": 1}));
    // compare: 20480 / 8192 → 3; Hausdorff: 3 chunks per side, 2 BVH builds of ~7 polls each.
    assert!(stage_polls(&s, "metrics") >= 10, "{s:?}");
    let (_, s) = polls(JobKind::Repair, &[soup_with_holes(&big)], &json!({}));
    // Seven passes (geometry, topology, faces, vertices, edges, components, boundary loops).
    assert!(stage_polls(&s, "validate_output") >= 7, "{s:?}");
    assert!(stage_polls(&s, "validate_input") >= 7, "{s:?}");
    // outward: after the topology, after the components, then per 65,536 edges and faces.
    assert!(stage_polls(&s, "outward") >= 4, "{s:?}");
    let (_, s) = polls(JobKind::Morph, &[icosphere(2, 1.0), icosphere(3, 1.0)], &json!({"frames": 2}));
    // Per input: the metamesh's vertices and the input's vertices and centroids, in chunks.
    assert!(stage_polls(&s, "report") >= 4, "{s:?}");
}

/// The two longest stretches without a poll left after the report stages (cancel_latency,
/// docs/benchmarks.md): validate's duplicate-face search (one sort of all faces, 136 ms on 280k
/// faces) and highlight fairing's QP step (CG polled every 256 iterations, the Hessian's triplets
/// sorted in one call, 300 ms at 30k unknowns). Both now poll in proportion to their work.
#[test]
fn long_passes_poll_in_proportion_to_their_work() {
    // validate `faces`: a scan poll every 65,536 faces and a duplicate-search poll every 32,768.
    let big = icosphere(6, 1.0); // 81,920 triangles
    let (_, s) = polls(JobKind::Validate, &[big], &json!({}));
    assert!(stage_polls(&s, "faces") >= 2 + 3, "{s:?}");
    // The topology build (3 between passes + one per 32,768 of the 40,962 vertices) and the vertex
    // kinds (one per 32,768 of the 122,880 edges and of the vertices).
    assert!(stage_polls(&s, "topology") >= 3 + 2, "{s:?}");
    assert!(stage_polls(&s, "vertices") >= 4 + 2, "{s:?}");

    // highlight `fair`: at least one poll per CG iteration and per outer QP iteration.
    let params = json!({"method": "highlight", "region_all": true, "iterations": 3, "light_normal": [0, 0, 1],
                        "light_direction": [1, 0, 0], "light_origin": [0, 0, 3], "light_spacing": 0.1});
    let (_, s, report) = polls_and_report(JobKind::Smooth, &[bumped_grid()], &params);
    let history = report["history"].as_array().unwrap_or_else(|| panic!("no history in {report}"));
    let work: u64 = history
        .iter()
        .map(|h| h["qp"]["cg_iterations"].as_u64().unwrap() + h["qp"]["outer_iterations"].as_u64().unwrap())
        .sum();
    assert!(work > 16, "too small a problem to tell: {work} QP iterations");
    let fair_polls = stage_polls(&s, "fair");
    assert!(fair_polls >= work, "fair polled {fair_polls} times for {work} CG + outer QP iterations");
}

/// The fit's `partition` (a flood fill over the re-triangulated faces, 200–290 ms of CPU without a
/// poll on the 200k faces of `cancel_latency` in session 9) reports its fraction every 4,096 faces
/// of its fill: on a 5,120-face template cut into octants (~7,000 faces after the re-triangulation)
/// at least 2 polls. The code before session 10 made none inside the stage. (Session 11: the
/// edge → faces map pass, polled too then, became vertex → faces lists that take a few ms.)
#[test]
fn the_fit_partition_polls_inside() {
    let curves = ellipsoid_sections([1.4, 1.15, 0.9], 6);
    let (_, s) = polls(JobKind::Fit, &[icosphere(4, 1.0), curves], &json!({}));
    assert!(stage_polls(&s, "partition") >= 2, "{s:?}");
}
