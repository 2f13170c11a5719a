//! The fit on templates in pieces (raw real meshes: suzanne's head and eyes, teapot's body,
//! spout and handle, unwelded seams). Two failures of earlier versions, each built from a truth
//! made here from the geometry, not read from the fit:
//! - a curve on one piece whose nearest template *vertices* belong to another piece close by must
//!   still be inserted on its own piece (closest point on the faces, not around the nearest
//!   vertex): every segment an edge chain, no flip, the other piece untouched;
//! - a segment whose ends lie on two pieces that no edge joins cannot be an edge chain: the
//!   report counts exactly those (`failed_pieces`) and names the reason `pieces` for each;
//! - curves on two pieces that cross in space (pieces passing through each other) are not joined
//!   by the network, so that every input segment, on one piece, is realised.

use meshwork_core::fit::curves::{CurveNetwork, NetworkOptions};
use meshwork_core::fit::testdata::{disjoint_union, plane_sections};
use meshwork_core::geometry::{dist, Aabb};
use meshwork_core::job::{self, JobKind, Output};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::{fan_triangles, icosphere};
use meshwork_core::spatial::closest_on_triangle;
use meshwork_core::Progress;
use serde_json::json;

fn fit(template: Mesh, curves: Mesh, params: serde_json::Value) -> Output {
    job::run(JobKind::Fit, vec![template, curves], params, &Progress::new()).expect("the fit runs")
}

fn shifted(m: &Mesh, by: Point3) -> Mesh {
    let mut m = m.clone();
    for p in &mut m.positions {
        *p = [p[0] + by[0], p[1] + by[1], p[2] + by[2]];
    }
    m
}

/// Distance from `p` to the surface of `m` (brute force over its triangles).
fn distance_to(m: &Mesh, p: Point3) -> f64 {
    fan_triangles(&m.faces)
        .iter()
        .map(|t| {
            let q = closest_on_triangle(p, &t.map(|v| m.positions[v as usize]));
            dist(p, q)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Sections by three planes (off round offsets) of a coarse sphere (320 faces, edges ≈ 0.3 long),
/// with a small sphere (radius 0.06) floating 0.09 outside the big one next to a section point:
/// for the curve points near it the nearest template vertices are the small sphere's (≈ 0.03
/// away) while the big sphere's are up to ≈ 0.15 away. Hand count of regions: three planes near
/// the centre cut the big sphere into 8 octant-like cells; the small sphere, with no curve on it,
/// is one region more: 9.
#[test]
fn curves_stay_on_their_piece_when_another_piece_is_nearer_by_vertices() {
    let big = icosphere(2, 1.0);
    let planes: Vec<(Point3, f64)> =
        vec![([0.0, 0.0, 1.0], 0.1237), ([1.0, 0.0, 0.0], 0.0713), ([0.0, 1.0, 0.0], -0.0531)];
    let curves = plane_sections(&big, &planes);
    // A section point on the z-plane circle with x > 0.9: the small sphere sits outside it.
    let p = *curves
        .positions
        .iter()
        .filter(|p| (p[2] - 0.1237).abs() < 1e-12 && p[0] > 0.9)
        .max_by(|a, b| a[0].total_cmp(&b[0]))
        .expect("a section point near +x");
    let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let c = [p[0] / r * (r + 0.09), p[1] / r * (r + 0.09), p[2] / r * (r + 0.09)];
    let small = shifted(&icosphere(1, 0.06), c);
    // The case this test is for: some curve point's nearest template vertex is on the small sphere.
    let nearest_small = curves.positions.iter().any(|&q| {
        let ds = small.positions.iter().map(|&v| dist(v, q)).fold(f64::INFINITY, f64::min);
        let db = big.positions.iter().map(|&v| dist(v, q)).fold(f64::INFINITY, f64::min);
        ds < db
    });
    assert!(nearest_small, "test set-up: no curve point is nearer to the small sphere's vertices");
    let template = disjoint_union(&big, &small);
    let out = fit(template, curves.clone(), json!({"alignment": "none", "smooth": false}));
    let r = &out.report;
    assert_eq!(r["segments_as_edges"], 1.0, "retriangulation {}", r["retriangulation"]);
    assert_eq!(r["flipped_faces"], 0);
    assert_eq!(r["regions"], 9);
    // The curves lie on the big sphere, so nothing needs to move: the small sphere's vertices
    // are all still in the output where they were.
    let m = &out.meshes[0];
    for &v in &small.positions {
        let d = m.positions.iter().map(|&q| dist(q, v)).fold(f64::INFINITY, f64::min);
        assert!(d < 1e-9, "small-sphere vertex {v:?} moved by {d}");
    }
    // Every curve vertex is an output vertex on the big sphere (its surface: distance 0).
    let diag = Aabb::of(&m.positions).map_or(1.0, |b| b.diagonal());
    for &q in &curves.positions {
        assert!(distance_to(&big, q) < 1e-12 * diag);
        let d = m.positions.iter().map(|&x| dist(x, q)).fold(f64::INFINITY, f64::min);
        assert!(d < 1e-9 * diag, "curve vertex {q:?} is {d} from the output");
    }
}

/// Two coarse spheres overlapping (centres 1.2 apart, radius 1), as separate components, cut by
/// the planes z = 0.1237 and y = −0.0531 (both cut both spheres) and x = 0.0713 (the first only).
/// In each of the two planes the two spheres' circles cross in space. Truth, from the geometry:
/// every input segment has both ends on one sphere (checked here), so every one can be an edge
/// chain of its own piece. The network used to join the circles where they cross (a shared
/// vertex, or one circle's segment split at the other's vertex), making segments between the
/// pieces that no edge chain can realise (this set-up: 4–8 such segments, `route: "pieces"`); the
/// aligned template now refuses every join between curves on two pieces (`fit::sheets`).
#[test]
fn curves_on_two_overlapping_pieces_are_not_joined_and_all_realised() {
    let a = icosphere(2, 1.0);
    let b = shifted(&icosphere(2, 1.0), [1.2, 0.0, 0.0]);
    let planes: Vec<(Point3, f64)> =
        vec![([0.0, 0.0, 1.0], 0.1237), ([0.0, 1.0, 0.0], -0.0531), ([1.0, 0.0, 0.0], 0.0713)];
    let template = disjoint_union(&a, &b);
    let curves = plane_sections(&template, &planes);
    for c in &curves.curves {
        let on = |m: &Mesh| c.iter().all(|&v| distance_to(m, curves.positions[v as usize]) < 1e-9);
        assert!(on(&a) || on(&b), "test set-up: an input polyline leaves its sphere");
    }
    // Without a template to ask, the network joins the circles (the case this test is for).
    let plain = CurveNetwork::build(&curves, &NetworkOptions::default()).expect("network").stats;
    assert!(plain.crossings_inserted + plain.crossings_at_vertices >= 2, "test set-up: {plain:?}");
    let out = fit(template, curves, json!({"alignment": "none"}));
    let r = &out.report;
    let retri = &r["retriangulation"];
    assert_eq!(retri["failed_pieces"], 0, "retriangulation {retri}");
    assert_eq!(r["segments_as_edges"], 1.0, "retriangulation {retri}");
    let refused = r["network"]["crossings_on_two_sheets"].as_u64().unwrap_or(0)
        + r["network"]["ends_on_two_sheets"].as_u64().unwrap_or(0);
    assert!(refused >= 2, "network {}", r["network"]);
}

/// The same two overlapping spheres and sections, plus one polyline drawn from a vertex of the
/// first sphere only to one of the second only, both away from every plane (through the inside
/// of both, 0.2 or more from every section): that segment's ends lie on two pieces that no edge
/// joins, so it cannot be an edge chain. The report counts exactly it (`failed_pieces`) and names
/// the reason `pieces`; every other segment is realised.
#[test]
fn segments_between_pieces_no_edge_joins_are_counted_and_named() {
    let a = icosphere(2, 1.0);
    let b = shifted(&icosphere(2, 1.0), [1.2, 0.0, 0.0]);
    let planes: Vec<(Point3, f64)> =
        vec![([0.0, 0.0, 1.0], 0.1237), ([0.0, 1.0, 0.0], -0.0531), ([1.0, 0.0, 0.0], 0.0713)];
    let template = disjoint_union(&a, &b);
    let mut curves = plane_sections(&template, &planes);
    // The vertices of each sphere farthest along (∓0.6, 0.6, −0.53) from its centre.
    let farthest = |m: &Mesh, c: Point3, d: Point3| {
        let along = |p: &Point3| (p[0] - c[0]) * d[0] + (p[1] - c[1]) * d[1] + (p[2] - c[2]) * d[2];
        *m.positions.iter().max_by(|p, q| along(p).total_cmp(&along(q))).expect("vertices")
    };
    let (pw, pe) =
        (farthest(&a, [0.0; 3], [-0.6, 0.6, -0.53]), farthest(&b, [1.2, 0.0, 0.0], [0.6, 0.6, -0.53]));
    assert!(distance_to(&b, pw) > 0.1 && distance_to(&a, pe) > 0.1, "test set-up: {pw:?} {pe:?}");
    let n = curves.positions.len() as u32;
    curves.positions.extend([pw, pe]);
    curves.curves.push(vec![n, n + 1]);
    let out = fit(template, curves, json!({"alignment": "none"}));
    let r = &out.report;
    let retri = &r["retriangulation"];
    assert_eq!(retri["failed_pieces"], 1, "retriangulation {retri}");
    assert_eq!(retri["failed_segments"], 1, "retriangulation {retri}");
    let failed = retri["failed"].as_array().expect("failed list");
    assert_eq!(failed.len(), 1);
    assert_eq!(failed[0]["route"], "pieces", "{}", failed[0]);
    let segments = r["curve_segments"].as_f64().expect("segments");
    let share = r["segments_as_edges"].as_f64().expect("share");
    assert!(
        (share - (segments - 1.0) / segments).abs() < 1e-12,
        "segments_as_edges {share}, {segments} segments"
    );
    // The measure tells the refusal from a failure: the one segment no chain can realise is the
    // one not an edge, and every segment a chain can realise is one.
    let not_edges = &r["segments_not_edges"];
    assert_eq!(not_edges["total"], 1, "{not_edges}");
    assert_eq!(not_edges["pieces"], 1, "{not_edges}");
    assert_eq!(not_edges["separated"], 0, "{not_edges}");
    assert_eq!(not_edges["broken_after_retriangulation"], 0, "{not_edges}");
    assert_eq!(r["segments_as_edges_realisable"], 1.0, "{r}");
}
