//! The smooth job end to end (through `job::run`, as the CLI and the service call it), checked
//! against analytic truths: sphere radii under mean-curvature flow, planes, volumes, fixed vertices.

use meshwork_core::geometry::{norm, signed_volume};
use meshwork_core::job::{run, JobKind, Output, Progress};
use meshwork_core::mesh::{Faces, Mesh};
use meshwork_core::shapes::{grid, icosphere, torus};
use serde_json::{json, Value};

fn smooth(mesh: &Mesh, params: Value) -> Output {
    run(JobKind::Smooth, vec![mesh.clone()], params, &Progress::new()).unwrap()
}

fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    }
}

fn radii(m: &Mesh) -> (f64, f64) {
    let r: Vec<f64> = m.positions.iter().map(|p| norm(*p)).collect();
    let mean = r.iter().sum::<f64>() / r.len() as f64;
    let sd = (r.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / r.len() as f64).sqrt();
    (mean, sd)
}

fn noisy_sphere(levels: u32, amp: f64) -> Mesh {
    let mut m = icosphere(levels, 1.0);
    let mut r = rng(11);
    for p in &mut m.positions {
        let f = 1.0 + amp * r();
        *p = [p[0] * f, p[1] * f, p[2] * f];
    }
    m
}

#[test]
fn sphere_shrinks_under_mcf_at_the_predicted_rate() {
    // Continuous MCF: dR/dt = −2/R. Backward Euler with step h: R₊ = (R + √(R² − 8h))/2.
    let m = icosphere(4, 1.0);
    let h = 0.01;
    let out =
        smooth(&m, json!({"method": "mcf", "iterations": 5, "time_step": h, "relative_time_step": false}));
    let mut r = radii(&m).0;
    for _ in 0..5 {
        r = (r + (r * r - 8.0 * h).sqrt()) / 2.0;
    }
    let (mean, sd) = radii(&out.meshes[0]);
    assert!((mean - r).abs() < 0.01 * r, "radius {mean}, predicted {r}");
    assert!(sd < 1e-3 * mean, "no longer a sphere: sd {sd}");
    assert!(out.report["solver"]["factorizations"].as_u64().unwrap() == 5);
}

#[test]
fn noisy_sphere_gets_smoother_with_every_method() {
    let m = noisy_sphere(3, 0.04);
    let sd0 = radii(&m).1;
    for p in [
        json!({"method": "laplacian"}),
        json!({"method": "taubin"}),
        json!({"method": "implicit"}),
        json!({"method": "mcf", "iterations": 2, "time_step": 0.5}),
        json!({"method": "inflate", "lambda": 2.0}),
    ] {
        let out = smooth(&m, p.clone());
        let sd = radii(&out.meshes[0]).1;
        assert!(sd < 0.5 * sd0, "{p}: sd {sd} vs {sd0}");
        assert_eq!(out.report["flipped_faces"], 0, "{p}");
    }
}

#[test]
fn plane_stays_flat() {
    let mut m = grid(12, 12, 0.1, false);
    let mut r = rng(3);
    for p in &mut m.positions {
        p[0] += 0.03 * r();
        p[1] += 0.03 * r();
    }
    for method in ["laplacian", "taubin", "implicit", "mcf", "inflate", "tangential"] {
        let out = smooth(&m, json!({"method": method, "boundary": "free"}));
        let zmax = out.meshes[0].positions.iter().map(|p| p[2].abs()).fold(0.0, f64::max);
        assert!(zmax < 1e-12, "{method}: z up to {zmax}");
    }
}

#[test]
fn implicit_with_volume_preservation_keeps_volume_to_1e9() {
    let m = noisy_sphere(3, 0.05);
    let v0 = signed_volume(&m.positions, &m.faces);
    let out =
        smooth(&m, json!({"method": "implicit", "time_step": 5.0, "iterations": 3, "preserve_volume": true}));
    let v1 = signed_volume(&out.meshes[0].positions, &m.faces);
    assert!(((v1 - v0) / v0).abs() < 1e-9, "{}", (v1 - v0) / v0);
    // Without preservation the same flow loses volume (the test can fail).
    let out = smooth(&m, json!({"method": "implicit", "time_step": 5.0, "iterations": 3}));
    assert!(out.report["volume_change"].as_f64().unwrap() < -1e-3);
    // With pinned vertices the rescale factor is solved for (only free vertices scale).
    let pinned: Vec<u32> = (0..50).collect();
    let out = smooth(
        &m,
        json!({"method": "implicit", "time_step": 5.0, "preserve_volume": true, "pinned": pinned}),
    );
    let v2 = signed_volume(&out.meshes[0].positions, &m.faces);
    assert!(((v2 - v0) / v0).abs() < 1e-9, "{}", (v2 - v0) / v0);
    for i in 0..50 {
        assert_eq!(out.meshes[0].positions[i], m.positions[i]);
    }
}

#[test]
fn pinned_weights_axes_and_fixed_boundary_are_bit_exact() {
    let mut m = grid(10, 10, 1.0, true);
    let mut r = rng(5);
    for p in &mut m.positions {
        p[2] += 0.2 * r();
        p[0] += 0.1 * r();
    }
    let n = m.vertex_count();
    let mut weights = vec![1.0; n];
    weights[60] = 0.0;
    for method in ["laplacian", "taubin", "implicit", "mcf", "inflate", "tangential"] {
        let out = smooth(
            &m,
            json!({"method": method, "pinned": [40, 41], "weights": weights, "preserve_volume": method != "mcf"}),
        );
        let x = &out.meshes[0].positions;
        for i in [40, 41, 60] {
            assert_eq!(x[i], m.positions[i], "{method}: vertex {i}");
        }
        for i in 0..=10 {
            assert_eq!(x[i], m.positions[i], "{method}: boundary vertex {i}"); // bottom row
        }
        assert!(x[45] != m.positions[45], "{method}: interior did not move");
        let out = smooth(&m, json!({"method": method, "axes": "z"}));
        for (a, b) in out.meshes[0].positions.iter().zip(&m.positions) {
            assert_eq!((a[0], a[1]), (b[0], b[1]), "{method}");
        }
    }
}

#[test]
fn curve_boundary_smooths_a_noisy_edge_and_keeps_a_straight_one() {
    // The 1-D operator with inverse-length weights (eq. 4-3) moves a boundary vertex only where the
    // boundary curves: collinear vertices stay exactly where they are, whatever their spacing.
    // Corners are pinned (a free corner is rounded off, as any curve smoothing does).
    let mut m = grid(8, 4, 1.0, true);
    let corners = [0, 8, 36, 44];
    let mut r = rng(9);
    for i in 1..8 {
        m.positions[i][0] += if i % 2 == 0 { 0.3 } else { -0.3 }; // uneven spacing on y = 0
        m.positions[36 + i][1] += 0.2 * r(); // noisy top edge
    }
    let noise0 = (1..8).map(|i| (m.positions[36 + i][1] - 4.0).abs()).fold(0.0, f64::max);
    for p in [
        json!({"method": "laplacian", "boundary": "curve", "iterations": 20, "pinned": corners}),
        json!({"method": "implicit", "boundary": "curve", "time_step": 2.0, "iterations": 5, "pinned": corners}),
    ] {
        let out = smooth(&m, p.clone());
        let x = &out.meshes[0].positions;
        for i in 0..=8 {
            assert!((x[i][0] - m.positions[i][0]).abs() < 1e-12 && x[i][1].abs() < 1e-12, "{p}: {:?}", x[i]);
        }
        let noise = (1..8).map(|i| (x[36 + i][1] - 4.0).abs()).fold(0.0, f64::max);
        assert!(noise < 0.5 * noise0, "{p}: {noise} vs {noise0}");
    }
    // With the default (fixed) boundary the noisy edge is untouched.
    let out = smooth(&m, json!({"method": "laplacian", "iterations": 20}));
    assert_eq!(out.meshes[0].positions[36..45], m.positions[36..45]);
}

/// The shared Stanford bunny (`../shared/meshes`, or `MESHWORK_MESHES`). It is not part of the
/// repository; on a machine without it the bunny tests say so and pass vacuously (the same
/// properties are also tested on analytic shapes above).
fn bunny() -> Option<Mesh> {
    let dir = std::env::var_os("MESHWORK_MESHES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes"));
    match std::fs::read(dir.join("stanford-bunny.obj")) {
        Ok(b) => Some(meshwork_core::io::read(&b, &Default::default()).unwrap().mesh),
        Err(e) => {
            eprintln!("SKIP stanford-bunny.obj: {e}");
            None
        }
    }
}

#[test]
fn inflation_increases_mean_curvature() {
    // Seed 004 §3.4.2: λ < 0 exaggerates the shape (its curvature); volume kept so that the
    // comparison is at the same scale.
    let Some(m) = bunny() else { return };
    let out = smooth(&m, json!({"method": "inflate", "lambda": -2.0, "preserve_volume": true}));
    let (h0, h1) = (
        out.report["mean_curvature_before"].as_f64().unwrap(),
        out.report["mean_curvature_after"].as_f64().unwrap(),
    );
    assert!(h1 > 1.05 * h0, "{h0} → {h1}");
    assert!(out.report["volume_change"].as_f64().unwrap().abs() < 1e-9);
    // The same λ with the other sign smooths: curvature decreases.
    let out = smooth(&m, json!({"method": "inflate", "lambda": 2.0, "preserve_volume": true}));
    assert!(out.report["mean_curvature_after"].as_f64().unwrap() < 0.95 * h0);
}

#[test]
fn taubin_keeps_the_bunny_volume_within_one_percent() {
    let Some(m) = bunny() else { return };
    let out = smooth(&m, json!({"method": "taubin", "iterations": 10, "report_curvature": true}));
    let dv = out.report["volume_change"].as_f64().unwrap();
    assert!(dv.abs() < 0.01, "{dv}");
    let h = |k: &str| out.report[k].as_f64().expect("curvature was asked for");
    assert!(h("mean_curvature_after") < h("mean_curvature_before"));
    // Not asked for (the default outside `inflate`): reported as null, the rest unchanged.
    let lean = smooth(&m, json!({"method": "taubin", "iterations": 10}));
    assert!(lean.report["mean_curvature_after"].is_null());
    assert_eq!(lean.report["volume_change"], out.report["volume_change"]);
    // Plain Laplacian flow with the same λ and number of steps shrinks it more than Taubin does.
    let lap = smooth(&m, json!({"method": "laplacian", "iterations": 20}));
    assert!(lap.report["volume_change"].as_f64().unwrap() < -dv.abs());
}

#[test]
fn a_bunny_scaled_by_1e_minus_3_smooths_exactly_like_the_original() {
    // Blender 3.4's modifier locks every vertex next to a face below 1e-5 area: at this scale
    // that is every vertex, and nothing moves. Our thresholds are relative to the mesh.
    let Some(m) = bunny() else { return };
    let mut small = m.clone();
    for p in &mut small.positions {
        *p = [p[0] * 1e-3, p[1] * 1e-3, p[2] * 1e-3];
    }
    for p in [
        json!({"method": "implicit"}),
        json!({"method": "implicit", "operator": "tqlbo_normalized"}),
        json!({"method": "taubin", "operator": "cotan"}),
    ] {
        let a = smooth(&m, p.clone());
        let b = smooth(&small, p.clone());
        // Only the 1,113 vertices no face uses are locked, at both scales.
        let unused =
            m.vertex_count() - m.faces.indices().iter().collect::<std::collections::HashSet<_>>().len();
        assert_eq!(b.report["locked_vertices"], unused);
        assert_eq!(a.report["locked_vertices"], unused);
        let moved = a.report["mean_displacement"].as_f64().unwrap();
        assert!(moved > 1e-4 * a.report["mean_edge_length"].as_f64().unwrap(), "{p}: nothing moved");
        let worst = a.meshes[0]
            .positions
            .iter()
            .zip(&b.meshes[0].positions)
            .map(|(p, q)| norm(sub(*p, [q[0] * 1e3, q[1] * 1e3, q[2] * 1e3])))
            .fold(0.0, f64::max);
        assert!(worst < 1e-9 * moved.max(1e-30) * 1e3, "{p}: {worst} vs displacement {moved}");
    }
}

#[test]
fn random_quad_to_triangle_conversion_gives_nearly_the_same_result() {
    // Seed 004 Fig. 3-7: all-quad, all-triangle and randomly mixed versions smooth alike.
    let quads = torus(48, 24, 2.0, 0.7, true);
    let mut r = rng(17);
    let mut noisy = quads.clone();
    for p in &mut noisy.positions {
        for c in p.iter_mut() {
            *c += 0.02 * r();
        }
    }
    let mut mixed = noisy.clone();
    let mut f = Faces::new();
    for q in noisy.faces.iter() {
        match (r() * 3.0 + 1.5) as i32 {
            0 | 1 => f.push(q, 0),
            2 => {
                f.push(&[q[0], q[1], q[2]], 0);
                f.push(&[q[0], q[2], q[3]], 0);
            }
            _ => {
                f.push(&[q[0], q[1], q[3]], 0);
                f.push(&[q[1], q[2], q[3]], 0);
            }
        }
    }
    mixed.faces = f;
    let p = json!({"method": "implicit", "operator": "tqlbo_normalized", "time_step": 2.0, "iterations": 2});
    let a = smooth(&noisy, p.clone());
    let b = smooth(&mixed, p);
    let (xa, xb) = (&a.meshes[0].positions, &b.meshes[0].positions);
    let moved: f64 =
        xa.iter().zip(&noisy.positions).map(|(p, q)| norm(sub(*p, *q))).sum::<f64>() / xa.len() as f64;
    let diff: f64 = xa.iter().zip(xb).map(|(p, q)| norm(sub(*p, *q))).sum::<f64>() / xa.len() as f64;
    assert!(diff < 0.25 * moved, "difference {diff} vs displacement {moved}");
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[test]
fn fairing_a_bump_in_a_plane_restores_the_plane() {
    // Biharmonic/harmonic functions on a planar mesh with planar boundary data are planar
    // (the operators reproduce linear functions), so the faired region must be flat again.
    let mut m = grid(16, 16, 0.25, false);
    let mut region = Vec::new();
    for j in 5..=11 {
        for i in 5..=11 {
            let v = j * 17 + i;
            m.positions[v][2] = 0.3 * (1.0 - ((i as f64 - 8.0).abs() + (j as f64 - 8.0).abs()) / 8.0);
            region.push(v as u32);
        }
    }
    for order in [1, 2, 3] {
        let out = smooth(&m, json!({"method": "fair", "region": region, "order": order}));
        let z = out.meshes[0].positions.iter().map(|p| p[2].abs()).fold(0.0, f64::max);
        assert!(z < 1e-10, "order {order}: {z}");
    }
    let e = run(JobKind::Smooth, vec![m], json!({"method": "fair"}), &Progress::new()).unwrap_err();
    assert!(e.to_string().contains("region"), "{e}");
}

#[test]
fn tangential_flow_improves_triangles_and_stays_on_the_surface() {
    let m0 = icosphere(3, 1.0);
    let mut m = m0.clone();
    // Slide vertices within the surface: random tangential jitter, then back on the sphere.
    let mut r = rng(23);
    for p in &mut m.positions {
        let q = [p[0] + 0.03 * r(), p[1] + 0.03 * r(), p[2] + 0.03 * r()];
        let l = norm(q);
        *p = [q[0] / l, q[1] / l, q[2] / l];
    }
    let out = smooth(&m, json!({"method": "tangential", "iterations": 20, "mcf_iterations": 3}));
    let rep = &out.report;
    assert!(
        rep["mean_min_angle_after"].as_f64().unwrap() > rep["mean_min_angle_before"].as_f64().unwrap() + 1.0,
        "{rep}"
    );
    // Every vertex stays on the input surface (an inscribed polyhedron of the unit sphere).
    for p in &out.meshes[0].positions {
        let l = norm(*p);
        assert!(l <= 1.0 + 1e-12 && l > 0.985, "{l}");
    }
    assert!(rep["hausdorff"].as_f64().unwrap() < 0.015);
}

#[test]
fn solvers_agree() {
    let m = noisy_sphere(4, 0.03);
    let a =
        smooth(&m, json!({"method": "implicit", "solver": "cholesky", "time_step": 3.0, "iterations": 2}));
    let b = smooth(
        &m,
        json!({"method": "implicit", "solver": "cg", "time_step": 3.0, "iterations": 2, "cg_tolerance": 1e-12}),
    );
    assert_eq!(a.report["solver"]["kind"], "cholesky");
    assert_eq!(b.report["solver"]["kind"], "cg");
    assert!(a.report["solver"]["factor_nnz"].as_u64().unwrap() > 0);
    for (p, q) in a.meshes[0].positions.iter().zip(&b.meshes[0].positions) {
        assert!(norm(sub(*p, *q)) < 1e-8);
    }
}

#[test]
fn bad_params_are_named() {
    let m = grid(3, 3, 1.0, true);
    for (p, field) in [
        (json!({"bogus": 1}), "bogus"),
        (json!({"pinned": [99]}), "pinned"),
        (json!({"weights": [1.0]}), "weights"),
        (json!({"lambda": 3.0}), "lambda"),
        (json!({"axes": "w"}), "axes"),
        (json!({"groups": ["nope"]}), "groups"),
        (json!({"method": "mcf", "operator": "uniform"}), "operator"),
    ] {
        match run(JobKind::Smooth, vec![m.clone()], p.clone(), &Progress::new()) {
            Err(meshwork_core::Error::InvalidParams { field: f, .. }) => assert_eq!(f, field, "{p}"),
            other => panic!("{p}: {other:?}"),
        }
    }
}

#[test]
fn report_has_the_named_keys() {
    let out = smooth(&noisy_sphere(2, 0.02), json!({"method": "implicit"}));
    for k in [
        "total_ms",
        "stages",
        "volume_change",
        "area_change",
        "max_displacement",
        "mean_displacement",
        "hausdorff",
        "min_angle_before",
        "min_angle_after",
        "mean_min_angle_before",
        "mean_min_angle_after",
        "flipped_faces",
        "solver",
    ] {
        assert!(out.report.get(k).is_some(), "missing {k}");
    }
    assert!(out.report["stages"]["assemble"].as_f64().is_some());
    assert!(out.report["solver"]["factor_nnz"].as_u64().unwrap() > 0);
}

#[test]
fn cancellation_stops_the_job() {
    let p = Progress::new();
    p.cancel();
    let r = run(JobKind::Smooth, vec![icosphere(2, 1.0)], json!({}), &p);
    assert!(matches!(r, Err(meshwork_core::Error::Cancelled)));
}
