//! Validate and repair timings on the shared meshes and a large generated mesh.
//!
//! ```text
//! CARGO_TARGET_DIR=/work/target-release cargo build --release -p meshwork-core --example bench_repair
//! /work/target-release/release/examples/bench_repair [MESH_DIR] [--json]
//! ```
//! Prints one line per mesh: read, topology, validate and repair times (best of 7 runs, 3 above
//! 500k faces: the minimum is the least disturbed by other processes on a shared machine) and
//! the key counts of the reports; `--json` also prints the full reports.

mod bench_support;
use bench_support::best;

use std::path::PathBuf;
use std::time::Instant;

use meshwork_core::io::{self, ReadOptions};
use meshwork_core::job::{self, JobKind, Progress};
use meshwork_core::mesh::Mesh;
use meshwork_core::shapes;
use meshwork_core::topology::Topology;

fn bench(name: &str, mesh: &Mesh, read_ms: f64, json: bool) {
    let runs = if mesh.face_count() > 500_000 { 3 } else { 7 };
    let topo_ms = best(runs, || {
        std::hint::black_box(Topology::new(mesh));
    })
    .0;
    let mut vrep = serde_json::Value::Null;
    let val_ms = best(runs, || {
        vrep = job::run(JobKind::Validate, vec![mesh.clone()], serde_json::Value::Null, &Progress::new())
            .unwrap()
            .report;
    })
    .0;
    let mut rrep = serde_json::Value::Null;
    let rep_ms = best(runs, || {
        rrep = job::run(JobKind::Repair, vec![mesh.clone()], serde_json::Value::Null, &Progress::new())
            .unwrap()
            .report;
    })
    .0;
    println!(
        "{name:<22} V={:<8} F={:<8} read {read_ms:>8.1} ms  topology {topo_ms:>7.1} ms  validate {val_ms:>7.1} ms  repair {rep_ms:>8.1} ms | comps {} loops {} nm_e {} nm_v {} pinch {} chi {} genus {} -> repaired V={} F={} comps {} loops {} closed {} manifold {} genus {} why {}",
        vrep["vertices"], vrep["faces"], vrep["components"], vrep["boundary_loops"], vrep["non_manifold_edges"],
        vrep["non_manifold_vertices"], vrep["pinch_vertices"], vrep["euler_characteristic"], vrep["genus"],
        rrep["output"]["vertices"], rrep["output"]["faces"], rrep["output"]["components"], rrep["output"]["boundary_loops"],
        rrep["closed"], rrep["manifold"], rrep["output"]["genus"], rrep["why_not"],
    );
    if json {
        println!(
            "{}\n{}",
            serde_json::to_string_pretty(&vrep).unwrap(),
            serde_json::to_string_pretty(&rrep).unwrap()
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let json = args.iter().any(|a| a == "--json");
    let dir = args
        .iter()
        .find(|a| !a.starts_with("--"))
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes"));
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "obj"))
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    for p in names {
        let bytes = std::fs::read(&p).unwrap();
        let t = Instant::now();
        let mesh = io::read(&bytes, &ReadOptions::default()).unwrap().mesh;
        let read_ms = t.elapsed().as_secs_f64() * 1e3;
        bench(&p.file_name().unwrap().to_string_lossy(), &mesh, read_ms, json);
    }
    // ~1M faces: a subdivided icosphere (level 7: 327,680 faces; level 8: 1,310,720).
    let big = shapes::icosphere(8, 1.0);
    bench("icosphere-8 (1.3M F)", &big, 0.0, false);
}
