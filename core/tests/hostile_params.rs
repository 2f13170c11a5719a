//! Every job with hostile *parameters* on small valid meshes: indices past the mesh, empty and
//! wrong-length lists, zero/negative/huge numbers, contradictory options. The truth is the
//! contract: `Ok` with meshes that pass `Mesh::check`, or an `Err` that is not an internal error
//! and names the problem; never a panic.

use std::panic::{catch_unwind, AssertUnwindSafe};

use meshwork_core::error::Error;
use meshwork_core::job::{run, JobKind, Progress};
use meshwork_core::mesh::Mesh;
use meshwork_core::shapes::{grid, icosphere};
use serde_json::{json, Value};

/// Runs one job and returns a failure line if it panicked, failed internally, gave an empty
/// message or output a mesh that breaks the invariants.
fn failure(kind: JobKind, inputs: Vec<Mesh>, params: Value) -> Option<String> {
    let what = format!("{} {params}", kind.name());
    let got = catch_unwind(AssertUnwindSafe(|| run(kind, inputs, params.clone(), &Progress::new())));
    if std::env::var("HOSTILE_VERBOSE").is_ok() {
        match &got {
            Ok(Ok(_)) => eprintln!("{what}: Ok"),
            Ok(Err(e)) => eprintln!("{what}: Err {e}"),
            Err(_) => eprintln!("{what}: panic"),
        }
    }
    match got {
        Err(_) => Some(format!("{what}: PANIC")),
        Ok(Err(Error::Internal(m))) => Some(format!("{what}: internal error: {m}")),
        Ok(Err(e)) if e.to_string().trim().is_empty() => Some(format!("{what}: empty error message")),
        Ok(Err(_)) => None,
        Ok(Ok(out)) => {
            out.meshes.iter().find_map(|m| m.check().err()).map(|e| format!("{what}: bad output: {e}"))
        }
    }
}

fn check_all(cases: Vec<(JobKind, Vec<Mesh>, Value)>) {
    let n = cases.len();
    let failures: Vec<String> = cases.into_iter().filter_map(|(k, i, p)| failure(k, i, p)).collect();
    assert!(failures.is_empty(), "{} of {n} runs failed:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn smooth_with_hostile_params_never_panics() {
    let sphere = icosphere(1, 1.0);
    let nv = sphere.positions.len() as u32;
    let sheet = grid(4, 4, 1.0, false);
    let mut cases = Vec::new();
    let methods = ["laplacian", "taubin", "implicit", "mcf", "inflate", "tangential", "fair", "highlight"];
    let hostile = [
        json!({ "pinned": [nv, u32::MAX] }),
        json!({ "region": [nv + 5] }),
        json!({ "region": [0, 0, 0] }),
        json!({ "region_faces": [u32::MAX] }),
        json!({ "weights": [0.5] }),
        json!({ "weights": vec![-1.0; nv as usize] }),
        json!({ "weights": vec![7.0; nv as usize] }),
        json!({ "groups": ["nope"] }),
        json!({ "pinned_groups": ["nope"] }),
        json!({ "axes": "" }),
        json!({ "axes": "w" }),
        json!({ "iterations": 0 }),
        json!({ "lambda": 0.0 }),
        json!({ "lambda": 1e300 }),
        json!({ "lambda": -1e300 }),
        json!({ "time_step": -1.0 }),
        json!({ "time_step": 0.0 }),
        // Found by the CLI fuzz campaign: tangential's steps overflowed to infinite positions, the
        // closest-point query then answered face u32::MAX and the job panicked indexing with it.
        json!({ "time_step": 1e300 }),
        json!({ "cg_tolerance": 0.0 }),
        json!({ "cg_tolerance": -1.0 }),
        json!({ "order": 0 }),
        json!({ "order": 99 }),
        json!({ "mcf_iterations": 0 }),
        json!({ "lambda_border": -5.0 }),
        json!({ "feature_angle": -1.0 }),
        json!({ "feature_angle": 1e9 }),
        json!({ "light_normal": [0.0, 0.0, 0.0] }),
        json!({ "highlight_weight": -1.0 }),
        json!({ "max_step_fraction": 0.0 }),
        json!({ "max_step_fraction": -1.0 }),
        json!({ "region_all": true, "pinned": (0..nv).collect::<Vec<u32>>() }),
    ];
    for m in methods {
        for h in &hostile {
            let mut p = h.clone();
            p["method"] = json!(m);
            // fair and highlight refuse to run without a region: give them one so the hostile
            // value itself is what they meet.
            if m == "fair" && p.get("region").is_none() {
                p["region"] = json!((0..20).collect::<Vec<u32>>());
            }
            if m == "highlight" && p.get("region").is_none() && p.get("region_faces").is_none() {
                p["region_all"] = json!(true);
            }
            cases.push((JobKind::Smooth, vec![sphere.clone()], p.clone()));
            cases.push((JobKind::Smooth, vec![sheet.clone()], p));
        }
    }
    check_all(cases);
}

#[test]
fn repair_and_validate_with_hostile_params_never_panic() {
    let sphere = icosphere(1, 1.0);
    let sheet = grid(4, 4, 1.0, false);
    let mut cases = Vec::new();
    for p in [
        json!({ "weld_tolerance": -1.0 }),
        json!({ "weld_tolerance": 1e300 }),
        json!({ "min_component_faces": u64::MAX }),
        json!({ "max_hole_edges": 0 }),
        json!({ "max_hole_edges": u64::MAX }),
        json!({ "max_hole_area_ratio": -1.0 }),
        json!({ "max_hole_area_ratio": 1e300 }),
        json!({ "dp_max_edges": 0 }),
        json!({ "dp_max_edges": u64::MAX }),
    ] {
        cases.push((JobKind::Repair, vec![sphere.clone()], p.clone()));
        cases.push((JobKind::Repair, vec![sheet.clone()], p));
    }
    for p in [json!({ "max_examples": 0 }), json!({ "max_examples": u64::MAX })] {
        cases.push((JobKind::Validate, vec![sheet.clone()], p));
    }
    check_all(cases);
}

#[test]
fn morph_with_hostile_params_never_panics() {
    let a = icosphere(1, 1.0);
    let b = icosphere(2, 1.0);
    let nv = a.positions.len() as u32;
    let disk = grid(4, 4, 1.0, false);
    let mut cases = Vec::new();
    for p in [
        json!({ "features": [[nv, 0]] }),
        json!({ "features": [[0, u32::MAX]] }),
        json!({ "features": [[0, 0], [0, 0]] }),
        json!({ "features": [[0, 0], [0, 1]] }),
        json!({ "features": [[0, 1], [1, 0]] }),
        json!({ "features": [[]] }),
        json!({ "blend_weights": [1.0, -1.0] }),
        json!({ "blend_weights": [0.0, 1.0] }),
        json!({ "blend_weights": [1.0] }),
        json!({ "max_vertices": 0 }),
        json!({ "working_vertices": 4, "max_flatten_rounds": 0 }),
        json!({ "pseudo_max_depth": 0, "correspondence": "pseudo" }),
        json!({ "pseudo_max_depth": 16, "correspondence": "pseudo" }),
        json!({ "relax_sweeps": 0, "final_relax_sweeps": 0 }),
        json!({ "support_radius": 1e-9, "features": [[0, 3]] }),
        json!({ "domain": "disk" }),
        json!({ "frames": 2, "duration_seconds": 1e-300 }),
        json!({ "frames": 2, "duration_seconds": 1e300 }),
    ] {
        let mut p = p;
        if p.get("frames").is_none() {
            p["frames"] = json!(2);
        }
        cases.push((JobKind::Morph, vec![a.clone(), b.clone()], p.clone()));
        cases.push((JobKind::Morph, vec![disk.clone(), disk.clone()], p));
    }
    check_all(cases);
}

/// Found by this file: a duration too long for the GLB's f32 keyframe times came back as "invalid
/// mesh at vertex 1: value is NaN or infinite" (blaming the mesh), and one too short wrote a GLB
/// whose keyframe times were all 0 (glTF requires them to increase). Both are now refused by name.
#[test]
fn morph_duration_outside_f32_keyframe_range_is_a_params_error() {
    let a = icosphere(1, 1.0);
    for d in [1e300, 1e-300, 1e8, 1e-4] {
        let e = run(
            JobKind::Morph,
            vec![a.clone(), a.clone()],
            json!({ "duration_seconds": d }),
            &Progress::new(),
        )
        .expect_err("refused");
        match e {
            Error::InvalidParams { field, .. } => assert_eq!(field, "duration_seconds", "{d}"),
            other => panic!("{d}: {other}"),
        }
    }
    for d in [1e-3, 1e7] {
        let out = run(
            JobKind::Morph,
            vec![a.clone(), a.clone()],
            json!({ "duration_seconds": d, "frames": 2 }),
            &Progress::new(),
        )
        .expect("accepted");
        assert!(!out.artifacts.is_empty() || !out.meshes.is_empty());
    }
}

/// Found by the CLI fuzz campaign: valid meshes with parameters that make the implicit system
/// singular came back as `numerical-failure` (CLI exit 1, "our fault"): mean curvature flow that
/// collapses the mesh it re-assembles on (an icosahedron with the default 5 steps, homer with
/// `iterations` 50), `implicit` with `time_step` 1e20, `inflate` with `lambda` 1e308. Each is now
/// an invalid-params error naming the parameter to change.
#[test]
fn parameters_that_make_the_implicit_system_singular_are_named() {
    let field_of = |mesh: Mesh, params: Value| match run(
        JobKind::Smooth,
        vec![mesh],
        params.clone(),
        &Progress::new(),
    ) {
        Err(Error::InvalidParams { field, message }) => (field, message),
        Err(e) => panic!("{params}: expected invalid-params, got {}: {e}", e.kind()),
        Ok(_) => panic!("{params}: expected an error"),
    };
    let (field, msg) = field_of(icosphere(0, 1.0), json!({ "method": "mcf" }));
    assert_eq!(field, "iterations");
    assert!(msg.contains("collapsed") && msg.contains("of 5") && msg.contains("time_step"), "{msg}");
    let (field, msg) = field_of(icosphere(2, 1.0), json!({ "method": "implicit", "time_step": 1e20 }));
    assert_eq!(field, "time_step");
    assert!(msg.contains("1e20"), "{msg}");
    let (field, _) = field_of(
        icosphere(2, 1.0),
        json!({ "method": "implicit", "time_step": 1e20, "relative_time_step": false }),
    );
    assert_eq!(field, "time_step");
    let (field, _) = field_of(icosphere(2, 1.0), json!({ "method": "inflate", "lambda": 1e308 }));
    assert_eq!(field, "lambda");
    // The bound itself is accepted, and an mcf that stops before the collapse still runs.
    for p in [
        json!({ "method": "implicit", "time_step": 1e12 }),
        json!({ "method": "mcf", "iterations": 1 }),
        json!({ "method": "inflate", "lambda": -1.0 }),
    ] {
        let out = run(JobKind::Smooth, vec![icosphere(2, 1.0)], p.clone(), &Progress::new());
        assert!(out.is_ok(), "{p}: {:?}", out.err());
    }
}

/// Found by the CLI fuzz campaign: `smooth --method inflate --iterations 10000` on suzanne grew
/// the mesh geometrically to NaN positions and returned them; the writer then refused the output
/// as "invalid mesh at vertex 0: coordinate is NaN or infinite", blaming the input. The job now
/// stops at the step that leaves ±1e150 and names `iterations`.
#[test]
fn inflation_that_diverges_names_iterations() {
    let got = run(
        JobKind::Smooth,
        vec![icosphere(2, 1.0)],
        json!({ "method": "inflate", "iterations": 10000 }),
        &Progress::new(),
    );
    match got {
        Err(Error::InvalidParams { field, message }) => {
            assert_eq!(field, "iterations");
            assert!(message.contains("diverged") && message.contains("of 10000"), "{message}");
        }
        Err(e) => panic!("expected invalid-params, got {}: {e}", e.kind()),
        Ok(out) => panic!("expected an error; output check: {:?}", out.meshes[0].check()),
    }
    // The few steps the method is meant for still run.
    let out = run(
        JobKind::Smooth,
        vec![icosphere(2, 1.0)],
        json!({ "method": "inflate", "iterations": 3 }),
        &Progress::new(),
    )
    .expect("3 inflation steps");
    assert!(out.meshes[0].check().is_ok());
}

/// Found by the CLI fuzz campaign: `smooth woody.obj --method highlight --region-all
/// --light-spacing 1e-300` ran for more than 40 s: the highlight levels of an edge (distance /
/// spacing, near 1e300) saturated to i64::MIN..i64::MAX, the count `hi - lo` overflowed past the
/// per-edge cap, and the node loop never ended. Edges whose levels are beyond exact integers are
/// now skipped like edges with too many nodes, so the job answers at once.
#[test]
fn highlight_with_a_vanishing_light_spacing_answers() {
    let (cap, _) = meshwork_core::shapes::icosphere_without_cap(3, 60.0);
    for spacing in [1e-300, 1e-200, 1e-20] {
        let p = json!({ "method": "highlight", "region_all": true, "light_spacing": spacing });
        assert_eq!(failure(JobKind::Smooth, vec![cap.clone()], p), None);
    }
}
