//! The fit endpoint and command with session 9's unseen inputs (see core/tests/fit_unseen9.rs and
//! the `formats` family of examples/sweep_unseen), the way a client sends them: a template of long
//! needles as a scanner's binary PLY (f32) with the curves as `{"polylines": …}` over HTTP, answered
//! as GLB; a template as an ASCII STL soup with the curves as GLB lines on the command line.
//! Truths: the ellipsoid's principal sections cut it into its 8 octants (counted by hand), every
//! curve point is an output vertex (up to the output's f32 rounding), and the needle template
//! keeps its 5,120 faces (the fit only adds).

mod common;

use common::{file_part, json_part, run_cli, split_mixed, stderr_text, tmp_file, Server};
use meshwork_core::fit::testdata::{ascii_stl, binary_ply, ellipsoid_sections, needle_sphere};
use meshwork_core::geometry::{dist, Aabb};
use meshwork_core::io::{read, write, Format, ReadOptions};
use meshwork_core::mesh::Mesh;
use meshwork_core::shapes::icosphere;

const AXES: [f64; 3] = [1.4, 1.15, 0.9];

/// The largest distance from a curve point to its nearest output vertex, over the bbox diagonal.
fn worst_curve_point(curves: &Mesh, out: &Mesh) -> f64 {
    let diag = Aabb::of(&curves.positions).expect("curve points").diagonal();
    curves
        .positions
        .iter()
        .map(|&p| out.positions.iter().map(|&q| dist(p, q)).fold(f64::INFINITY, f64::min))
        .fold(0.0, f64::max)
        / diag
}

fn polylines_json(c: &Mesh) -> Vec<u8> {
    let lines: Vec<Vec<[f64; 3]>> =
        c.curves.iter().map(|l| l.iter().map(|&v| c.positions[v as usize]).collect()).collect();
    serde_json::to_vec(&serde_json::json!({ "polylines": lines })).expect("JSON of polylines")
}

#[test]
fn needle_template_as_binary_ply_over_http_answered_as_glb() {
    let s = Server::start(&[]);
    let template = needle_sphere(512, 6, 1.0);
    assert_eq!(template.faces.len(), 5120);
    let curves = ellipsoid_sections(AXES, 6);
    let r = s.post_multipart(
        "/v1/fit?format=glb&report=inline",
        &[
            file_part("template", "scan.ply", &binary_ply(&template)),
            file_part("curves", "curves.json", &polylines_json(&curves)),
            json_part("params", "{}"),
        ],
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let parts = split_mixed(r.header("content-type").expect("content-type"), &r.body);
    let report: serde_json::Value = serde_json::from_slice(&parts[0].1).expect("JSON report");
    assert_eq!(report["regions"], 8, "{report}");
    assert_eq!(report["segments_as_edges"], 1.0);
    assert_eq!(report["flipped_faces"], 0);
    let out = read(&parts[1].1, &ReadOptions::default()).expect("the answer is a readable GLB").mesh;
    assert_eq!(out.groups.len(), 8, "one primitive per region");
    let faces = out.faces.triangles().len();
    assert!(faces >= 5120, "{faces} faces out of a 5,120-face template");
    // GLB positions are f32: a curve point is a vertex up to f32 rounding (2⁻²⁴ relative).
    let worst = worst_curve_point(&curves, &out);
    assert!(worst < 1e-6, "a curve point is {worst} × diagonal from the output's vertices");
}

#[test]
fn stl_soup_template_and_glb_curves_on_the_command_line() {
    let template = tmp_file("fit-unseen9", "sphere.stl");
    std::fs::write(&template, ascii_stl(&icosphere(3, 1.0))).expect("write STL");
    let curves = ellipsoid_sections(AXES, 6);
    let glb = write(&curves, Format::Glb).expect("GLB of curves");
    let curves_file = tmp_file("fit-unseen9", "curves.glb");
    std::fs::write(&curves_file, &glb).expect("write GLB");
    // The job sees the curve points as the GLB holds them (f32).
    let curves = read(&glb, &ReadOptions::default()).expect("GLB read back").mesh;
    let out_file = tmp_file("fit-unseen9", "out.obj");
    let report_file = tmp_file("fit-unseen9", "report.json");
    let path = |p: &std::path::PathBuf| p.to_str().expect("UTF-8 path").to_string();
    let o = run_cli(&[
        "fit",
        &path(&template),
        &path(&curves_file),
        "-o",
        &path(&out_file),
        "--report",
        &path(&report_file),
    ]);
    assert!(o.status.success(), "{}", stderr_text(&o));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report_file).expect("report")).expect("JSON report");
    assert_eq!(report["regions"], 8, "{report}");
    assert_eq!(report["segments_as_edges"], 1.0);
    assert_eq!(report["flipped_faces"], 0);
    let out = read(&std::fs::read(&out_file).expect("output"), &ReadOptions::default()).expect("OBJ").mesh;
    assert_eq!(out.groups.len(), 8, "one group per region");
    let worst = worst_curve_point(&curves, &out);
    assert!(worst < 1e-9, "a curve point is {worst} × diagonal from the output's vertices");
}
