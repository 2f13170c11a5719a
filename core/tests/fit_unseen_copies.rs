//! Inputs of session 7's search for new failure classes, each with a truth made by hand:
//! a curve given twice with another sampling (two CAD patches each exporting their shared
//! border), template faces with a repeated corner (collapsed edges), loose edges of a PLY file as
//! the curves, the face named in a template error when the template has n-gons, and a sparse
//! network (4 points per section) on a template 20 times denser.

use meshwork_core::fit::curves::{CurveNetwork, NetworkOptions};
use meshwork_core::fit::testdata::{circle, ellipsoid_sections, great_circles, ngon_sphere, polylines};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::job::{self, JobKind, Output};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::icosphere;
use meshwork_core::{Error, Progress};
use serde_json::json;

fn fit(template: Mesh, curves: Mesh, params: serde_json::Value) -> Result<Output, Error> {
    job::run(JobKind::Fit, vec![template, curves], params, &Progress::new())
}

/// The checks every fit here must pass: regions as counted by hand, one group per region, every
/// segment an edge chain, no flipped face.
fn check(out: &Output, regions: u64) {
    let r = &out.report;
    assert_eq!(r["regions"], regions, "network {}", r["network"]);
    assert_eq!(out.meshes[0].groups.len() as u64, regions);
    assert_eq!(r["segments_as_edges"], 1.0, "retriangulation {}", r["retriangulation"]);
    assert_eq!(r["flipped_faces"], 0);
}

/// A straight line from x = 0 to 10 given twice: at the integers (11 points) and at the half
/// integers (10 points). Hand count: every half-integer point goes into the first copy's segment
/// around it (10), every inner integer point into the second's (9), so both copies run through
/// x = 0, 0.5, …, 10: 21 points, 20 distinct segments, the second copy's 18 repeated.
#[test]
fn a_line_given_twice_with_other_samples_is_one_line() {
    let a: Vec<Point3> = (0..=10).map(|i| [i as f64, 0.0, 0.0]).collect();
    let b: Vec<Point3> = (0..10).map(|i| [i as f64 + 0.5, 0.0, 0.0]).collect();
    let net = CurveNetwork::build(&polylines(&[a, b]), &NetworkOptions::default()).unwrap();
    assert_eq!(net.stats.overlap_points_joined, 19);
    assert_eq!(net.points.len(), 21);
    assert_eq!(net.segments.len(), 20);
    assert_eq!(net.stats.duplicate_segments, 18);
    assert_eq!(net.stats.dangling_ends, 2);
}

/// Two lines crossing at 10° near x = 5, one sampled finely around the crossing: they meet at
/// one point (a crossing), and no point of one is merged into the other as a copy.
#[test]
fn a_shallow_crossing_is_not_a_copy() {
    let a: Vec<Point3> = (0..=10).map(|i| [i as f64, 0.0, 0.0]).collect();
    let tan = 10f64.to_radians().tan();
    let xs = [0.0, 2.0, 4.0, 4.6, 4.8, 4.9, 5.05, 5.2, 5.4, 6.0, 8.0, 10.0];
    let b: Vec<Point3> = xs.iter().map(|&x| [x, (x - 5.013) * tan, 0.0]).collect();
    let net = CurveNetwork::build(&polylines(&[a, b]), &NetworkOptions::default()).unwrap();
    assert_eq!(net.stats.overlap_points_joined, 0, "{:?}", net.stats);
    assert_eq!(net.stats.crossings_inserted + net.stats.crossings_at_vertices, 1, "{:?}", net.stats);
}

/// The octant network of the unit sphere (three great circles of 48 points) with the equator
/// given a second time with 37 points from another phase: still the 8 octants (hand count), not
/// a strip of slivers between the two equators (36 regions before).
#[test]
fn the_equator_given_twice_still_makes_eight_octants() {
    let mut lines = great_circles(1.0, 48, [0.0; 3]);
    lines.push(circle([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0, 37, 0.03));
    let out = fit(icosphere(3, 1.0), polylines(&lines), json!({})).unwrap();
    check(&out, 8);
    assert!(out.report["network"]["overlap_points_joined"].as_u64().unwrap() >= 37 + 48 - 2);
}

/// A triangle `3 3 5` (a collapsed edge) and a quad `a b b c` added to the icosphere: the first
/// is removed, the second becomes the triangle it is; both counted (hand: 2 corners, 1 face).
/// The quad duplicates an existing face's edge direction unless turned: it is given as the
/// reverse of face 0 with one corner doubled, on a copy of face 0's vertices, so it is a second
/// component (one more region).
#[test]
fn faces_with_a_repeated_corner_are_mended_or_removed_and_counted() {
    let mut t = icosphere(3, 1.0);
    let f0 = t.faces.triangles()[0];
    let n = t.positions.len() as u32;
    for &v in &f0 {
        let p = t.positions[v as usize];
        t.positions.push([p[0] * 1.5 + 6.0, p[1] * 1.5, p[2] * 1.5]);
    }
    t.faces.push(&[3, 3, 5], 0);
    t.faces.push(&[n, n + 1, n + 1, n + 2], 0);
    let out = fit(t, ellipsoid_sections([1.4, 1.15, 0.9], 6), json!({"alignment": "none"})).unwrap();
    check(&out, 9);
    let r = &out.report["template_repeated_corners"];
    assert_eq!((r["corners_removed"].as_u64(), r["faces_removed"].as_u64()), (Some(2), Some(1)), "{r}");
    assert_eq!(r["first_faces_removed"], json!([1280]));
}

/// The octant network written as a PLY of loose edges (`element edge`, as Blender writes a
/// curve object): the same 8 regions as the same network as polylines.
#[test]
fn loose_ply_edges_are_curves() {
    let c = ellipsoid_sections([1.4, 1.15, 0.9], 6);
    let segs: Vec<[u32; 2]> = c.curves.iter().flat_map(|l| l.windows(2).map(|w| [w[0], w[1]])).collect();
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element edge {}\nproperty int vertex1\nproperty int vertex2\nend_header\n",
        c.positions.len(),
        segs.len()
    );
    for p in &c.positions {
        s += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for e in &segs {
        s += &format!("{} {}\n", e[0], e[1]);
    }
    let opts = ReadOptions { name_hint: Some("c.ply".into()), ..Default::default() };
    let curves = read(s.as_bytes(), &opts).unwrap().mesh;
    assert_eq!(curves.curves.len(), segs.len());
    let out = fit(icosphere(3, 1.0), curves, json!({})).unwrap();
    check(&out, 8);
}

/// An n-gon template (8-gon caps, quads) with a fin triangle on the edge 0 → 1 of face 1 (the
/// quad 0 1 9 8): the error names the input faces 1 and 26 (the fin, after 1 + 24 + 1 faces),
/// not their triangles (7 and 60).
#[test]
fn a_template_error_names_the_input_face_of_an_ngon_template() {
    let mut t = ngon_sphere(8, 4, 1.0);
    assert_eq!(t.faces.get(1), &[0, 1, 9, 8]);
    t.positions.push([2.0, 0.0, -2.0]);
    let v = t.positions.len() as u32 - 1;
    t.faces.push(&[0, 1, v], 0);
    let e = fit(t, ellipsoid_sections([1.4, 1.15, 0.9], 6), json!({})).unwrap_err().to_string();
    assert!(e.contains("faces 1 and 26"), "{e}");
}

/// Sections with 4 points each (90° chords) on an icosphere of 1,280 faces: each segment's strip
/// crosses some 25 faces bent by up to 90°. It is split along the surface, not re-filled through
/// the chord (which folded 141 faces on the 20k-face icosphere of `examples/sweep_unseen.rs` and
/// took 7 s to untangle; that case is too slow for a test in the dev profile).
#[test]
fn a_sparse_network_on_a_dense_template() {
    let out = fit(icosphere(3, 1.0), ellipsoid_sections([1.4, 1.15, 0.9], 1), json!({})).unwrap();
    check(&out, 8);
    assert!(out.report["retriangulation"]["curved_strips"].as_u64().unwrap() > 0);
}
