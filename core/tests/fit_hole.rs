//! Templates with a hole under the curves (a scan with a gap): the icosphere with the faces around
//! a point removed, fitted to the octant sections of an ellipsoid. A segment whose straight way
//! crosses the hole has no surface under it: it must be counted as `off_surface_segments`, not
//! routed around the hole (which cut a spurious 9th region off), and every other segment must be
//! an edge chain. Truths: the octants' 8 regions (hand count: the chains on both sides of the
//! gap end on its rim, so no two octants join); the hole stays one boundary loop; the segments
//! reported off the surface are counted again on the output (middle off every output face) and
//! bounded from the input geometry (segments whose middle's direction is inside the hole, and
//! those with any of their points there).

use meshwork_core::fit::testdata::{ellipsoid_sections, with_holes};
use meshwork_core::geometry::{cross, dot, norm, normalize, sub, Aabb};
use meshwork_core::job::{self, JobKind, Output};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::icosphere;
use meshwork_core::spatial::closest_on_triangle;
use meshwork_core::Progress;
use serde_json::json;

const AXES: [f64; 3] = [1.4, 1.15, 0.9];

fn fit(template: Mesh, curves: Mesh, params: serde_json::Value) -> Output {
    job::run(JobKind::Fit, vec![template, curves], params, &Progress::new()).unwrap()
}

/// Boundary loops of the mesh, by `core::topology` (not part of the fit under test).
fn boundary_loops(m: &Mesh) -> usize {
    meshwork_core::topology::Topology::new(m).boundary_loops().len()
}

/// Input segments (consecutive polyline points) whose middle is farther than 0.1 × their length
/// from every face of the output.
fn segments_off_output(curves: &Mesh, out: &Mesh) -> usize {
    let tris = out.faces.triangles();
    segments(curves)
        .filter(|(a, b)| {
            let mid = mid(*a, *b);
            let d = tris
                .iter()
                .map(|t| norm(sub(mid, closest_on_triangle(mid, &t.map(|v| out.positions[v as usize])))))
                .fold(f64::INFINITY, f64::min);
            d > 0.1 * norm(sub(*b, *a))
        })
        .count()
}

fn segments(curves: &Mesh) -> impl Iterator<Item = (Point3, Point3)> + '_ {
    let p = |v: u32| curves.positions[v as usize];
    curves.curves.iter().flat_map(|l| l.windows(2)).map(move |s| (p(s[0]), p(s[1])))
}

fn mid(a: Point3, b: Point3) -> Point3 {
    [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, (a[2] + b[2]) / 2.0]
}

/// Angle (radians) between the directions of `p` and `q` from the origin.
fn angle(p: Point3, q: Point3) -> f64 {
    dot(normalize(p), normalize(q)).clamp(-1.0, 1.0).acos()
}

/// The checks every case makes; returns the number of segments off the surface. `hole`: the
/// hole's centre when the template was not moved by an alignment (the input bounds need it).
fn check_holed(template: &Mesh, curves: &Mesh, out: &Output, hole: Option<Point3>) -> u64 {
    let m = &out.meshes[0];
    let r = &out.report;
    let rt = &r["retriangulation"];
    assert_eq!(r["regions"], 8, "retriangulation {rt}");
    assert_eq!(m.groups.len(), 8);
    let off = rt["off_surface_segments"].as_u64().unwrap();
    // Every segment not over the hole is an edge chain; the others are the failures.
    assert_eq!(rt["failed_segments"], off, "{rt}");
    assert_eq!(rt["failed_pieces"], 0);
    let segs = r["curve_segments"].as_u64().unwrap();
    let edges = r["segments_as_edges"].as_f64().unwrap();
    assert!((edges - (segs - off) as f64 / segs as f64).abs() < 1e-12, "{edges}");
    // The segments over the hole are the refusals the measure sets apart: every other one is a chain.
    let not_edges = &r["segments_not_edges"];
    assert_eq!(not_edges["total"], off, "{not_edges}");
    assert_eq!(not_edges["off_surface"], off, "{not_edges}");
    assert_eq!(not_edges["pieces"], 0, "{not_edges}");
    assert_eq!(r["segments_as_edges_realisable"], 1.0, "{r}");
    // Nothing is routed around the hole.
    assert_eq!(rt["route_long_detours"], 0, "{rt}");
    assert_eq!(r["flipped_faces"], 0);
    // The hole is still there: one boundary loop, as in the template.
    assert_eq!(boundary_loops(template), 1);
    assert_eq!(boundary_loops(m), 1);
    // No zero-area face; every curve point on the output.
    let diag = Aabb::of(&m.positions).unwrap().diagonal();
    for t in m.faces.triangles() {
        let p = |k: usize| m.positions[t[k] as usize];
        assert!(norm(cross(sub(p(1), p(0)), sub(p(2), p(0)))) > 1e-14 * diag * diag);
    }
    assert!(r["curve_residual_max_relative"].as_f64().unwrap() <= 1e-9);
    // The count on the output geometry.
    assert_eq!(segments_off_output(curves, m) as u64, off);
    let Some(hole) = hole else { return off };
    // Bounds from the input: the hole spans the directions within `inner` of its centre (every
    // removed face's centre; the template's rim vertices lie beyond `outer`). A segment whose
    // middle points inside the removed faces' centres crosses the gap for sure; one with no point
    // (ends or middle) within the rim's angle cannot.
    let rim: Vec<Point3> = {
        let tris = template.faces.triangles();
        let mut on = std::collections::HashMap::new();
        for t in &tris {
            for k in 0..3 {
                *on.entry((t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))).or_insert(0) += 1;
            }
        }
        on.iter()
            .filter(|e| *e.1 == 1)
            .flat_map(|e| [e.0 .0, e.0 .1])
            .map(|v| template.positions[v as usize])
            .collect()
    };
    let outer = rim.iter().map(|&p| angle(p, hole)).fold(0.0, f64::max);
    let inner = rim.iter().map(|&p| angle(p, hole)).fold(f64::INFINITY, f64::min);
    let sure = segments(curves).filter(|&(a, b)| angle(mid(a, b), hole) < 0.5 * inner).count() as u64;
    let touching = segments(curves)
        .filter(|&(a, b)| [a, b, mid(a, b)].iter().any(|&p| angle(p, hole) < outer))
        .count() as u64;
    assert!(sure <= off && off <= touching, "sure {sure} off {off} touching {touching}");
    off
}

fn holed(centre: Point3, radius: f64) -> Mesh {
    with_holes(&icosphere(3, 1.0), &[centre], radius)
}

#[test]
fn hole_where_two_curves_cross() {
    // The hole is around (1, 0, 0), where the sections z = 0 and y = 0 cross.
    let x = [1.0, 0.0, 0.0];
    for params in [json!({"alignment": "none"}), json!({})] {
        let (t, c) = (holed(x, 0.2), ellipsoid_sections(AXES, 6));
        let out = fit(t.clone(), c.clone(), params.clone());
        let none = params["alignment"] == "none";
        let off = check_holed(&t, &c, &out, none.then_some(x));
        assert!(off >= 1, "{params}: {}", out.report["retriangulation"]);
    }
}

#[test]
fn big_hole_under_a_curve() {
    // Around (0, √½, √½), on the section x = 0 only, 0.35 wide.
    let c0 = [0.0, 0.7071, 0.7071];
    let (t, c) = (holed(c0, 0.35), ellipsoid_sections(AXES, 6));
    let out = fit(t.clone(), c.clone(), json!({"alignment": "none"}));
    let off = check_holed(&t, &c, &out, Some(c0));
    assert!(off >= 1, "{}", out.report["retriangulation"]);
}
