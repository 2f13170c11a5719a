//! The fit endpoint fed as a client would: a multipart upload of a quad/n-gon template and a
//! hand-written glTF LINES curve file, answered with a GLB whose per-region primitives must pass
//! the Khronos validator; and bad uploads (a stray curve, a pair far from the curves, a NaN in
//! the curve file, an empty file) answered with problems that say what and where. The CLI's
//! `--pairs` / `--report` form is checked for the report fields issue 5 names.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{file_part, json_part, split_mixed, Server, BIN};
use meshwork_core::fit::testdata::{circle, ellipsoid_sections, gltf_lines, ngon_sphere, polylines};
use meshwork_core::io::{write, Format};
use meshwork_core::shapes::icosphere;

const AXES: [f64; 3] = [1.4, 1.15, 0.9];

/// The octant network (three principal ellipse sections) as glTF LINES, one index pair per segment.
fn octants_gltf_lines() -> Vec<u8> {
    let c = ellipsoid_sections(AXES, 6);
    let idx: Vec<u32> = c.curves.iter().flat_map(|l| l.windows(2).flat_map(|w| [w[0], w[1]])).collect();
    gltf_lines(&c.positions, &idx, 1)
}

fn post_fit(s: &Server, query: &str, template: &[u8], curves: (&str, &[u8]), params: &str) -> common::Resp {
    s.post_multipart(
        &format!("/v1/fit?{query}"),
        &[
            file_part("template", "template.obj", template),
            file_part("curves", curves.0, curves.1),
            json_part("params", params),
        ],
    )
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("service/ has a parent").to_path_buf()
}

/// Runs the Khronos validator on one file: Some(number of errors), None when skipped.
fn khronos_errors(path: &Path) -> Option<u64> {
    if std::env::var("MESHWORK_SKIP_VALIDATOR").as_deref() == Ok("1") {
        eprintln!("\n*** MESHWORK_SKIP_VALIDATOR=1: the validator check of the fit GLB was SKIPPED ***\n");
        return None;
    }
    let root = repo_root();
    assert!(
        root.join("tests/gltf-validator/node_modules/gltf-validator").exists(),
        "run `npm ci --prefix tests/gltf-validator --no-audit --no-fund` (or MESHWORK_SKIP_VALIDATOR=1)"
    );
    let out = Command::new("node")
        .arg(root.join("tests/gltf-validator/validate.mjs"))
        .arg(path)
        .output()
        .expect("node runs");
    let line = String::from_utf8_lossy(&out.stdout).lines().next().unwrap_or_default().to_string();
    let report: serde_json::Value =
        serde_json::from_str(&line).unwrap_or_else(|_| panic!("validator: {line}"));
    eprintln!("{report}");
    report["numErrors"].as_u64()
}

/// The JSON chunk of a GLB.
fn glb_json(glb: &[u8]) -> serde_json::Value {
    assert_eq!(&glb[..4], b"glTF");
    let len = u32::from_le_bytes([glb[12], glb[13], glb[14], glb[15]]) as usize;
    assert_eq!(&glb[16..20], b"JSON");
    serde_json::from_slice(&glb[20..20 + len]).expect("GLB JSON chunk")
}

#[test]
fn ngon_template_and_gltf_lines_upload_gives_a_valid_glb_per_region() {
    let s = Server::start(&[]);
    // 24-gon caps and quads: the template must be triangulated by the job, not refused.
    let template = write(&ngon_sphere(24, 12, 1.0), Format::Obj).unwrap();
    let r = post_fit(&s, "format=glb&report=inline", &template, ("curves.gltf", &octants_gltf_lines()), "{}");
    assert_eq!(r.status, 200, "{}", r.text());
    let parts = split_mixed(r.header("content-type").unwrap(), &r.body);
    assert_eq!(parts.len(), 2);
    let report: serde_json::Value = serde_json::from_slice(&parts[0].1).unwrap();
    // The octants: 8 regions by hand; 2 × 22 + 264 × 2 = 572 template triangles.
    assert_eq!(report["regions"], 8, "{report}");
    assert_eq!(report["template_triangles"], 572);
    assert_eq!(report["segments_as_edges"], 1.0);
    assert_eq!(report["inputs"][1]["format"], "gltf");
    let glb = &parts[1].1;
    let doc = glb_json(glb);
    // One TRIANGLES mesh per region (named region_i) and one LINE_STRIP mesh for the curves.
    let meshes = doc["meshes"].as_array().unwrap();
    let tri_meshes: Vec<_> = meshes.iter().filter(|m| m["primitives"][0]["mode"] == 4).collect();
    assert_eq!(tri_meshes.len(), 8);
    assert!(tri_meshes.iter().all(|m| m["name"].as_str().unwrap().starts_with("region_")));
    let curves = meshes.iter().find(|m| m["name"] == "curves").expect("a curves mesh");
    assert_eq!(curves["primitives"].as_array().unwrap().len(), 3, "three section curves");
    assert!(curves["primitives"].as_array().unwrap().iter().all(|p| p["mode"] == 3));
    let path = std::env::temp_dir().join(format!("meshwork-fit-upload-{}.glb", std::process::id()));
    std::fs::write(&path, glb).unwrap();
    if let Some(errors) = khronos_errors(&path) {
        assert_eq!(errors, 0);
    }
}

#[test]
fn bad_uploads_are_problems_that_say_what_and_where() {
    let s = Server::start(&[]);
    let template = write(&icosphere(3, 1.0), Format::Obj).unwrap();
    let c = ellipsoid_sections(AXES, 6);
    // A fourth curve far away, sent as JSON polylines.
    let mut lines: Vec<Vec<[f64; 3]>> =
        c.curves.iter().map(|l| l.iter().map(|&v| c.positions[v as usize]).collect()).collect();
    lines.push(circle([30.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.5, 12, 0.0));
    let stray = serde_json::to_vec(&serde_json::json!({ "polylines": lines })).unwrap();
    let octants_obj = write(&polylines(&lines[..3]), Format::Obj).unwrap();
    let far_pair = r#"{"pairs": [
        {"template_vertex": 0, "curve_point": [1.4, 0, 0]},
        {"template_vertex": 5, "curve_point": [0, 1.15, 0]},
        {"template_vertex": 9, "curve_point": [0, 0, 0.9]},
        {"template_vertex": 11, "curve_point": [-50, 0, 0]}]}"#;
    let nan_lines = b"v 0 0 1\nv 1 0 0\nv nan 1 0\nl 1 2 3\n";
    let cases: [(&str, &[u8], &str, &str); 4] = [
        ("c.json", &stray, "{}", "curve 3 is"),
        ("c.obj", &octants_obj, far_pair, "pairs[3].curve_point"),
        ("c.obj", nan_lines, "{}", "line 3"),
        ("c.obj", b"", "{}", "empty"),
    ];
    for (name, bytes, params, want) in cases {
        let r = post_fit(&s, "format=obj", &template, (name, bytes), params);
        assert!((400..500).contains(&r.status), "{want}: {} {}", r.status, r.text());
        assert_eq!(r.header("content-type"), Some("application/problem+json"));
        let text = r.json().to_string();
        assert!(text.contains(want), "expected {want} in {text}");
        assert!(!text.contains("panicked"), "{text}");
    }
}

#[test]
fn cli_report_has_the_fields_issue_5_names() {
    let dir = std::env::temp_dir().join(format!("meshwork-fit-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let template = dir.join("t.obj");
    // A vertex in no face first: the job removes it and counts it.
    let mut obj = b"v 9 9 9\n".to_vec();
    let ico = write(&icosphere(3, 1.0), Format::Obj).unwrap();
    let text = String::from_utf8(ico).unwrap();
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("f ") {
            let shifted: Vec<String> =
                rest.split_whitespace().map(|t| (t.parse::<u32>().unwrap() + 1).to_string()).collect();
            obj.extend_from_slice(format!("f {}\n", shifted.join(" ")).as_bytes());
        } else if line.starts_with("v ") {
            obj.extend_from_slice(format!("{line}\n").as_bytes());
        }
    }
    std::fs::write(&template, &obj).unwrap();
    let curves = dir.join("c.gltf");
    std::fs::write(&curves, octants_gltf_lines()).unwrap();
    let out = dir.join("out.obj");
    let report = dir.join("r.json");
    let run = |pairs: Option<&Path>| {
        let mut args = vec![
            "fit".to_string(),
            template.display().to_string(),
            curves.display().to_string(),
            "-o".into(),
            out.display().to_string(),
            "--report".into(),
            report.display().to_string(),
        ];
        if let Some(p) = pairs {
            args.extend(["--pairs".to_string(), p.display().to_string()]);
        }
        Command::new(BIN).args(&args).output().unwrap()
    };
    let o = run(None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    for field in [
        "curve_residual_max",
        "curve_residual_mean",
        "segments_as_edges",
        "flipped_faces",
        "min_angle_deg_before_smoothing",
        "min_angle_deg_after_smoothing",
        "regions",
        "template_faces",
        "output_faces",
        "total_ms",
    ] {
        assert!(r[field].is_number(), "{field} missing: {r}");
    }
    assert_eq!(r["regions"], 8);
    assert_eq!(r["template_vertices"], 643);
    assert_eq!(r["template_unreferenced_vertices_removed"], 1);
    // Every stage is timed.
    for stage in ["curves", "coarse", "fine", "retriangulate", "partition", "smooth"] {
        assert!(r["stages"][stage].is_object() || r["stages"][stage].is_number(), "{stage}: {}", r["stages"]);
    }
    // OBJ output: one group per region.
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("g ")).count(), 8);
    // A pairs file naming the vertex in no face (index 0 of the file) is refused, naming the pair.
    let pairs = dir.join("p.json");
    std::fs::write(&pairs, br#"{"pairs": [{"template_vertex": 0, "curve_point": [1.4, 0, 0]}]}"#).unwrap();
    let o = run(Some(&pairs));
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("pairs[0].template_vertex") && err.contains("no face"), "{err}");
}
