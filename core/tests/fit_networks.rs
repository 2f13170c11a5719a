//! Curve networks that are not plane sections (issue 5's general case): crossings without a
//! shared vertex, T-junctions, dangling curves, degenerate polylines, near-duplicate points,
//! non-planar curves and extreme scales. Every truth comes from the geometry of closed-form
//! curves on a sphere (region counts by hand, crossing points at the axis points, the outward
//! normal), never from the fit. The heavier variants are in `examples/sweep_networks.rs`.

use meshwork_core::fit::curves::{CurveNetwork, NetworkOptions};
use meshwork_core::fit::testdata::{arc, circle, ellipsoid_sections, great_circles, loxodrome, polylines};
use meshwork_core::fit::testdata::{ellipsoid_outward, faces_against};
use meshwork_core::fit::{run, FitParams};
use meshwork_core::geometry::{dist, norm};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::icosphere;
use meshwork_core::{Output, Progress};

const R: f64 = 1.3;
const O: Point3 = [0.0; 3];
const X: Point3 = [1.0, 0.0, 0.0];
const Y: Point3 = [0.0, 1.0, 0.0];
const Z: Point3 = [0.0, 0.0, 1.0];

fn fit(curves: Mesh, params: &FitParams) -> Output {
    run(vec![icosphere(3, 1.0), curves], params, &Progress::new()).expect("fit")
}

/// Faces whose normal points into the sphere (the analytic outward normal is the position).
fn inward_faces(m: &Mesh) -> usize {
    faces_against(m, ellipsoid_outward([1.0; 3])).len()
}

/// The checks every case shares: all segments are edge chains, no face turned inward, `regions`
/// regions (also as output groups).
fn check(out: &Output, regions: usize) {
    let r = &out.report;
    assert_eq!(r["segments_as_edges"], 1.0, "{}", r["retriangulation"]["failed"]);
    assert_eq!(inward_faces(&out.meshes[0]), 0);
    assert_eq!(r["regions"], regions as u64, "network {}", r["network"]);
    assert_eq!(out.meshes[0].groups.len(), regions);
}

#[test]
fn crossings_without_a_shared_vertex_get_one() {
    // Three great circles sampled with phases that put no vertex on any crossing.
    let curves = polylines(&great_circles(R, 32, [0.05, 0.11, 0.07]));
    let net = CurveNetwork::build(&curves, &NetworkOptions::default()).unwrap();
    assert_eq!(net.stats.crossings_inserted, 6);
    assert_eq!(net.feature_count(), 6);
    // Each crossing is at an axis point ±R e_k, off by at most the chords' sag R(1 − cos(π/32)).
    let sag = R * (1.0 - (std::f64::consts::PI / 32.0).cos());
    for (p, &d) in net.points.iter().zip(&net.degree) {
        if d == 4 {
            let k = (0..3).max_by(|&a, &b| p[a].abs().total_cmp(&p[b].abs())).unwrap();
            let mut axis = [0.0; 3];
            axis[k] = R * p[k].signum();
            assert!(dist(*p, axis) <= 2.0 * sag, "crossing {p:?} is not near {axis:?}");
        }
    }
    check(&fit(curves.clone(), &FitParams::default()), 8);
    // Without the junction step the circles stay apart and the octants merge: the case needs it.
    let off = fit(curves, &FitParams { junction_tolerance: 0.0, ..Default::default() });
    assert!(off.report["regions"].as_u64().unwrap() < 8);
}

#[test]
fn sparse_crossings_far_off_the_chords_are_found() {
    // 8 points per circle: chords span 45° and pass up to 0.1 R inside the sphere.
    let curves = polylines(&great_circles(R, 8, [0.2, 0.31, 0.13]));
    let net = CurveNetwork::build(&curves, &NetworkOptions::default()).unwrap();
    assert_eq!(net.feature_count(), 6);
    assert!(net.degree.iter().all(|&d| d == 2 || d == 4));
    check(&fit(curves, &FitParams::default()), 8);
}

/// The equator (32 points) and the half meridian in the xz plane from (R, 0, 0) over the north
/// pole to (−R, 0, 0): the half meridian splits the north hemisphere, 3 regions.
fn t_junction(ends_on_chords: bool) -> Mesh {
    let equator = circle(O, X, Y, R, 32, 0.05);
    let mut half = arc(O, X, Z, R, 0.0, std::f64::consts::PI, 16);
    if ends_on_chords {
        // Exactly on the equator's chords: the chord through the x axis at (R cos(π/32 ...)).
        for e in [0, half.len() - 1] {
            let p = half[e];
            let w = equator
                .windows(2)
                .find(|w| (w[0][1] <= 0.0) != (w[1][1] <= 0.0) && w[0][0] * p[0] > 0.0)
                .unwrap();
            let t = w[0][1] / (w[0][1] - w[1][1]);
            half[e] = [w[0][0] + t * (w[1][0] - w[0][0]), 0.0, 0.0];
        }
    }
    polylines(&[equator, half])
}

#[test]
fn t_junctions_split_the_segment_they_end_on() {
    for on_chords in [false, true] {
        let curves = t_junction(on_chords);
        let net = CurveNetwork::build(&curves, &NetworkOptions::default()).unwrap();
        assert_eq!(net.stats.t_junctions, 2, "ends on chords: {on_chords}");
        assert_eq!(net.stats.dangling_ends, 0);
        assert_eq!(net.feature_count(), 2);
        check(&fit(curves, &FitParams::default()), 3);
    }
}

#[test]
fn dangling_curves_are_kept_and_counted() {
    // An arc from an equator vertex up to latitude 60° and a floating arc in the south: neither
    // closes a region, so the equator's 2 remain; 3 free ends.
    let zc = -0.6;
    let curves = polylines(&[
        circle(O, X, Y, R, 32, 0.0),
        arc(O, X, Z, R, 0.0, std::f64::consts::PI / 3.0, 8),
        arc([0.0, 0.0, zc], X, Y, (R * R - zc * zc).sqrt(), 0.3, 2.3, 10),
    ]);
    let out = fit(curves, &FitParams::default());
    check(&out, 2);
    assert_eq!(out.report["network"]["dangling_ends"], 3);
    // Every curve point is still a vertex of the output (the dangling ones too).
    assert!(out.report["curve_residual_max"].as_f64().unwrap() <= 1e-9 * 2.0 * R);
}

#[test]
fn degenerate_polylines_are_dropped_or_merged_and_reported() {
    let mut lines = great_circles(R, 16, [0.0; 3]);
    let p = [R * 0.6, R * 0.64, R * (1.0f64 - 0.36 - 0.4096).sqrt()];
    lines.push(vec![p, p]); // a closed loop of one point
    let mut repeated_point = lines[0].clone();
    repeated_point.insert(5, repeated_point[5]); // a zero-length segment
    lines.push(repeated_point);
    lines.push(lines[1].clone()); // a repeated polyline
    let out = fit(polylines(&lines), &FitParams::default());
    check(&out, 8);
    let n = &out.report["network"];
    assert_eq!(n["dropped_polylines"], serde_json::json!([3]));
    // The one-point loop's repeat and the inserted repeat.
    assert_eq!(n["zero_length_segments"], 2);
    // Polylines 4 and 5 repeat circles 0 and 1: 16 segments each.
    assert_eq!(n["duplicate_segments"], 32);
    // 3 circles of 16 points sharing the 6 axis points.
    assert_eq!(out.report["curve_vertices"], 42);
}

#[test]
fn near_duplicate_points_are_merged_and_counted() {
    let mut c = ellipsoid_sections([1.4, 1.15, 0.9], 16);
    let (a, b) = (c.curves[0][3], c.curves[0][4]);
    let (pa, pb) = (c.positions[a as usize], c.positions[b as usize]);
    let d = 2e-5 / dist(pa, pb);
    c.positions.push([pa[0] + d * (pb[0] - pa[0]), pa[1] + d * (pb[1] - pa[1]), pa[2] + d * (pb[2] - pa[2])]);
    let id = (c.positions.len() - 1) as u32;
    c.curves[0].insert(4, id);
    let out = run(vec![icosphere(3, 1.0), c.clone()], &FitParams::default(), &Progress::new()).unwrap();
    let n = &out.report["network"];
    assert_eq!(n["near_duplicates_merged"], 1);
    assert!((n["near_duplicate_max_distance"].as_f64().unwrap() - 2e-5).abs() < 1e-9);
    // The pair's segment is 2e-5 long against ~0.14 for the others: kept, it leaves a sliver.
    let kept = run(
        vec![icosphere(3, 1.0), c],
        &FitParams { merge_tolerance: 0.0, ..Default::default() },
        &Progress::new(),
    )
    .unwrap();
    let min = |o: &Output| o.report["min_angle_deg_before_smoothing"].as_f64().unwrap();
    assert!(min(&out) > 5.0, "merged: {}", min(&out));
    assert!(min(&kept) < 1.0, "kept: {}", min(&kept));
}

#[test]
fn a_loxodrome_crossing_the_equator_between_vertices() {
    // The loxodrome crosses the equator once (latitude 0 at longitude 0), between the equator's
    // vertices (phase 0.03) and between its own (odd segment count): one inserted crossing.
    let curves = polylines(&[circle(O, X, Y, R, 48, 0.03), loxodrome(R, 1.2, 1.5, 41)]);
    let out = fit(curves, &FitParams::default());
    check(&out, 2);
    assert_eq!(out.report["network"]["crossings_inserted"], 1);
    assert_eq!(out.report["network"]["dangling_ends"], 2);
}

#[test]
fn scale_and_offset_do_not_change_the_result() {
    let base = || (icosphere(3, 1.0), ellipsoid_sections([R; 3], 2));
    let (t, c) = base();
    let reference = run(vec![t, c], &FitParams::default(), &Progress::new()).unwrap();
    check(&reference, 8);
    for (s, off) in [(1e-3, 0.0), (1e3, 0.0), (1.0, 1e6)] {
        let (mut t, mut c) = base();
        for p in t.positions.iter_mut().chain(c.positions.iter_mut()) {
            *p = [p[0] * s + off, p[1] * s + off, p[2] * s + off];
        }
        let out = run(vec![t, c], &FitParams::default(), &Progress::new()).unwrap();
        let r = &out.report;
        assert_eq!(r["regions"], 8, "scale {s} offset {off}");
        assert_eq!(r["segments_as_edges"], 1.0);
        assert_eq!(r["flipped_faces"], 0);
        assert_eq!(r["output_faces"], reference.report["output_faces"], "scale {s} offset {off}");
        // Same mesh up to the map: angles agree to rounding of the coordinates, carried through
        // the iterative stages (measured in the dev profile: up to 8e-3°, from where the alignment's iterations stop).
        for key in ["min_angle_deg_before_smoothing", "min_angle_deg_after_smoothing"] {
            let (a, b) = (r[key].as_f64().unwrap(), reference.report[key].as_f64().unwrap());
            assert!((a - b).abs() < 0.05, "{key} scale {s} offset {off}: {a} vs {b}");
        }
        // Curve points stay on the output, relative to the size.
        assert!(r["curve_residual_max"].as_f64().unwrap() <= 1e-9 * 2.0 * R * s.max(1.0) + 1e-9 * off);
        let m = &out.meshes[0];
        let centre_dist = m.positions.iter().map(|p| norm([p[0] - off, p[1] - off, p[2] - off]) / s);
        assert!(centre_dist.fold(0.0, f64::max) <= R * 1.01);
    }
}
