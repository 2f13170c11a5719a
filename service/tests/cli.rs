//! The `meshwork` command line, run as a subprocess on the shared meshes.

mod common;

use std::path::PathBuf;
use std::process::Output;

use common::{run_cli as run, shared_mesh, stderr_text as stderr, TETRA_OBJ};
use meshwork_core::io::{read, ReadOptions};

fn tmp(name: &str) -> PathBuf {
    common::tmp_file("cli", name)
}

/// No panic message or backtrace ever reaches the user.
fn assert_clean(o: &Output) {
    let e = stderr(o);
    assert!(
        !e.contains("panicked") && !e.contains("RUST_BACKTRACE") && !e.contains("stack backtrace"),
        "{e}"
    );
}

#[test]
fn convert_writes_readable_output_and_reports_to_stdout() {
    let out = tmp("cow.obj");
    let cow = shared_mesh("cow.obj");
    let o = run(&["convert", cow.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = read(&std::fs::read(&out).unwrap(), &ReadOptions::default()).unwrap().mesh;
    // shared/meshes/README.md: cow.obj has 2,903 vertices and 5,804 triangles.
    assert_eq!((m.vertex_count(), m.face_count()), (2903, 5804));
    // The report goes to stdout when the mesh goes to a file.
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("report JSON on stdout");
    assert_eq!(report["vertices"], 2903);
    assert!(report["total_ms"].is_number() && report["stages"].is_object());
    assert_eq!(report["inputs"][0]["format"], "obj");
}

#[test]
fn report_file_params_file_and_stdout_output() {
    let rep = tmp("r.json");
    let params = tmp("p.json");
    std::fs::write(&params, "{}").unwrap();
    let input = tmp("t.obj");
    std::fs::write(&input, TETRA_OBJ).unwrap();
    let o = run(&[
        "convert",
        input.to_str().unwrap(),
        "-o",
        "-",
        "--format",
        "obj",
        "--report",
        rep.to_str().unwrap(),
        "--params",
        params.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m =
        read(&o.stdout, &ReadOptions { name_hint: Some("obj".into()), ..Default::default() }).unwrap().mesh;
    assert_eq!((m.vertex_count(), m.face_count()), (4, 4));
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&rep).unwrap()).unwrap();
    assert_eq!(r["faces"], 4);
}

#[test]
fn bad_input_and_params_exit_2_with_kind_and_location() {
    let input = tmp("bad.obj");
    std::fs::write(&input, "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let out = tmp("never.obj");
    let o = run(&["convert", input.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("error[malformed-input]") && e.contains("line 2"), "{e}");
    assert!(!out.exists(), "no output on failure");
    assert_clean(&o);

    let good = tmp("good.obj");
    std::fs::write(&good, TETRA_OBJ).unwrap();
    // Unknown job parameter, from a flag: named.
    let o = run(&["convert", good.to_str().unwrap(), "-o", out.to_str().unwrap(), "--bogus-thing", "3"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("error[invalid-params]") && stderr(&o).contains("bogus_thing"),
        "{}",
        stderr(&o)
    );
    // Unknown key in a params file.
    let p = tmp("bad-params.json");
    std::fs::write(&p, "{\"weird\": 1}").unwrap();
    let o = run(&[
        "convert",
        good.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--params",
        p.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("weird"), "{}", stderr(&o));
    // Missing file, unknown output extension, missing -o, wrong input count.
    let o = run(&["convert", "/nonexistent/x.obj", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("/nonexistent/x.obj"));
    let o = run(&["convert", good.to_str().unwrap(), "-o", tmp("x.xyz").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let o = run(&["convert", good.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let o = run(&["fit", good.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("inputs"), "{}", stderr(&o));
    assert_clean(&o);
}

/// Found by the CLI fuzz campaign: `--timeout 1e300` panicked (exit 101, "cannot convert float
/// seconds to Duration"); a timeout too long to represent now means no deadline.
#[test]
fn huge_timeout_means_no_deadline() {
    let good = tmp("timeout-good.obj");
    std::fs::write(&good, TETRA_OBJ).unwrap();
    for t in ["1e300", "9e18", "1e6"] {
        let out = tmp(&format!("timeout-{t}.obj"));
        let o = run(&["convert", good.to_str().unwrap(), "-o", out.to_str().unwrap(), "--timeout", t]);
        assert_clean(&o);
        assert!(o.status.success(), "--timeout {t}: {}", stderr(&o));
        assert!(out.exists(), "--timeout {t}");
    }
    let o = run(&[
        "convert",
        good.to_str().unwrap(),
        "-o",
        tmp("timeout-nan.obj").to_str().unwrap(),
        "--timeout",
        "nan",
    ]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn piped_run_prints_no_progress_line() {
    let good = tmp("quiet.obj");
    std::fs::write(&good, TETRA_OBJ).unwrap();
    let o = run(&["convert", good.to_str().unwrap(), "-o", tmp("quiet-out.obj").to_str().unwrap()]);
    assert!(o.status.success());
    assert_eq!(stderr(&o), "", "stderr is not a terminal: nothing extra");
}

#[test]
fn help_lists_every_command() {
    let o = run(&["--help"]);
    let t = String::from_utf8_lossy(&o.stdout);
    for c in ["info", "convert", "repair", "smooth", "fit", "morph", "serve", "openapi"] {
        assert!(t.contains(c), "{c} missing from --help");
    }
}

#[test]
fn info_repair_and_smooth_on_shared_meshes() {
    let cow = shared_mesh("cow.obj");
    let o = run(&["info", cow.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // shared/meshes/README.md: 2,903 vertices, 5,804 triangles, closed.
    assert_eq!(
        (v["vertices"].as_u64(), v["faces"].as_u64(), v["closed"].as_bool()),
        (Some(2903), Some(5804), Some(true))
    );

    let out = tmp("suzanne-repaired.glb");
    let rep = tmp("suzanne-report.json");
    let o = run(&[
        "repair",
        shared_mesh("suzanne.obj").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--report",
        rep.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(o.stdout.is_empty(), "report went to the file, not stdout");
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&rep).unwrap()).unwrap();
    assert!(r["total_ms"].is_number());
    let m = read(&std::fs::read(&out).unwrap(), &ReadOptions::default()).unwrap().mesh;
    assert!(m.face_count() > 0);

    // Flags are the params' names: --method, --iterations, --preserve-volume (alone = true).
    let out = tmp("fandisk-smooth.obj");
    let o = run(&[
        "smooth",
        shared_mesh("fandisk.obj").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--method",
        "taubin",
        "--iterations",
        "3",
        "--preserve-volume",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(r["volume_change"].is_number() && r["hausdorff"].is_number(), "{r}");
    let m = read(&std::fs::read(&out).unwrap(), &ReadOptions::default()).unwrap().mesh;
    assert_eq!(m.vertex_count(), 6475);
    let o = run(&[
        "smooth",
        shared_mesh("fandisk.obj").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--method",
        "nope",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("method"), "{}", stderr(&o));
}

/// Issue 5's CLI form: `meshwork fit TEMPLATE CURVES.json --pairs PAIRS.json`, the curves as
/// `{"polylines": …}` and the pairs file as `{"pairs": …}`. Truth: the curves are the principal
/// sections of an analytic ellipsoid, so every segment must end up as mesh edges.
#[test]
fn fit_takes_polylines_json_and_a_pairs_file() {
    use meshwork_core::fit::testdata::ellipsoid_sections;
    use meshwork_core::io::{write, Format};
    use meshwork_core::shapes::icosphere;
    const AXES: [f64; 3] = [1.4, 1.15, 0.9];

    let sphere = icosphere(3, 1.0);
    let template = tmp("fit-template.obj");
    std::fs::write(&template, write(&sphere, Format::Obj).unwrap()).unwrap();

    let net = ellipsoid_sections(AXES, 10);
    let polylines: Vec<Vec<[f64; 3]>> =
        net.curves.iter().map(|c| c.iter().map(|&v| net.positions[v as usize]).collect()).collect();
    let curves = tmp("fit-curves.json");
    std::fs::write(&curves, serde_json::to_vec(&serde_json::json!({ "polylines": polylines })).unwrap())
        .unwrap();

    // The six axis ends of the unit sphere go to the ellipsoid's axis ends.
    let mut pairs = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut dir = [0.0; 3];
            dir[axis] = sign;
            let v = (0..sphere.positions.len())
                .min_by(|&i, &j| {
                    let d = |k: usize| (0..3).map(|c| (sphere.positions[k][c] - dir[c]).powi(2)).sum::<f64>();
                    d(i).total_cmp(&d(j))
                })
                .unwrap();
            let mut target = [0.0; 3];
            target[axis] = sign * AXES[axis];
            pairs.push(serde_json::json!({ "template_vertex": v, "curve_point": target }));
        }
    }
    let pairs_file = tmp("fit-pairs.json");
    std::fs::write(&pairs_file, serde_json::to_vec(&serde_json::json!({ "pairs": pairs })).unwrap()).unwrap();

    let out = tmp("fit-out.obj");
    let report = tmp("fit-report.json");
    let o = run(&[
        "fit",
        template.to_str().unwrap(),
        curves.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
        "--pairs",
        pairs_file.to_str().unwrap(),
    ]);
    assert_clean(&o);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert_eq!(r["alignment"]["method"], "pairs", "{r}");
    assert_eq!(r["segments_as_edges"], 1.0, "{r}");
    assert_eq!(r["inputs"][1]["format"], "polylines-json");
    let fitted = read(&std::fs::read(&out).unwrap(), &ReadOptions::default()).unwrap().mesh;
    assert_eq!(fitted.groups.len(), 8, "one group per octant region");

    // A malformed point is named by its JSON path, exit 2, no panic.
    std::fs::write(&curves, br#"{"polylines": [[[0,0,0],[1,0]]]}"#).unwrap();
    let o = run(&["fit", template.to_str().unwrap(), curves.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_clean(&o);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("polylines[0][1]"), "{}", stderr(&o));
}

/// Entries of a ZIP by its end-of-central-directory record (no comment: the last 22 bytes).
fn zip_entries(b: &[u8]) -> u16 {
    assert!(b.len() >= 22 && b[..4] == [0x50, 0x4b, 0x03, 0x04], "not a ZIP");
    let end = &b[b.len() - 22..];
    assert_eq!(end[..4], [0x50, 0x4b, 0x05, 0x06], "no end record");
    u16::from_le_bytes([end[10], end[11]])
}

#[test]
fn morph_to_a_zip_writes_one_file_per_frame() {
    // Two open meshes (woody and alligator are disks): the planar path, frames zipped as GLB.
    let out = tmp("frames.zip");
    let o = run(&[
        "morph",
        shared_mesh("woody.obj").to_str().unwrap(),
        shared_mesh("alligator.obj").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--frames",
        "3",
        "--report",
        tmp("frames-report.json").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let z = std::fs::read(&out).unwrap();
    assert_eq!(zip_entries(&z), 3);
    // The first entry is frame_0000.glb and holds a GLB (local header 30 bytes + name).
    assert_eq!(&z[30..44], b"frame_0000.glb");
    assert_eq!(&z[44..48], b"glTF");
    let rep: serde_json::Value =
        serde_json::from_slice(&std::fs::read(tmp("frames-report.json")).unwrap()).unwrap();
    assert_eq!(rep["domain"], "planar");
    assert_eq!(rep["frames_zip"], "glb");
    // `--frames-zip obj` picks OBJ frames.
    let o = run(&[
        "morph",
        shared_mesh("woody.obj").to_str().unwrap(),
        shared_mesh("alligator.obj").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--frames",
        "2",
        "--frames-zip",
        "obj",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let z = std::fs::read(&out).unwrap();
    assert_eq!(zip_entries(&z), 2);
    assert_eq!(&z[30..44], b"frame_0000.obj");
}
