//! Fits where the curves turn faster than the template's faces are long: a sphere reaching into
//! spot's legs, ears and muzzle, and the rim of a flattened ellipsoid. Truth: the region count the
//! section planes cut the source surface into (counted on a finer copy, independently of the fit).
//! The thin rim is open (an ignored repro); see docs/benchmarks.md, "Thin shapes" (fit-shapes,
//! session 7). Spot is fixed by the approach's field refinement (fit-field, session 8).

use meshwork_core::fit::testdata::{
    bend, plane_sections, section_regions, sweep_planes, to_unit_box, TruthSurface,
};
use meshwork_core::fit::{run, FitParams};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::mesh::Mesh;
use meshwork_core::repair::{self, RepairParams};
use meshwork_core::shapes::icosphere;
use meshwork_core::Progress;

fn spot_unit() -> Mesh {
    let bytes = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/meshes/spot.obj"))
        .or_else(|_| std::fs::read("../../shared/meshes/spot.obj"))
        .expect("spot.obj in ../shared/meshes");
    let raw =
        read(&bytes, &ReadOptions { name_hint: Some("x.obj".into()), ..Default::default() }).unwrap().mesh;
    let params = RepairParams { fill_holes: false, ..Default::default() };
    let mut m = repair::run(raw, &params, &Progress::new()).unwrap().meshes.remove(0);
    to_unit_box(&mut m);
    m
}

/// Fixed by the approach's field refinement (`fit/field_refine.rs`; 21 flipped faces without it).
#[test]
fn a_sphere_reaches_spots_legs_without_folds() {
    // sweep_unseen's "icosphere vs sections of spot (auto)".
    let spot = spot_unit();
    let planes = sweep_planes(&spot);
    let expected = section_regions(&spot, &planes);
    let curves = plane_sections(&spot, &planes);
    let mut t = icosphere(3, 0.5);
    for p in &mut t.positions {
        *p = [p[0] + 0.5, p[1] + 0.5, p[2] + 0.5];
    }
    let out = run(vec![t, curves], &FitParams::default(), &Progress::new()).expect("fit");
    let r = &out.report;
    assert_eq!(r["segments_as_edges"].as_f64(), Some(1.0));
    assert_eq!(r["regions"].as_u64(), Some(expected as u64));
    // Against spot's own surface (an independent truth: the output's faces whose normal opposes
    // that of the closest face of spot). The test was first written against the fine surface's
    // vertex normals (0 until session 17, 21 without the field refinement), a measure the last
    // repairs knowingly trade away: measured in session 20, one round of flip sequences 123 faces
    // against spot (fine surface 1), three rounds 124 (2), the steep faces flipped 118 (4), while
    // `flipped_faces` fell 29 → 27 → 25 and folded edges 6 → 6 → 4. The bound is the level before
    // those changes.
    let against_spot = TruthSurface::new(&spot).faces_against(&out.meshes[0]);
    assert!(against_spot <= 124, "{against_spot} faces against spot's surface");
    assert!(
        r["folds"]["output"]["folded_edges"].as_u64().is_some_and(|n| n <= 6),
        "{}",
        r["folds"]["output"]
    );
    // The approach converged: its last level started within the median segment of the curves.
    let last = r["fine"]["approach"]["distance_max"].as_array().unwrap().last().unwrap().as_f64().unwrap();
    assert!(last < 0.02, "approach left {last}");
}

/// The flattened ellipsoid 1 × 0.6 × `thick` (an icosphere of `level`) centred at (0.5, 0.5, 0.5).
fn flat(level: u32, thick: f64) -> Mesh {
    let mut m = icosphere(level, 0.5);
    for p in &mut m.positions {
        *p = [p[0] + 0.5, 0.5 + 0.6 * p[1], 0.5 + thick * p[2]];
    }
    m
}

/// sweep_unseen's "flat icosphere 4 vs sections of ellipsoid 1×0.6×0.04": the template is the
/// source's shape at a coarser level. The alignment's warp trimmed the curve points at the tips
/// (its cut, 2.5 × the median distance, was ~7.5e-5 where the sheets fit), left the template 0.0037
/// too far along its long axis, and the fit folded the rim. Fixed by the warp's trim floor
/// (`fit/align/warp.rs`, `TRIM_FLOOR_SEGMENTS`, `TRIM_FLOOR_SAGS`). Counted independently, against
/// the ellipsoid's normal: without the floor 100 output faces turned over (the report, against the
/// fine surface: 14); with it 2 (the floor alone, without its sag rule: 0, but that moved a faceted
/// template off its exact place, see fit_align's `the_warp_does_not_chase_a_templates_faceting`).
/// The bound leaves room for the thin rim's sensitivity to the floor (session 11: floors of 1 / 1.25
/// / 1.5 / 2 / 3 segments gave 5 / 0 / 0 / 3 / 3 flipped faces) and still fails without the floor.
#[test]
fn the_alignment_keeps_a_thin_template_rim_on_the_sections() {
    let surface = flat(5, 0.04);
    let planes = sweep_planes(&surface);
    let curves = plane_sections(&surface, &planes);
    let out = run(vec![flat(4, 0.04), curves], &FitParams::default(), &Progress::new()).expect("fit");
    let r = &out.report;
    assert_eq!(r["regions"].as_u64(), Some(section_regions(&surface, &planes) as u64));
    assert_eq!(r["segments_as_edges"].as_f64(), Some(1.0));
    assert_eq!(r["flipped_faces_against_fine_surface"].as_u64(), Some(0));
    let turned = against_the_ellipsoid(&out.meshes[0], 0.04);
    assert!(turned <= 4, "{turned} output faces turned against the ellipsoid's normal (no floor: 100)");
    // The report's count against the template's normal carried by the fit's maps (session 13):
    // never above the analytic count here (2 and 2; against the fine surface: 0).
    let flipped = r["flipped_faces"].as_u64().unwrap_or(u64::MAX) as usize;
    assert!(flipped <= turned, "report {flipped}, against the ellipsoid {turned}");
}

/// Faces of `m` whose normal opposes the normal of the ellipsoid 1 × 0.6 × `thick` centred at
/// (0.5, 0.5, 0.5), taken as its gradient at the face's centroid.
fn against_the_ellipsoid(m: &Mesh, thick: f64) -> usize {
    let axes2 = [0.25, 0.09, thick * thick / 4.0];
    m.faces
        .triangles()
        .iter()
        .filter(|t| {
            let p: Vec<[f64; 3]> = t.iter().map(|&v| m.positions[v as usize]).collect();
            let grad: Vec<f64> =
                (0..3).map(|k| ((p[0][k] + p[1][k] + p[2][k]) / 3.0 - 0.5) / axes2[k]).collect();
            let u: Vec<f64> = (0..3).map(|k| p[1][k] - p[0][k]).collect();
            let v: Vec<f64> = (0..3).map(|k| p[2][k] - p[0][k]).collect();
            let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            n[0] * grad[0] + n[1] * grad[1] + n[2] * grad[2] < 0.0
        })
        .count()
}

#[test]
#[ignore = "open: thin rims fold (session 11: 181 flipped faces, 16 of 20 regions); see docs/benchmarks.md, 'Thin shapes'"]
fn a_flat_template_fits_bent_sections_of_a_thin_ellipsoid() {
    let surface = flat(5, 0.04);
    let planes = sweep_planes(&surface);
    let expected = section_regions(&surface, &planes);
    let mut curves = plane_sections(&surface, &planes);
    for p in &mut curves.positions {
        *p = bend(*p, 1.0);
    }
    let out = run(vec![flat(4, 0.04), curves], &FitParams::default(), &Progress::new()).expect("fit");
    let r = &out.report;
    assert_eq!(r["regions"].as_u64(), Some(expected as u64));
    assert_eq!(r["flipped_faces"].as_u64(), Some(0));
    assert_eq!(r["segments_as_edges"].as_f64(), Some(1.0));
}

/// Three great circles of 48 points on the unit sphere (sharing the 6 axis points: 3·48 − 6 = 138
/// curve vertices) and a level-3 icosphere (1,280 triangles): the face guard's base is
/// 1,280 + 8 · 138 = 2,384 faces.
fn octants() -> Vec<Mesh> {
    use meshwork_core::fit::testdata::{great_circles, polylines};
    vec![icosphere(3, 1.0), polylines(&great_circles(1.0, 48, [0.0; 3]))]
}

#[test]
fn a_fit_past_its_face_budget_stops_naming_the_stage() {
    // Half the base (1,192) is below the template's own 1,280 triangles: the guard trips as soon
    // as the fine stage's mesh is built.
    let params = FitParams { max_face_growth: 0.5, ..Default::default() };
    let err = match run(octants(), &params, &Progress::new()) {
        Err(e) => e,
        Ok(_) => panic!("a fit with 1,192 faces allowed went through"),
    };
    let text = err.to_string();
    match err {
        meshwork_core::Error::TooLarge { limit, actual, .. } => {
            assert_eq!(limit, 1192, "{text}");
            // The template's triangles plus the insertion's splits (each adds faces).
            assert!(actual > 1280, "{text}");
        }
        other => panic!("expected too-large, got {other:?}"),
    }
    assert!(text.contains("stage `fine`") && text.contains("max_face_growth"), "{text}");
}

#[test]
fn the_default_face_budget_leaves_an_ordinary_fit_alone() {
    let out = run(octants(), &FitParams::default(), &Progress::new()).expect("fit");
    let r = &out.report;
    assert_eq!(r["regions"].as_u64(), Some(8));
    assert_eq!(r["face_growth"]["base"].as_u64(), Some(2384));
    let peak = r["face_growth"]["peak_faces"].as_u64().unwrap();
    // At least the template's faces, and the output never has more than the peak.
    assert!(peak >= 1280 && r["output_faces"].as_u64().unwrap() <= peak, "peak {peak}");
    assert!(peak < 2384, "an 8-octant fit used {peak} faces");
}

#[test]
fn max_face_growth_must_be_positive() {
    for bad in [0.0, -1.0, f64::NAN] {
        let params = FitParams { max_face_growth: bad, ..Default::default() };
        let err = run(octants(), &params, &Progress::new()).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(err.contains("max_face_growth"), "{bad}: {err}");
    }
}
