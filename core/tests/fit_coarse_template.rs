//! The "different template: a coarse shared mesh". A shared mesh (repaired, unit box) is
//! cut by the sweep's six planes; the template is the same mesh simplified to 1,000 vertices by
//! quadric half-edge collapses that keep it a closed manifold of its genus (`morph::simplify`), and
//! the automatic alignment places it. Truths: the planes cut the fine surface into
//! `section_regions` regions (counted on the fine mesh, not by the fit); every curve vertex is a
//! vertex of the output; the output lies near the fine surface (with `smooth_hold_creases_deg` 30,
//! which keeps smoothing from sliding vertices off the coarse copy's creases).

mod fit_support;

use meshwork_core::fit::testdata::{plane_sections, section_regions, sweep_planes, TruthSurface};
use meshwork_core::job::{self, JobKind};
use meshwork_core::mesh::Mesh;
use meshwork_core::morph::simplify::Hierarchy;
use meshwork_core::Progress;

/// `fine` simplified to `vertices` vertices.
fn coarse_copy(fine: &Mesh, vertices: usize) -> Mesh {
    let mut h = Hierarchy::new(&fine.positions, &fine.faces.triangles());
    h.simplify(vertices, true, &Progress::new()).expect("simplify");
    let (map, tris) = h.current();
    Mesh::from_triangles(map.iter().map(|&v| fine.positions[v as usize]).collect(), &tris)
}

fn fits_its_coarse_copy(name: &str, flips_allowed: u64) {
    let fine = fit_support::load_repaired(name);
    let planes = sweep_planes(&fine);
    let curves = plane_sections(&fine, &planes);
    let regions = section_regions(&fine, &planes);
    let template = coarse_copy(&fine, 1000);
    // How well the coarse copy approximates the fine surface: the largest distance from a fine
    // vertex to it (its own vertices are fine vertices, so the other side is 0).
    let approximation = TruthSurface::new(&template).max_distance(&fine);
    let out = job::run(
        JobKind::Fit,
        vec![template, curves],
        serde_json::json!({"smooth_hold_creases_deg": 30}),
        &Progress::new(),
    )
    .expect("fit");
    let r = &out.report;
    let off = TruthSurface::new(&fine).max_distance(&out.meshes[0]);
    // The other side: the largest distance from a fine vertex to the output.
    let cut = TruthSurface::new(&out.meshes[0]).max_distance(&fine);
    eprintln!(
        "{name}: regions {} (want {regions}) edges {} flips {}; coarse copy within {approximation:.4} of the fine surface, output vertices within {off:.4}, fine vertices within {cut:.4} of the output",
        r["regions"], r["segments_as_edges"], r["flipped_faces"]
    );
    assert_eq!(r["regions"].as_u64(), Some(regions as u64), "{}", r["segments_not_edges"]);
    assert_eq!(r["segments_as_edges"], 1.0, "{}", r["segments_not_edges"]);
    assert!(r["curve_residual_max_relative"].as_f64().expect("residual") <= 1e-9);
    assert!(r["flipped_faces"].as_u64().is_some_and(|n| n <= flips_allowed), "{}", r["flipped_faces_at"]);
    // The output's vertices are curve vertices (on the fine surface) or template vertices moved by
    // the fit's maps and smoothing: none ends farther from the fine surface than the coarse copy's
    // own approximation error. (Rocker-arm: 0.0131 against 0.0097 while smoothing's second stage
    // projected onto the surface after its first; 0.0073 since session 22.)
    // And the fine surface stays near the output: smoothing slides vertices off creases and tips
    // (the chords then cut them): 0.0344 (spot) and 0.0272 (rocker-arm) without holding the
    // template's creases, 2.4 and 2.8 × the coarse copy's own; 0.0133 and 0.0106 with them held.
    assert!(
        cut <= 1.5 * approximation,
        "fine vertices {cut:.4} from the output, coarse copy {approximation:.4}"
    );
    assert!(
        off <= approximation,
        "output vertices {off:.4} from the fine surface, the coarse copy {approximation:.4}"
    );
}

#[test]
fn a_coarse_rocker_arm_is_fitted_to_the_fine_ones_sections() {
    // Genus 1: the coarse copy keeps the hole, so the region count must match the fine one's.
    fits_its_coarse_copy("rocker-arm", 0);
}

#[test]
fn a_coarse_spot_is_fitted_to_the_fine_ones_sections() {
    // One face near the tip of a horn, where the 1,000-vertex copy's faces point every way: 0 from
    // the pose ICP reached from the PCA starts, 1 since ICP also starts from the pose as placed
    // (session 23; the same face in `sweep_unseen`'s row with default options, and 0 there again
    // from the CLI on the row's inputs written to OBJ and read back). Chaotic at that scale; a
    // second face is a regression.
    fits_its_coarse_copy("spot", 1);
}
