//! `meshwork morph --domain … --repair`: the morph's domain parameter through the command line
//! (the generic `--some-name VALUE` → `some_name` mapping), on the shared disk woody with a hole
//! punched into it, and the refusal of a closed mesh under `--domain disk`; the same over HTTP
//! (`?domain=disk&repair=true`).

mod common;

use std::collections::HashMap;
use std::path::PathBuf;

use common::{file_part, run_cli as run, shared_mesh, stderr_text as stderr, Server, TETRA_OBJ};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::mesh::Mesh;

fn dir() -> PathBuf {
    common::tmp_dir("morph-domain")
}

fn tmp(name: &str) -> PathBuf {
    common::tmp_file("morph-domain", name)
}

/// Woody with the faces around its interior vertex farthest from the rim removed: a disk with a
/// second boundary loop that does not touch the first. Returns the mesh and the faces removed.
fn holed_woody() -> (Mesh, usize) {
    let m = read(&std::fs::read(shared_mesh("woody.obj")).unwrap(), &ReadOptions::default()).unwrap().mesh;
    let tris = meshwork_core::shapes::fan_triangles(&m.faces);
    let mut count: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let rim: Vec<u32> =
        count.iter().filter(|(_, &n)| n == 1).flat_map(|(&(a, b), _)| [a, b]).collect::<Vec<_>>();
    let d = |v: u32| {
        rim.iter()
            .map(|&r| meshwork_core::geometry::dist(m.positions[v as usize], m.positions[r as usize]))
            .fold(f64::INFINITY, f64::min)
    };
    let used: Vec<u32> = tris.iter().flatten().copied().collect();
    let centre = used.iter().copied().max_by(|&a, &b| d(a).total_cmp(&d(b))).unwrap();
    let kept: Vec<[u32; 3]> = tris.iter().copied().filter(|t| !t.contains(&centre)).collect();
    let removed = tris.len() - kept.len();
    (Mesh::from_triangles(m.positions.clone(), &kept), removed)
}

#[test]
fn domain_flag_repairs_a_holed_disk_and_refuses_a_closed_one() {
    let (holed, removed) = holed_woody();
    assert!(removed >= 3);
    let src = tmp("holed-woody.obj");
    std::fs::write(&src, meshwork_core::io::obj::write(&holed).unwrap()).unwrap();
    let (out, rep) = (tmp("morph.glb"), tmp("report.json"));
    let alligator = shared_mesh("alligator.obj");
    // Without --repair: refused, exit 2, naming the two boundary loops.
    let o = run(&[
        "morph",
        src.to_str().unwrap(),
        alligator.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--domain",
        "disk",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("genus 0 with 2 boundary loops"), "{}", stderr(&o));
    // With --repair --domain disk: the hole filled, the rim kept, morphed on the plane.
    let o = run(&[
        "morph",
        src.to_str().unwrap(),
        alligator.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--repair",
        "--domain",
        "disk",
        "--frames",
        "2",
        "--report",
        rep.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&rep).unwrap()).unwrap();
    assert_eq!(r["domain"], "planar");
    assert!(r["domain_reason"].as_str().unwrap().contains("domain: disk"), "{}", r["domain_reason"]);
    assert_eq!(r["repair"][0]["summary"]["holes_filled"], 1, "{}", r["repair"][0]);
    assert_eq!(r["repair"][0]["summary"]["vertices_removed_unreferenced"], 1, "{}", r["repair"][0]);
    assert_eq!(r["foldovers"], serde_json::json!([0, 0]));
    assert!(r["hausdorff_first_frame"].as_f64().unwrap() <= 1e-3);
    assert_eq!(&std::fs::read(&out).unwrap()[..4], b"glTF");
    // A closed tetrahedron under --domain disk: refused, naming what it is.
    let tet = tmp("tetra.obj");
    std::fs::write(&tet, TETRA_OBJ).unwrap();
    let o = run(&[
        "morph",
        tet.to_str().unwrap(),
        alligator.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--domain",
        "disk",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("genus 0 with 0 boundary loops"), "{}", stderr(&o));
    let _ = std::fs::remove_dir_all(dir());
}

#[test]
fn domain_query_parameter_over_http() {
    let s = Server::start(&[]);
    let (holed, _) = holed_woody();
    let a = meshwork_core::io::obj::write(&holed).unwrap();
    let b = std::fs::read(shared_mesh("alligator.obj")).unwrap();
    let r = s.post_multipart(
        "/v1/morph?frames=2&repair=true&domain=disk",
        &[file_part("mesh", "a.obj", &a), file_part("mesh", "b.obj", &b)],
    );
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(&r.body[..4], b"glTF");
    let link = r.header("link").expect("Link to the report").to_string();
    let path = link.trim_start_matches('<').split('>').next().unwrap().to_string();
    let rep = s.get(&path).json();
    assert_eq!(rep["domain"], "planar", "{rep}");
    assert_eq!(rep["repair"][0]["summary"]["holes_filled"], 1);
    // A closed mesh under domain=disk, and an unknown domain.
    let t = TETRA_OBJ.as_bytes();
    let p = s
        .post_multipart(
            "/v1/morph?domain=disk",
            &[file_part("mesh", "t.obj", t), file_part("mesh", "b.obj", &b)],
        )
        .problem(422, "unsupported-topology");
    assert!(p["detail"].as_str().unwrap().contains("genus 0 with 0 boundary loops"), "{p}");
    s.post_multipart(
        "/v1/morph?domain=torus",
        &[file_part("mesh", "t.obj", t), file_part("mesh", "b.obj", &b)],
    )
    .problem(422, "invalid-params");
    s.terminate();
}
