//! Session 8's unseen inputs (each a failure found by `examples/sweep_unseen.rs`, turned into a
//! fast case checked against a truth counted by hand): curves in other units than the template
//! (auto alignment scales, so the distance limit must too), two curves closer than a quarter
//! segment crossed by a third (they must not be pinched together), glTF curves placed by node
//! transforms (shared ends differ by f32 rounding: welded and the distance reported), and a pair
//! point so far away that its squared distance overflows.

use meshwork_core::fit::curves::{CurveNetwork, NetworkOptions};
use meshwork_core::fit::testdata::{
    circle, ellipsoid_sections, gltf_strips_with_nodes, great_circles, polylines,
};
use meshwork_core::geometry::{dist, Aabb};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::job::{self, JobKind, Output};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::icosphere;
use meshwork_core::{Error, Progress};
use serde_json::json;

const AXES: [f64; 3] = [1.4, 1.15, 0.9];
const X: Point3 = [1.0, 0.0, 0.0];
const Y: Point3 = [0.0, 1.0, 0.0];

fn fit(template: Mesh, curves: Mesh, params: serde_json::Value) -> Result<Output, Error> {
    job::run(JobKind::Fit, vec![template, curves], params, &Progress::new())
}

/// Distance from `p` to the nearest vertex of the output's curve chains.
fn to_chains(out: &Output, p: Point3) -> f64 {
    let m = &out.meshes[0];
    m.curves.iter().flatten().map(|&v| dist(m.positions[v as usize], p)).fold(f64::INFINITY, f64::min)
}

fn lines_of(m: &Mesh) -> Vec<Vec<Point3>> {
    m.curves.iter().map(|l| l.iter().map(|&v| m.positions[v as usize]).collect()).collect()
}

/// The octant network 100× larger than the unit icosphere (a template in metres, curves in
/// centimetres): the automatic alignment scales the template, and "far from the template" is
/// then measured against the aligned template, not the one given (which refused every curve).
#[test]
fn curves_in_other_units_fit_with_auto_alignment() {
    let mut c = ellipsoid_sections(AXES, 6);
    for p in &mut c.positions {
        *p = [p[0] * 100.0, p[1] * 100.0, p[2] * 100.0];
    }
    let out = fit(icosphere(3, 1.0), c.clone(), json!({})).expect("fit");
    let r = &out.report;
    assert_eq!(r["regions"], 8);
    assert_eq!(r["segments_as_edges"], 1.0);
    assert_eq!(r["flipped_faces"], 0);
    // Every curve vertex is on the output (relative to the curves' size, 1e-9).
    let diag = Aabb::of(&c.positions).unwrap().diagonal();
    for &p in &c.positions {
        assert!(to_chains(&out, p) <= 1e-9 * diag, "{p:?}");
    }
    // The output is the size of the curves: its bounding box is the ellipsoid's, 280 × 230 × 180,
    // within the sag of the template's faces between the curves (< 10 %).
    let b = Aabb::of(&out.meshes[0].positions).unwrap();
    for k in 0..3 {
        let ext = b.max[k] - b.min[k];
        assert!((ext / (200.0 * AXES[k]) - 1.0).abs() < 0.1, "axis {k}: {ext}");
    }
}

/// The equator and a parallel 0.01 above it (segments 0.13 long, so the parallel is within the
/// junction tolerance, ¼ segment, of the equator), crossed by two great circles. Where a meridian
/// crosses the parallel, the parallel's own vertex lies on the meridian (both sampled at the same
/// longitudes), while the meridian's nearest vertex is on the equator: the crossing must be that
/// parallel vertex, not a merge of the two (which pinched the parallel onto the equator at four
/// points, moving it by 0.01).
fn equator_and_close_parallel() -> Mesh {
    let mut l = great_circles(1.0, 48, [0.0; 3]);
    l.push(circle([0.0, 0.0, 0.01], X, Y, (1.0f64 - 1e-4).sqrt(), 48, 0.0));
    polylines(&l)
}

#[test]
fn a_parallel_close_to_the_equator_keeps_its_own_vertices() {
    let c = equator_and_close_parallel();
    let net = CurveNetwork::build(&c, &NetworkOptions::default()).expect("network");
    // Every input point is a network point (nothing merged away, nothing moved beyond the
    // round-off of the circles' shared axis points, welded).
    for &p in &c.positions {
        let d = net.points.iter().map(|&q| dist(p, q)).fold(f64::INFINITY, f64::min);
        assert!(d <= 1e-12, "{p:?} moved by {d}");
    }
    // 6 axis points of degree 4 (the great circles), plus the parallel's 4 crossings with the
    // two vertical circles (degree 4): 10 feature points.
    assert_eq!(net.feature_count(), 10);
    // The largest gap closed is the meridian chord's sag at the parallel's vertex (the vertex is
    // on the circle, 0.57° from the chord's end: ≈ ½ · 0.077 · 0.923 · 0.13² ≈ 6e-4), not the
    // 0.01 between the parallel and the equator.
    let gap = net.stats.junction_max_gap;
    assert!(gap > 5e-4 && gap < 7e-4, "{gap}");
    // Fitted: 8 octants, the 4 upper ones each cut in two by the parallel = 12 regions.
    let out = fit(icosphere(2, 1.0), c.clone(), json!({"alignment": "none"})).expect("fit");
    assert_eq!(out.report["regions"], 12);
    assert_eq!(out.report["segments_as_edges"], 1.0);
    for &p in &c.positions {
        assert!(to_chains(&out, p) <= 1e-9, "{p:?} is {} from the chains", to_chains(&out, p));
    }
}

/// Two curves that meet at a point each samples separately (a corner drawn twice, 1 % of a
/// segment apart, neither on the other's segment) are still joined into one vertex.
#[test]
fn a_corner_sampled_twice_is_still_one_vertex() {
    // Two straight lines crossing at right angles near the origin, segments 0.1 long: their
    // samples there are 0.0016 apart, each 0.001-0.0013 off the other's line.
    let a: Vec<Point3> = (0..=6).map(|k| [0.1 * (k as f64 - 3.0), 0.0, 0.0]).collect();
    let b: Vec<Point3> = (0..=6).map(|k| [0.001, -0.0013 + 0.1 * (k as f64 - 3.0), 0.0]).collect();
    let net = CurveNetwork::build(&polylines(&[a, b]), &NetworkOptions::default()).expect("network");
    assert_eq!(net.feature_count(), 1);
    assert_eq!(net.points.len(), 13);
}

/// Three LINE_STRIP meshes, each under a node with translation, rotation and scale, under a
/// parent that scales by 2: read back to f32 rounding, the shared axis points (stored once per
/// strip, each through its own transform) are welded, and the report says by how much.
#[test]
fn gltf_strips_under_node_transforms() {
    let want = ellipsoid_sections(AXES, 6);
    let lines = lines_of(&want);
    let bytes = gltf_strips_with_nodes(&lines);
    let c =
        read(&bytes, &ReadOptions { name_hint: Some("c.gltf".into()), ..Default::default() }).unwrap().mesh;
    // The reader applied the transforms: every polyline comes back where it was.
    assert_eq!(c.curves.len(), 3);
    for (l, w) in c.curves.iter().zip(&lines) {
        assert_eq!(l.len(), w.len());
        for (&v, &p) in l.iter().zip(w) {
            assert!(dist(c.positions[v as usize], p) < 1e-6, "{:?} vs {p:?}", c.positions[v as usize]);
        }
    }
    let out = fit(icosphere(3, 1.0), c.clone(), json!({})).expect("fit");
    let r = &out.report;
    assert_eq!(r["regions"], 8);
    assert_eq!(r["segments_as_edges"], 1.0);
    assert_eq!(r["flipped_faces"], 0);
    // The 6 axis points are each stored by two strips (plus each circle's closing point): 9 welds.
    assert_eq!(r["network"]["welded_points"], 9);
    let moved = r["network"]["welded_max_distance"].as_f64().unwrap();
    assert!(moved > 0.0 && moved < 1e-6, "{moved}");
    for &p in &c.positions {
        assert!(to_chains(&out, p) <= moved + 1e-12, "{p:?}");
    }
}

/// A pair point at 1e300: its squared distance overflows; still the "far from every curve" error
/// naming the pair, not an internal error.
#[test]
fn a_pair_point_at_1e300_is_named() {
    let p = |v: u32, x: Point3| json!({"template_vertex": v, "curve_point": x});
    let pairs = json!([
        p(0, [1.4, 0.0, 0.0]),
        p(5, [0.0, 1.15, 0.0]),
        p(9, [0.0, 0.0, 0.9]),
        p(11, [1e300, 0.0, 0.0])
    ]);
    let e =
        fit(icosphere(2, 1.0), ellipsoid_sections(AXES, 6), json!({ "pairs": pairs })).err().expect("error");
    let text = e.to_string();
    assert!(text.contains("pairs[3].curve_point") && text.contains("nearest curve vertex"), "{text}");
}
