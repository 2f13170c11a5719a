//! The fit endpoint with session 8's unseen inputs (see core/tests/fit_unseen8.rs): curves as glTF
//! LINE_STRIPs placed by node transforms, in other units than the template (100×), and a pair point
//! at 1e300. Truths: the octants (8 regions, counted by hand), the welds of the 6 axis points shared
//! by two strips each plus the 3 closing points (9), and the problem naming the pair.

mod common;

use common::{inline_report, post_fit_on_icosphere, Server};
use meshwork_core::fit::testdata::{ellipsoid_sections, gltf_strips_with_nodes};

const AXES: [f64; 3] = [1.4, 1.15, 0.9];

#[test]
fn gltf_strips_under_node_transforms_in_other_units() {
    let s = Server::start(&[]);
    let c = ellipsoid_sections(AXES, 6);
    let lines: Vec<Vec<[f64; 3]>> = c
        .curves
        .iter()
        .map(|l| l.iter().map(|&v| c.positions[v as usize].map(|x| x * 100.0)).collect())
        .collect();
    let r = inline_report(&post_fit_on_icosphere(&s, "c.gltf", &gltf_strips_with_nodes(&lines), "{}"));
    assert_eq!(r["regions"], 8, "{}", r["network"]);
    assert_eq!(r["segments_as_edges"], 1.0);
    assert_eq!(r["flipped_faces"], 0);
    assert_eq!(r["network"]["welded_points"], 9);
    assert!(r["network"]["welded_max_distance"].as_f64().unwrap() > 0.0);
}

#[test]
fn a_pair_point_at_1e300_is_a_problem_naming_the_pair() {
    let s = Server::start(&[]);
    let c = ellipsoid_sections(AXES, 6);
    let lines: Vec<Vec<[f64; 3]>> =
        c.curves.iter().map(|l| l.iter().map(|&v| c.positions[v as usize]).collect()).collect();
    let params = r#"{"pairs": [
        {"template_vertex": 0, "curve_point": [1.4, 0, 0]},
        {"template_vertex": 5, "curve_point": [0, 1.15, 0]},
        {"template_vertex": 9, "curve_point": [0, 0, 0.9]},
        {"template_vertex": 11, "curve_point": [1e300, 0, 0]}]}"#;
    let r = post_fit_on_icosphere(&s, "c.gltf", &gltf_strips_with_nodes(&lines), params);
    assert!((400..500).contains(&r.status), "{} {}", r.status, r.text());
    assert_eq!(r.header("content-type"), Some("application/problem+json"));
    let text = r.json().to_string();
    assert!(text.contains("pairs[3].curve_point"), "{text}");
    assert!(!text.contains("internal"), "{text}");
}
