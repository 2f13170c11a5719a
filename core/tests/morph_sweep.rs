//! Regressions found by the morph sweep (`core/examples/sweep_morph.rs`): cases the shared meshes
//! never produced. Truths: analytic shapes, the area of the unit sphere (an overlay of two
//! embeddings covers it exactly once), brute-force closest points, the input vertices themselves.

use meshwork_core::geometry::{cross, dot, norm, normalize, sub};
use meshwork_core::job::{self, JobKind, Progress};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::morph::metamesh::{self, Layer};
use meshwork_core::morph::overlay_degenerate;
use meshwork_core::shapes::{cube, icosphere, octahedron as octa, tetrahedron as tetra};
use meshwork_core::spatial::closest_on_triangle;
use serde_json::json;

mod morph_support;
use morph_support::ellipsoid;

fn tris_of(m: &Mesh) -> Vec<[u32; 3]> {
    m.faces.iter().map(|f| [f[0], f[1], f[2]]).collect()
}

/// A convex polyhedron about the origin, radially projected: its own spherical embedding.
fn layer(m: &Mesh) -> Layer {
    let sphere: Vec<Point3> = m.positions.iter().map(|&p| normalize(p)).collect();
    Layer { sphere, tris: tris_of(m), shapes: vec![m.positions.clone()] }
}

/// Signed area of the spherical triangle (Van Oosterom–Strackee).
fn spherical_area(a: Point3, b: Point3, c: Point3) -> f64 {
    2.0 * dot(a, cross(b, c)).atan2(1.0 + dot(a, b) + dot(b, c) + dot(c, a))
}

fn max_dist_brute(pts: &[Point3], pos: &[Point3], tris: &[[u32; 3]]) -> f64 {
    pts.iter()
        .map(|&p| {
            tris.iter()
                .map(|t| {
                    let tri = [pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]];
                    norm(sub(p, closest_on_triangle(p, &tri)))
                })
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

fn diag(p: &[Point3]) -> f64 {
    meshwork_core::geometry::Aabb::of(p).expect("non-empty").diagonal()
}

/// Overlay of two very coarse embeddings (tetrahedron, octahedron: arcs of 90°–110°). The
/// crossing test must not assume short arcs. Truth: the overlay covers the sphere once
/// (spherical areas sum to 4π, none negative) and keeps all 4 + 6 input vertices.
#[test]
fn overlay_of_long_arcs_covers_the_sphere_once() {
    // In general position (octahedron turned about a generic axis): the plain overlay.
    let turned = {
        let mut m = octa();
        let (s, c) = 0.3f64.sin_cos();
        for p in &mut m.positions {
            *p = [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
            let (s2, c2) = 0.5f64.sin_cos();
            *p = [p[0], c2 * p[1] - s2 * p[2], s2 * p[1] + c2 * p[2]];
        }
        m
    };
    check_covers(
        &metamesh::overlay(&layer(&tetra()), &layer(&turned), &Progress::new()).expect("plain overlay").0,
        &turned,
    );
    // As given, octahedron vertices lie exactly on tetrahedron arcs (plane y = z holds (1,0,0)).
    let (o, _, angle) =
        overlay_degenerate::overlay(&layer(&tetra()), &layer(&octa()), &Progress::new()).expect("overlay");
    assert!(angle <= 1e-4);
    check_covers(&o, &octa());
}

fn check_covers(o: &Layer, oc: &Mesh) {
    let areas: Vec<f64> = o
        .tris
        .iter()
        .map(|t| spherical_area(o.sphere[t[0] as usize], o.sphere[t[1] as usize], o.sphere[t[2] as usize]))
        .collect();
    assert!(areas.iter().all(|&x| x > -1e-12), "negative spherical area: {areas:?}");
    let total: f64 = areas.iter().sum();
    assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-9, "total area {total}");
    assert!(o.sphere.len() >= 10, "{} vertices", o.sphere.len());
    // Every overlay vertex in shape 0 lies on the tetrahedron, in shape 1 on the octahedron.
    let t = tetra();
    assert!(max_dist_brute(&o.shapes[0], &t.positions, &tris_of(&t)) < 1e-12);
    assert!(max_dist_brute(&o.shapes[1], &oc.positions, &tris_of(&oc)) < 1e-12);
}

/// Morph job between a tetrahedron and a cube: the end frames must be the inputs (the overlay,
/// not the barycentric transfer that only samples the target at 4 points).
#[test]
fn coarse_polyhedra_morph_reproduces_both_ends() {
    let cube = cube();
    for (a, b) in [(tetra(), octa()), (tetra(), cube.clone())] {
        let o = job::run(
            JobKind::Morph,
            vec![a.clone(), b.clone()],
            json!({"registration": "none", "frames": 3}),
            &Progress::new(),
        )
        .expect("morph");
        assert_eq!(o.report["correspondence"], "overlay", "{}", o.report["correspondence_fallback"]);
        let last = &o.meshes[1];
        let lt = tris_of(last);
        let d = max_dist_brute(&last.positions, &b.positions, &tris_of(&b)).max(max_dist_brute(
            &b.positions,
            &last.positions,
            &lt,
        ));
        assert!(d / diag(&b.positions) < 1e-9, "last frame off the target by {d}");
    }
}

/// Feature pairs meet exactly on the sphere, so A- and B-vertices coincide there: the overlay
/// must still be built (no silent fall-back to the transfer), the last frame must be the
/// target and each source feature vertex must arrive on its target feature vertex.
#[test]
fn features_keep_the_overlay_and_meet() {
    let a = icosphere(2, 1.0);
    let b = ellipsoid(2, [2.0, 1.0, 0.5]);
    let pairs = [[0u32, 3u32], [5, 9], [11, 40]];
    let feats: Vec<Vec<u32>> = pairs.iter().map(|p| p.to_vec()).collect();
    let o = job::run(
        JobKind::Morph,
        vec![a.clone(), b.clone()],
        json!({"registration": "none", "frames": 3, "features": feats}),
        &Progress::new(),
    )
    .expect("morph");
    assert_eq!(o.report["correspondence"], "overlay", "{}", o.report["correspondence_fallback"]);
    let (first, last) = (&o.meshes[0], &o.meshes[1]);
    let d = max_dist_brute(&last.positions, &b.positions, &tris_of(&b)).max(max_dist_brute(
        &b.positions,
        &last.positions,
        &tris_of(last),
    ));
    assert!(d / diag(&b.positions) < 1e-9, "last frame off the target by {d}");
    let scale = diag(&b.positions);
    for [va, vb] in pairs {
        // The metamesh vertex that is source vertex va in frame 0 …
        let pa = a.positions[va as usize];
        let m = (0..first.positions.len())
            .min_by(|&i, &j| norm(sub(first.positions[i], pa)).total_cmp(&norm(sub(first.positions[j], pa))))
            .expect("vertices");
        assert!(norm(sub(first.positions[m], pa)) < 1e-12);
        // … ends on target vertex vb.
        let gap = norm(sub(last.positions[m], b.positions[vb as usize])) / scale;
        assert!(gap < 1e-4, "feature {va}->{vb} misses by {gap} of the diagonal");
    }
}

/// A mesh morphed to itself: every vertex of A sits on a vertex of B and every edge on an edge.
/// The overlay is A itself; both ends must be the input.
#[test]
fn self_morph_keeps_the_overlay() {
    let a = ellipsoid(2, [1.5, 1.0, 0.6]);
    let o = job::run(
        JobKind::Morph,
        vec![a.clone(), a.clone()],
        json!({"registration": "none", "frames": 3}),
        &Progress::new(),
    )
    .expect("morph");
    assert_eq!(o.report["correspondence"], "overlay", "{}", o.report["correspondence_fallback"]);
    for m in &o.meshes {
        let d = max_dist_brute(&m.positions, &a.positions, &tris_of(&a)).max(max_dist_brute(
            &a.positions,
            &m.positions,
            &tris_of(m),
        ));
        assert!(d / diag(&a.positions) < 1e-9, "frame off the input by {d}");
    }
}

/// PCA sign rule: a rotated, scaled and moved copy of a shape has the same normalised form
/// (truth: the copy's construction). Checked on an asymmetric analytic shape and on homer.
#[test]
fn pca_frame_is_invariant_under_similarity() {
    let k = normalize([1.0, 2.0, 3.0]);
    let (s, c) = 0.7f64.sin_cos();
    let similar = |p: Point3| -> Point3 {
        let kxp = cross(k, p);
        let kdp = dot(k, p);
        let r: Vec<f64> = (0..3).map(|i| p[i] * c + kxp[i] * s + k[i] * kdp * (1.0 - c)).collect();
        [3.5 * r[0] + 10.0, 3.5 * r[1], 3.5 * r[2] - 4.0]
    };
    // An egg: ellipsoid with one end fatter (third moments non-zero on every axis).
    let mut egg = ellipsoid(3, [2.0, 1.0, 0.6]);
    for p in &mut egg.positions {
        let f = 1.0 + 0.25 * p[0] + 0.15 * p[1] + 0.1 * p[2];
        *p = [p[0], p[1] * f, p[2] * f];
    }
    let homer = {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes/homer.obj");
        let bytes = std::fs::read(&p).expect("homer.obj");
        meshwork_core::io::read(&bytes, &Default::default()).expect("readable").mesh
    };
    for m in [egg, homer] {
        let t = tris_of(&m);
        let copy: Vec<Point3> = m.positions.iter().map(|&p| similar(p)).collect();
        let fa = meshwork_core::register::pca_frame(&m.positions, &t).to_normalised;
        let fb = meshwork_core::register::pca_frame(&copy, &t).to_normalised;
        let d = m
            .positions
            .iter()
            .zip(&copy)
            .map(|(&p, &q)| norm(sub(fa.apply(p), fb.apply(q))))
            .fold(0.0, f64::max);
        assert!(d < 1e-9, "normalised copies differ by {d}");
    }
}

/// Planar domain, one interior feature pair (woody vertex 300, alligator vertex 1500, both off the
/// rim): the pair must meet (truth: the request itself), so the metamesh vertex that is woody's
/// vertex 300 in the first frame is alligator's vertex 1500 in the last.
/// KNOWN FAILURE (gap 0.08 in plane units): the pair's goal lies near the rim (r ≈ 0.93) and
/// the stepwise planar warp flips a rim triangle at every step size (the rim vertices are dragged
/// and projected back; fading the warp out towards a fixed rim only gets the gap to 0.048, as the
/// band between feature and rim must be compressed, not translated). For the planar domain's
/// owner; run with `--ignored`.
#[test]
#[ignore = "known failure: planar feature warp toward the rim stalls (docs/benchmarks.md, Morph sweep)"]
fn planar_interior_feature_pair_meets() {
    let load = |n: &str| {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../shared/meshes/{n}.obj"));
        meshwork_core::io::read(&std::fs::read(&p).expect("mesh file"), &Default::default())
            .expect("readable")
            .mesh
    };
    let (a, b) = (load("woody"), load("alligator"));
    let o = job::run(
        JobKind::Morph,
        vec![a.clone(), b.clone()],
        json!({"frames": 3, "repair": true, "registration": "none", "features": [[300, 1500]]}),
        &Progress::new(),
    )
    .expect("morph");
    assert_eq!(o.report["domain"], "planar");
    let gap = o.report["features"]["max_feature_gap_after"].as_f64().expect("gap");
    assert!(gap < 1e-6, "feature gap after the warp {gap}");
    let (first, last) = (&o.meshes[0], &o.meshes[1]);
    let pa = a.positions[300];
    let m = (0..first.positions.len())
        .min_by(|&i, &j| norm(sub(first.positions[i], pa)).total_cmp(&norm(sub(first.positions[j], pa))))
        .expect("vertices");
    assert!(norm(sub(first.positions[m], pa)) < 1e-9 * diag(&a.positions));
    let miss = norm(sub(last.positions[m], b.positions[1500])) / diag(&b.positions);
    assert!(miss < 1e-4, "woody 300 ends {miss} of the diagonal from alligator 1500");
}
