//! Morph benchmark and experiment driver.
//!
//! `bench_morph [SOURCE TARGET [MORE…]] [--dense | --centroid] [--params JSON] [--out OUT.glb]`
//! Defaults: ../shared/meshes/fandisk.obj and homer.obj. `--dense` applies two steps of √3
//! subdivision without smoothing (×9 faces, ~54k/58k vertices for homer/fandisk): the issue's "two ~50k-vertex
//! genus-0 meshes to a 30-frame GLB" case. `--centroid` splits every face at its centroid twice
//! instead (same vertex counts, many thin triangles). Prints the report's headline numbers and the wall time.

use std::time::Instant;

use meshwork_core::io::{read, ReadOptions};
use meshwork_core::job::{self, JobKind, Progress};
use meshwork_core::mesh::Mesh;

fn centroid_split(m: &Mesh) -> Mesh {
    let mut pos = m.positions.clone();
    let mut tris = Vec::new();
    for f in m.faces.iter() {
        let c = f.iter().fold([0.0; 3], |s, &v| {
            let p = m.positions[v as usize];
            [s[0] + p[0], s[1] + p[1], s[2] + p[2]]
        });
        let n = f.len() as f64;
        pos.push([c[0] / n, c[1] / n, c[2] / n]);
        let ci = (pos.len() - 1) as u32;
        for k in 0..f.len() {
            tris.push([f[k], f[(k + 1) % f.len()], ci]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}

/// One step of √3 subdivision without smoothing (Kobbelt 2000): split every triangle at its
/// centroid, then flip every original edge, so triangles stay well shaped and vertices ×3.
fn sqrt3_split(m: &Mesh) -> Mesh {
    let split = centroid_split(m);
    let mut tris: Vec<[u32; 3]> = split.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    let n_old = m.positions.len() as u32;
    // Each original edge (a, b) now borders two triangles (a, b, c1) and (b, a, c2).
    let mut by_edge: std::collections::HashMap<(u32, u32), usize> = std::collections::HashMap::new();
    for (i, t) in tris.iter().enumerate() {
        by_edge.insert((t[0], t[1]), i);
    }
    let mut done = vec![false; tris.len()];
    for i in 0..tris.len() {
        let [a, b, c1] = tris[i];
        if done[i] || a >= n_old || b >= n_old {
            continue;
        }
        let Some(&j) = by_edge.get(&(b, a)) else { continue };
        if done[j] {
            continue;
        }
        let c2 = tris[j][2];
        tris[i] = [a, c2, c1];
        tris[j] = [c2, b, c1];
        done[i] = true;
        done[j] = true;
    }
    Mesh::from_triangles(split.positions, &tris)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut paths = Vec::new();
    let mut dense = false;
    let mut centroid = false;
    let mut params = serde_json::json!({});
    let mut out: Option<String> = None;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--dense" => dense = true,
            "--centroid" => centroid = true,
            "--params" => {
                i += 1;
                params = serde_json::from_str(&args[i]).expect("--params takes JSON");
            }
            "--out" => {
                i += 1;
                out = Some(args[i].clone());
            }
            p => paths.push(p.to_string()),
        }
        i += 1;
    }
    if paths.is_empty() {
        paths = vec!["../shared/meshes/fandisk.obj".into(), "../shared/meshes/homer.obj".into()];
    }
    let mut meshes = Vec::new();
    for p in &paths {
        let bytes = std::fs::read(p).unwrap_or_else(|e| panic!("{p}: {e}"));
        let mut m = read(&bytes, &ReadOptions { name_hint: Some(p.clone()), ..Default::default() })
            .unwrap_or_else(|e| panic!("{p}: {e}"))
            .mesh;
        if dense {
            m = sqrt3_split(&sqrt3_split(&m));
        }
        if centroid {
            m = centroid_split(&centroid_split(&m));
        }
        println!("{p}: {} vertices, {} faces", m.vertex_count(), m.face_count());
        meshes.push(m);
    }
    let t = Instant::now();
    let r = job::run(JobKind::Morph, meshes, params, &Progress::new());
    let secs = t.elapsed().as_secs_f64();
    match r {
        Ok(o) => {
            let rep = &o.report;
            for k in [
                "angle_distortion",
                "area_distortion",
                "foldovers",
                "metamesh_vertices",
                "hausdorff_per_input",
                "correspondence",
                "stages",
            ] {
                println!("{k}: {}", rep[k]);
            }
            for p in rep["per_input"].as_array().into_iter().flatten() {
                println!("param: {}", p["parameterisation"]);
            }
            println!("features: {}", rep["features"]);
            println!("glb bytes: {}", o.artifacts[0].bytes.len());
            if let Some(path) = out {
                std::fs::write(&path, &o.artifacts[0].bytes).expect("write glb");
            }
        }
        Err(e) => println!("error: {e}"),
    }
    println!("wall: {secs:.3} s");
}
