//! Bad fit inputs give clear errors naming the problem.

use meshwork_core::fit::testdata::ellipsoid_sections;
use meshwork_core::fit::{run, Alignment, FitPair, FitParams};
use meshwork_core::job::{self, JobKind};
use meshwork_core::mesh::{Faces, Mesh};
use meshwork_core::shapes::icosphere;
use meshwork_core::{Error, Progress};

const AXES: [f64; 3] = [1.4, 1.15, 0.9];

fn params_err(e: Error) -> (String, String) {
    match e {
        Error::InvalidParams { field, message } => (field, message),
        other => panic!("expected invalid-params, got {other}"),
    }
}

/// Runs the fit, keeping only the error (an `Output` is too big to print in a failed assertion).
fn fit(template: Mesh, curves: Mesh, p: &FitParams) -> Result<(), Error> {
    run(vec![template, curves], p, &Progress::new()).map(|o| eprintln!("unexpected success: {}", o.report))
}

fn none() -> FitParams {
    FitParams { alignment: Alignment::None, ..Default::default() }
}

#[test]
fn curves_far_from_the_template_name_the_curve() {
    let mut c = ellipsoid_sections(AXES, 4);
    // Only the third curve (the z-x ellipse) is moved far away; its points not shared with the
    // others are then far from the template.
    let shared: Vec<u32> = c.curves[0].iter().chain(&c.curves[1]).copied().collect();
    for &v in &c.curves[2].clone() {
        if !shared.contains(&v) {
            c.positions[v as usize][1] += 30.0;
        }
    }
    let (field, msg) = params_err(fit(icosphere(3, 1.0), c, &none()).unwrap_err());
    assert_eq!(field, "curves");
    assert!(msg.contains("curve 2"), "{msg}");
}

#[test]
fn pairs_pointing_at_missing_or_repeated_vertices() {
    let c = ellipsoid_sections(AXES, 4);
    let t = icosphere(2, 1.0);
    let pair = |v: u32, p: [f64; 3]| FitPair { template_vertex: v, curve_point: p };
    let p = FitParams { pairs: vec![pair(99_999, [1.4, 0.0, 0.0])], ..Default::default() };
    let (field, msg) = params_err(fit(t.clone(), c.clone(), &p).unwrap_err());
    assert_eq!(field, "pairs[0].template_vertex");
    assert!(msg.contains("99999"), "{msg}");
    let p =
        FitParams { pairs: vec![pair(3, [1.4, 0.0, 0.0]), pair(3, [0.0, 1.15, 0.0])], ..Default::default() };
    let (field, msg) = params_err(fit(t.clone(), c.clone(), &p).unwrap_err());
    assert_eq!(field, "pairs[1].template_vertex");
    assert!(msg.contains("pairs[0]"), "{msg}");
    let p =
        FitParams { pairs: vec![pair(1, [1.4, 0.0, 0.0]), pair(2, [1.4, 0.0, 0.01])], ..Default::default() };
    let (field, _) = params_err(fit(t.clone(), c.clone(), &p).unwrap_err());
    assert_eq!(field, "pairs[1].curve_point");
    // Fewer than 4 pairs, and 4 coplanar ones.
    let p =
        FitParams { pairs: vec![pair(1, [1.4, 0.0, 0.0]), pair(2, [0.0, 1.15, 0.0])], ..Default::default() };
    let (field, msg) = params_err(fit(t.clone(), c.clone(), &p).unwrap_err());
    assert_eq!(field, "pairs");
    assert!(msg.contains("at least 4"), "{msg}");
    // Icosphere vertices 0, 1, 2, 3 are (±1, t, 0), (±1, −t, 0) normalised: all in z = 0.
    let p = FitParams {
        pairs: vec![
            pair(0, [-1.4, 0.0, 0.0]),
            pair(1, [0.0, 1.15, 0.0]),
            pair(2, [0.0, -1.15, 0.0]),
            pair(3, [1.4, 0.0, 0.0]),
        ],
        ..Default::default()
    };
    let (field, msg) = params_err(fit(t, c, &p).unwrap_err());
    assert_eq!(field, "pairs");
    assert!(msg.contains("one plane"), "{msg}");
}

#[test]
fn malformed_networks_and_templates() {
    let t = icosphere(2, 1.0);
    // No polylines at all.
    let empty = Mesh { positions: vec![[0.0; 3]], ..Default::default() };
    let (field, _) = params_err(fit(t.clone(), empty, &none()).unwrap_err());
    assert_eq!(field, "curves");
    // A single straight curve: its points are collinear, so the RBF cannot be solved.
    let line = Mesh {
        positions: (0..6).map(|k| [-0.9 + 0.36 * k as f64, 0.1, 0.4]).collect(),
        curves: vec![(0..6).collect()],
        ..Default::default()
    };
    let (field, msg) = params_err(fit(t.clone(), line, &none()).unwrap_err());
    assert_eq!(field, "curves");
    assert!(msg.contains("one line"), "{msg}");
    // A curve that repeats one point only.
    let dot = Mesh { positions: vec![[1.0, 0.0, 0.0]], curves: vec![vec![0, 0]], ..Default::default() };
    let (_, msg) = params_err(fit(t.clone(), dot, &none()).unwrap_err());
    assert!(msg.contains("one point"), "{msg}");
    // Non-manifold template: one face listed twice.
    let mut bad = t.clone();
    let f0 = bad.faces.get(0).to_vec();
    let mut faces = Faces::new();
    for f in t.faces.iter() {
        faces.push(f, 0);
    }
    faces.push(&f0, 0);
    bad.faces = faces;
    let e = fit(bad, ellipsoid_sections(AXES, 4), &none()).unwrap_err();
    assert!(matches!(e, Error::Topology(ref m) if m.contains("face")), "{e}");
}

#[test]
fn unknown_and_out_of_range_params_are_named() {
    let inputs = || vec![icosphere(1, 1.0), ellipsoid_sections(AXES, 2)];
    let e = job::run(JobKind::Fit, inputs(), serde_json::json!({"snap": 0.2}), &Progress::new()).unwrap_err();
    assert_eq!(params_err(e).0, "snap");
    let e = job::run(JobKind::Fit, inputs(), serde_json::json!({"snap_fraction": 0.9}), &Progress::new())
        .unwrap_err();
    assert_eq!(params_err(e).0, "snap_fraction");
    let e = job::run(JobKind::Fit, inputs(), serde_json::json!({"kernel": "gaussian"}), &Progress::new())
        .unwrap_err();
    assert!(params_err(e).1.contains("gaussian"));
}
