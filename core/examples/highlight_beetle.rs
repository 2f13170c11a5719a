//! Seed 001 highlight-line fairing on the shared VW Beetle mesh (the paper's model, Fig. 7/8):
//! the roof region, as is and with normal noise added to it. Prints the report's key numbers and
//! writes the faired meshes and the highlight lines (OBJ `l` polylines) to `target/highlight/`.
//!
//! `cargo run --release -p meshwork-core --example highlight_beetle [-- Y_MIN [NOISE]]`

use meshwork_core::geometry::add;
use meshwork_core::io::{read, write, Format, ReadOptions};
use meshwork_core::job::{run, JobKind, Progress};
use meshwork_core::smooth::highlight::{lines, lines::Adjacency, lines::Lights};
use serde_json::{json, Value};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let y_min: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(0.5);
    let noise: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.1);
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/meshes/beetle.obj");
    let bytes = std::fs::read(path).expect("beetle.obj");
    let mesh = read(&bytes, &ReadOptions::default()).expect("read").mesh;
    let region: Vec<u32> =
        (0..mesh.vertex_count() as u32).filter(|&v| mesh.positions[v as usize][1] > y_min).collect();
    let params = json!({"method": "highlight", "region": region, "light_normal": [0, 1, 0],
                        "light_direction": [0, 0, 1]});
    let out_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/highlight");
    std::fs::create_dir_all(&out_dir).expect("mkdir");
    let adj = Adjacency::new(&mesh).expect("triangles");
    let nrm = adj.normals(&mesh.positions);
    let mut noisy = mesh.clone();
    let mut s = 7u64;
    let e = mean_edge(&mesh, &region);
    for &v in &region {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let t = ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5;
        noisy.positions[v as usize] =
            add(mesh.positions[v as usize], nrm[v as usize].map(|c| c * t * noise * e));
    }
    for (name, m) in [("as_is", &mesh), ("noisy", &noisy)] {
        let out = run(JobKind::Smooth, vec![m.clone()], params.clone(), &Progress::new()).expect("smooth");
        let r = &out.report;
        summary(name, r);
        let l = Lights {
            normal: to3(&r["lights"]["normal"]),
            direction: to3(&r["lights"]["direction"]),
            origin: to3(&r["lights"]["origin"]),
            spacing: r["lights"]["spacing"].as_f64().unwrap(),
        };
        for (tag, x) in [("before", &m.positions), ("after", &out.meshes[0].positions)] {
            let md = lines::model(&adj, x, &l);
            std::fs::write(out_dir.join(format!("beetle_{name}_lines_{tag}.obj")), lines::to_obj(&md))
                .unwrap();
        }
        std::fs::write(out_dir.join(format!("beetle_{name}_in.obj")), write(m, Format::Obj).unwrap())
            .unwrap();
        std::fs::write(
            out_dir.join(format!("beetle_{name}_faired.obj")),
            write(&out.meshes[0], Format::Obj).unwrap(),
        )
        .unwrap();
    }
    eprintln!("wrote {}", out_dir.display());
}

fn to3(v: &Value) -> [f64; 3] {
    let a = v.as_array().unwrap();
    [a[0].as_f64().unwrap(), a[1].as_f64().unwrap(), a[2].as_f64().unwrap()]
}

fn mean_edge(m: &meshwork_core::Mesh, region: &[u32]) -> f64 {
    let mut inr = vec![false; m.vertex_count()];
    region.iter().for_each(|&v| inr[v as usize] = true);
    let (mut s, mut n) = (0.0, 0);
    for f in m.faces.iter() {
        for k in 0..f.len() {
            let (a, b) = (f[k] as usize, f[(k + 1) % f.len()] as usize);
            if inr[a] && inr[b] {
                s += meshwork_core::geometry::dist(m.positions[a], m.positions[b]);
                n += 1;
            }
        }
    }
    s / n.max(1) as f64
}

fn summary(name: &str, r: &Value) {
    let d0 = &r["highlight_deviation_before"];
    let d1 = &r["highlight_deviation_after"];
    println!("== beetle roof, {name}");
    println!(
        "region {} vertices, movable {}, moved {}, iterations {} ({}), e = {:.5}",
        r["region_vertices"],
        r["movable_vertices"],
        r["vertices_moved"],
        r["iterations"],
        r["stop_reason"],
        r["mean_edge_length_region"].as_f64().unwrap()
    );
    println!(
        "highlight lines {} (runs {}, nodes {}), spacing {:.5}",
        r["highlight_before"]["lines"],
        d0["runs"],
        d0["nodes"],
        r["lights"]["spacing"].as_f64().unwrap()
    );
    for k in [
        "mean_distance_relative",
        "max_distance_relative",
        "f_diff_relative",
        "mean_turning_deg",
        "max_turning_deg",
    ] {
        println!("  {k:24} {:>12.5} → {:>12.5}", d0[k].as_f64().unwrap(), d1[k].as_f64().unwrap());
    }
    println!(
        "  {:24} {:>12.5} → {:>12.5}",
        "willmore (eq. 6)",
        r["willmore_before"].as_f64().unwrap(),
        r["willmore_after"].as_f64().unwrap()
    );
    println!(
        "  {:24} {:>12.5} → {:>12.5}",
        "mean curvature sd",
        r["mean_curvature_std_before"].as_f64().unwrap(),
        r["mean_curvature_std_after"].as_f64().unwrap()
    );
    println!(
        "max displacement {:.3e} ({:.4} e), flipped faces {}, min angle {:.2}° → {:.2}°",
        r["max_displacement"].as_f64().unwrap(),
        r["max_displacement_relative"].as_f64().unwrap(),
        r["flipped_faces"],
        r["min_angle_before"].as_f64().unwrap(),
        r["min_angle_after"].as_f64().unwrap()
    );
    println!("stages (ms) {}  total {:.1} ms", r["stages"], r["total_ms"].as_f64().unwrap());
}
