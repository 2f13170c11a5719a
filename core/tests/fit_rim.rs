//! Failure classes at the end of the pipeline (fit-rim): what the smoothing may do to faces.
//!
//! A dense template (an icosphere of 20,480 faces) fitted through 12 chords of 90° arcs on the
//! ellipsoid 1.4 × 1.15 × 0.9 (its three coordinate sections with one point per quadrant: the
//! six axis points). Was 1 flipped face (the report's `flipped_faces`: a face against the sum of
//! its corners' reference normals, those of the surface after the fine stage), made by the
//! smoothing (0 before it): its guard compares each step with the face before that step, so a
//! face in the crease along a chord, already steep to the reference, tilted past 90° from it by
//! small steps. Fixed by `smooth::undo_new_flips` (the moved corners of a face the smoothing
//! turned against the reference go back where they were).
//!
//! Truths independent of the fit's report: the three coordinate planes cut a closed surface
//! around the origin into 8 octant regions; and the same fit without smoothing is the surface
//! before smoothing, so every face present in both (same three vertices) must face the same way
//! in both (smoothing slides vertices along the surface; it never turns a face over). That check
//! held before the fix too (the face was not turned against its own normal before smoothing, only
//! against the reference); the report's count is what failed, and is asserted as the goal.

use std::collections::HashMap;

use meshwork_core::fit::testdata::ellipsoid_sections;
use meshwork_core::fit::{run, FitParams};
use meshwork_core::geometry::{dot, triangle_cross};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::icosphere;
use meshwork_core::Progress;

fn fit(smooth: bool) -> (Mesh, serde_json::Value) {
    let template = icosphere(5, 1.0);
    let curves = ellipsoid_sections([1.4, 1.15, 0.9], 1);
    assert_eq!(curves.positions.len(), 6, "the six axis points");
    let params = FitParams { smooth, ..Default::default() };
    let mut out = run(vec![template, curves], &params, &Progress::new()).expect("fit");
    (out.meshes.remove(0), out.report)
}

/// Normal of every face by its sorted vertex triple.
fn normals(m: &Mesh) -> HashMap<[u32; 3], Point3> {
    m.faces
        .iter()
        .map(|f| {
            let mut key = [f[0], f[1], f[2]];
            key.sort_unstable();
            let p = |k: usize| m.positions[f[k] as usize];
            (key, triangle_cross(p(0), p(1), p(2)))
        })
        .collect()
}

#[test]
fn smoothing_a_dense_template_through_octant_chords_turns_no_face_over() {
    let (rough, _) = fit(false);
    let (smooth, r) = fit(true);
    assert_eq!(r["regions"], 8);
    assert_eq!(r["segments_as_edges"], 1.0);
    let before = normals(&rough);
    let after = normals(&smooth);
    let common: Vec<_> = after.keys().filter(|k| before.contains_key(*k)).collect();
    // Smoothing changes the faces only by the untangling's few edge flips.
    assert!(common.len() * 10 > after.len() * 9, "{} of {} faces in common", common.len(), after.len());
    let turned = common.iter().filter(|k| dot(before[**k], after[**k]) <= 0.0).count();
    assert_eq!(turned, 0, "{turned} faces turned over by the smoothing");
    // Against the fine surface: the measure this test was written for; `flipped_faces` (against the
    // template's normal carried by the fit's maps, session 13) counts 1 here (docs/benchmarks.md, fit-flipcount).
    assert_eq!(r["flipped_faces_against_fine_surface"], 0, "smoothing {}", r["smoothing"]);
}
