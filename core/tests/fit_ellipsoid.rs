//! Fit a sphere template through the principal sections of an ellipsoid: the truth is the
//! analytic ellipsoid (curves on it, surface near it, 8 octant regions).

use meshwork_core::fit::testdata::{ellipsoid_distance, ellipsoid_sections};
use meshwork_core::fit::{run, Alignment, FitParams};
use meshwork_core::geometry::signed_volume;
use meshwork_core::shapes::icosphere;
use meshwork_core::Progress;

const AXES: [f64; 3] = [1.4, 1.15, 0.9];

fn fit(params: &FitParams) -> meshwork_core::Output {
    let template = icosphere(4, 1.0);
    let curves = ellipsoid_sections(AXES, 10);
    run(vec![template, curves], params, &Progress::new()).expect("fit")
}

#[test]
fn sphere_fits_ellipsoid_sections() {
    let params = FitParams { alignment: Alignment::None, ..Default::default() };
    let out = fit(&params);
    let r = &out.report;
    eprintln!("{}", serde_json::to_string_pretty(r).unwrap());
    let m = &out.meshes[0];
    let max_dev = m.positions.iter().map(|&p| ellipsoid_distance(p, AXES)).fold(0.0, f64::max);
    let mean_dev = m.positions.iter().map(|&p| ellipsoid_distance(p, AXES)).sum::<f64>() / m.positions.len() as f64;
    eprintln!("surface deviation max {max_dev} mean {mean_dev}");
    let vol = signed_volume(&m.positions, &m.faces);
    let exact = 4.0 / 3.0 * std::f64::consts::PI * AXES[0] * AXES[1] * AXES[2];
    eprintln!("volume {vol} exact {exact}");
    // The flipped-face check here uses the analytic outward normal, not the job's own measure.
    let flipped = m
        .faces
        .iter()
        .filter(|f| {
            let (a, b, c) = (m.positions[f[0] as usize], m.positions[f[1] as usize], m.positions[f[2] as usize]);
            let n = meshwork_core::geometry::triangle_cross(a, b, c);
            let g = [(a[0] + b[0] + c[0]) / AXES[0].powi(2), (a[1] + b[1] + c[1]) / AXES[1].powi(2), (a[2] + b[2] + c[2]) / AXES[2].powi(2)];
            meshwork_core::geometry::dot(n, g) <= 0.0
        })
        .count();
    eprintln!("analytic flipped {flipped}");
    assert_eq!(r["regions"], 8);
}
