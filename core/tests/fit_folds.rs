//! The report's reference-free fold measure (`folded_edges`, `folds`) against independent truths:
//! on an analytic case (an icosphere fitted through principal sections of an ellipsoid) the output
//! is a smooth convex surface, so no two adjacent faces may fold back onto each other, and the
//! count must agree with a dihedral check made here from the output mesh alone; on a grid with one
//! vertex pushed across its ring (faces turned over by construction) the measure must see it.

use meshwork_core::fit::testdata::ellipsoid_sections;
use meshwork_core::fit::untangle::{fold_stats, FOLD_ANGLE_DEG};
use meshwork_core::fit::{run, FitParams};
use meshwork_core::geometry::{dot, triangle_cross};
use meshwork_core::shapes::{fan_triangles, grid, icosphere};
use meshwork_core::Progress;

/// Edges whose two faces' normals are more than `deg` apart, counted from scratch.
fn folded_edges_by_hand(pos: &[[f64; 3]], tris: &[[u32; 3]], deg: f64) -> usize {
    let mut by_edge: std::collections::HashMap<(u32, u32), Vec<usize>> = Default::default();
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let n = |f: usize| {
        let t = tris[f];
        triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize])
    };
    by_edge
        .values()
        .filter(|fs| fs.len() == 2)
        .filter(|fs| {
            let (a, b) = (n(fs[0]), n(fs[1]));
            dot(a, b) / (dot(a, a) * dot(b, b)).sqrt() < deg.to_radians().cos()
        })
        .count()
}

#[test]
fn an_ellipsoid_fit_has_no_folded_edge_and_the_report_says_so() {
    let curves = ellipsoid_sections([1.4, 1.15, 0.9], 10);
    let params = FitParams::default();
    let out = run(vec![icosphere(3, 1.0), curves], &params, &Progress::new()).expect("fit");
    let m = &out.meshes[0];
    let tris = fan_triangles(&m.faces);
    let by_hand = folded_edges_by_hand(&m.positions, &tris, FOLD_ANGLE_DEG);
    assert_eq!(by_hand, 0, "the fit folded {by_hand} edges of a convex surface");
    assert_eq!(out.report["folded_edges"], 0, "{}", out.report["folds"]);
    assert_eq!(out.report["folds"]["template"]["folded_edges"], 0);
    // A convex smooth surface: adjacent normals stay well apart from a fold.
    let max = out.report["folds"]["output"]["max_normal_angle_deg"].as_f64().unwrap();
    assert!(max < 90.0, "largest angle between adjacent normals {max}°");
}

#[test]
fn a_vertex_pushed_across_its_ring_is_seen_as_folds() {
    let g = grid(6, 6, 1.0, false);
    let tris = fan_triangles(&g.faces);
    let mut pos = g.positions.clone();
    let v = 3 * 7 + 3; // the centre vertex (3, 3) of the 7×7 vertex grid
    pos[v][0] += 1.7; // beyond its neighbours at x = 4
    let by_hand = folded_edges_by_hand(&pos, &tris, FOLD_ANGLE_DEG);
    let s = fold_stats(&pos, &tris);
    assert!(by_hand > 0);
    assert_eq!(s.folded_edges, by_hand);
    assert_eq!(fold_stats(&g.positions, &tris).folded_edges, 0);
}
