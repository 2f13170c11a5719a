//! Templates as they come: real files read as they are (quads, n-gons, seams, unwelded soup,
//! several components or holes), and template defects (inside out, a fin, a stray triangle, a face
//! repeating a vertex, zero-area faces, an open rim the curves run past).

use meshwork_core::fit::testdata::{ngon_sphere, polylines, with_holes, with_zero_area_face};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::icosphere;

use crate::support::{
    case, fit_inputs, icosphere_and_far, raw_vs_own_sections, repaired_vs_own_sections, reversed,
    sections_of, vs_octants, Case, Expect,
};

pub fn templates() -> Vec<Case> {
    use serde_json::json;
    let none = || json!({"alignment": "none"});
    let mut out = Vec::new();
    // Regions the sweep planes cut the (welded) meshes into, counted on a finer copy.
    let spot_regions = sections_of("spot").2;
    out.push(case(
        "suzanne-raw (quads, 4 comps, non-manifold spot)",
        || raw_vs_own_sections("suzanne"),
        none(),
        // Its non-manifold spot is a vertex (every directed edge is used once), which the fit
        // accepts: it must then fit like the repaired copy.
        Expect::Fit(None),
    ));
    out.push(case(
        "suzanne-repaired (quads+tris)",
        || repaired_vs_own_sections("suzanne"),
        none(),
        Expect::Fit(None),
    ));
    out.push(case(
        "teapot-raw (unwelded soup, 4 comps)",
        || raw_vs_own_sections("teapot"),
        none(),
        Expect::Fit(None),
    ));
    out.push(case(
        "spot-raw (13 seam pieces) vs own sections",
        || raw_vs_own_sections("spot"),
        none(),
        Expect::Fit(Some(spot_regions)),
    ));
    out.push(case(
        "beetle-raw (33 pieces, open)",
        || raw_vs_own_sections("beetle"),
        none(),
        Expect::Error(&["template edge", "repair"]),
    ));
    out.push(case(
        "ngon-sphere (24-gon caps + quads)",
        || vs_octants(ngon_sphere(24, 12, 1.0)),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    let corners: Vec<Point3> = (0..8)
        .map(|k| {
            let s = |b: usize| if k >> b & 1 == 1 { 1.0 } else { -1.0 } / 3f64.sqrt();
            [s(0), s(1), s(2)]
        })
        .collect();
    let c2 = corners.clone();
    out.push(case(
        "icosphere with 8 holes (one per octant)",
        move || vs_octants(with_holes(&icosphere(3, 1.0), &c2, 0.2)),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "two components, curves on one",
        || vs_octants(icosphere_and_far(&icosphere(2, 1.0))),
        none(),
        Expect::Fit(Some(9)),
    ));
    out.push(case(
        "two components, auto alignment",
        || vs_octants(icosphere_and_far(&icosphere(2, 1.0))),
        json!({}),
        Expect::Fit(Some(9)),
    ));
    out.push(case(
        "zero-area face + unreferenced duplicate vertex",
        || vs_octants(with_zero_area_face(3)),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "curves past an open template's rim",
        || {
            let ico = icosphere(3, 1.0);
            let tris: Vec<[u32; 3]> = ico
                .faces
                .triangles()
                .into_iter()
                .filter(|t| t.iter().all(|&v| ico.positions[v as usize][2] > -0.3))
                .collect();
            vs_octants(Mesh::from_triangles(ico.positions.clone(), &tris))
        },
        // The lower halves of the meridians are 1.17 (0.38 diagonals) below the rim: under the
        // default limit (0.5) the template is stretched to them; under 0.25 they are named.
        json!({"max_curve_distance": 0.25}),
        Expect::Error(&["curve 1", "max_curve_distance"]),
    ));
    out.push(case(
        "inside-out template",
        || vs_octants(reversed(&icosphere(3, 1.0))),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "inside-out template, no alignment",
        || vs_octants(reversed(&icosphere(3, 1.0))),
        json!({"alignment": "none"}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "second component inside out",
        || vs_octants(icosphere_and_far(&reversed(&icosphere(2, 1.0)))),
        json!({"alignment": "none"}),
        Expect::Fit(Some(9)),
    ));
    out.push(case(
        "tiny stray triangle 100 away, auto",
        || {
            let mut t = icosphere(3, 1.0);
            let n = t.positions.len() as u32;
            t.positions.extend_from_slice(&[[100.0, 0.0, 0.0], [100.01, 0.0, 0.0], [100.0, 0.01, 0.0]]);
            t.faces.push(&[n, n + 1, n + 2], 0);
            vs_octants(t)
        },
        json!({}),
        Expect::Fit(Some(9)),
    ));
    out.push(case(
        "template with a fin (non-manifold edge)",
        || {
            let mut t = icosphere(2, 1.0);
            let f = t.faces.triangles()[7];
            t.positions.push([2.0, 2.0, 2.0]);
            let n = t.positions.len() as u32 - 1;
            t.faces.push(&[f[0], f[1], n], 0);
            vs_octants(t)
        },
        json!({}),
        Expect::Error(&["template edge", "320"]),
    ));
    out.push(case(
        "template face repeating a vertex",
        || {
            let mut t = icosphere(3, 1.0);
            t.faces.push(&[3, 3, 5], 0);
            vs_octants(t)
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "cylinder, curves through its vertices",
        || {
            let cyl = meshwork_core::fit::testdata::open_cylinder(32, 9, 1.0, 2.0);
            let at = |i: usize, j: usize| cyl.positions[j * 32 + i % 32];
            let mut l: Vec<Vec<Point3>> = vec![(0..=32).map(|i| at(i, 4)).collect()];
            for i in [0, 8, 16, 24] {
                l.push((0..9).map(|j| at(i, j)).collect());
            }
            fit_inputs(cyl, polylines(&l))
        },
        json!({"alignment": "none"}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "cylinder, curves along its rims",
        || {
            let cyl = meshwork_core::fit::testdata::open_cylinder(32, 9, 1.0, 2.0);
            let at = |i: usize, j: usize| cyl.positions[j * 32 + i % 32];
            let mut l: Vec<Vec<Point3>> = vec![(0..=32).map(|i| at(i, 0)).collect()];
            l.push((0..=32).map(|i| at(i, 8)).collect());
            for i in [3, 11, 19, 27] {
                l.push((0..9).map(|j| at(i, j)).collect());
            }
            fit_inputs(cyl, polylines(&l))
        },
        json!({"alignment": "none"}),
        Expect::Fit(Some(4)),
    ));
    for name in ["cow", "fandisk", "homer", "rocker-arm"] {
        out.push(case(
            &format!("{name}-raw vs own sections"),
            move || raw_vs_own_sections(name),
            json!({"alignment": "none"}),
            Expect::Fit(None),
        ));
    }
    out
}
