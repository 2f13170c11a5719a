//! The report's `flipped_faces` against independent truths: a face counts when its normal opposes
//! the template's normal pushed forward by the fit's maps (`fit/orientation.rs`). Truths: the
//! analytic outward normal of the sphere / ellipsoid the output lies on.

use meshwork_core::fit::testdata::{
    ellipsoid_outward, ellipsoid_sections, faces_against, great_circles, polylines,
};
use meshwork_core::fit::{run, Alignment, FitPair, FitParams};
use meshwork_core::geometry::{dist, dot, normalize};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::{icosphere, octahedron};
use meshwork_core::Progress;

/// The pairs that send the unit sphere's six axis points to `image` of themselves, each through the
/// template vertex nearest to its preimage.
fn axis_pairs(template: &Mesh, image: impl Fn(Point3) -> Point3) -> Vec<FitPair> {
    // The octahedron's vertices are the six axis points.
    octahedron()
        .positions
        .iter()
        .map(|&a| {
            let v = (0..template.positions.len())
                .min_by(|&i, &j| dist(template.positions[i], a).total_cmp(&dist(template.positions[j], a)))
                .unwrap();
            FitPair { template_vertex: v as u32, curve_point: image(a) }
        })
        .collect()
}

fn fit(template: Mesh, curves: Mesh, params: &FitParams) -> meshwork_core::job::Output {
    run(vec![template, curves], params, &Progress::new()).expect("fit")
}

/// A sphere whose pairs mirror it (z ↦ −z: the coarse RBF's map is a reflection, det J < 0
/// everywhere) comes out inside out: every face points into the sphere. The report counts them
/// all, and all of them as turned by the maps; the surface-based measure (the report's before
/// session 13) saw none, because the fine surface is inside out too. Control: the same pairs
/// without the mirror, no face counted.
#[test]
fn a_template_mirrored_by_its_pairs_is_counted_inside_out() {
    let curves = polylines(&great_circles(1.0, 64, [0.0; 3]));
    let template = icosphere(3, 1.0);
    let outward = ellipsoid_outward([1.0, 1.0, 1.0]);
    let mirror = |p: Point3| [p[0], p[1], -p[2]];
    let params =
        FitParams { alignment: Alignment::Pairs, pairs: axis_pairs(&template, mirror), ..Default::default() };
    let out = fit(template.clone(), curves.clone(), &params);
    let (m, r) = (&out.meshes[0], &out.report);
    let faces = m.faces.triangles().len();
    let inward = faces_against(m, &outward).len();
    assert!(inward * 100 >= faces * 99, "the case: {inward} of {faces} faces point inward");
    assert_eq!(r["flipped_faces"], inward, "report {}", r["flipped_faces"]);
    assert!(
        r["faces_inverted_by_maps"].as_u64().unwrap() as usize * 100 >= faces * 99,
        "{}",
        r["faces_inverted_by_maps"]
    );
    assert!(r["flipped_faces_against_fine_surface"].as_u64().unwrap() * 10 < faces as u64);

    let params =
        FitParams { alignment: Alignment::Pairs, pairs: axis_pairs(&template, |p| p), ..Default::default() };
    let out = fit(template, curves, &params);
    assert_eq!(faces_against(&out.meshes[0], &outward).len(), 0);
    assert_eq!(out.report["flipped_faces"], 0);
    assert_eq!(out.report["faces_inverted_by_maps"], 0);
}

/// A template turned by 150° against its curves: the automatic alignment turns it back (a
/// rotation, legitimate however large), so no face is counted, as the ellipsoid's own normal
/// says; the template's raw normals would oppose most of the output.
#[test]
fn a_template_turned_by_150_degrees_counts_no_face() {
    let axes = [1.4, 1.15, 0.9];
    let curves = ellipsoid_sections(axes, 12);
    let mut template = icosphere(4, 1.0);
    let axis = normalize([1.0, 1.0, 0.3]);
    let (s, c) = 150f64.to_radians().sin_cos();
    for p in &mut template.positions {
        let q = [p[0] * axes[0], p[1] * axes[1], p[2] * axes[2]];
        // Rodrigues: q cos + (k × q) sin + k (k · q)(1 − cos), then shifted.
        let kxq = [
            axis[1] * q[2] - axis[2] * q[1],
            axis[2] * q[0] - axis[0] * q[2],
            axis[0] * q[1] - axis[1] * q[0],
        ];
        let kq = dot(axis, q);
        *p = [0, 1, 2].map(|k| q[k] * c + kxq[k] * s + axis[k] * kq * (1.0 - c) + 0.3);
    }
    let out = fit(template, curves, &FitParams::default());
    let m = &out.meshes[0];
    assert_eq!(faces_against(m, ellipsoid_outward(axes)).len(), 0);
    assert_eq!(out.report["flipped_faces"], 0);
    assert_eq!(out.report["faces_inverted_by_maps"], 0);
}
