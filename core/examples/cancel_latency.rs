//! How long each job runs on after its deadline passes: the time between a job's deadline and
//! its return, sampled at deadlines spread over its run. A long overshoot names a stage whose
//! loops do not poll `progress.check()` (the service's time limit and cancel rely on it).
//!
//! `CARGO_TARGET_DIR=/work/target-release cargo run --release -p meshwork-core --example cancel_latency [SAMPLES]`
//! (meshes from `../shared/meshes/`).

use std::time::{Duration, Instant};

use meshwork_core::io::{read, ReadOptions};
use meshwork_core::job::{run, JobKind};
use meshwork_core::{Mesh, Progress};
use serde_json::{json, Value};

fn load(name: &str) -> Mesh {
    let path = format!("../shared/meshes/{name}");
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    read(&bytes, &ReadOptions::default()).unwrap_or_else(|e| panic!("{path}: {e}")).mesh
}

/// Runs the job with an optional deadline; (elapsed, stage at return, error kind if any).
fn timed(
    kind: JobKind,
    inputs: &[Mesh],
    params: &Value,
    deadline: Option<Duration>,
) -> (Duration, String, String) {
    let progress = Progress::new();
    let t = Instant::now();
    if let Some(d) = deadline {
        progress.set_deadline(t + d);
    }
    let r = run(kind, inputs.to_vec(), params.clone(), &progress);
    let e = t.elapsed();
    (e, progress.snapshot().0, r.err().map(|e| e.kind().to_string()).unwrap_or_else(|| "ok".into()))
}

fn main() {
    let samples: u32 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(12);
    let bunny = load("stanford-bunny.obj");
    let homer = load("homer.obj");
    let mut jobs: Vec<(String, JobKind, Vec<Mesh>, Value)> = vec![
        ("validate".into(), JobKind::Validate, vec![bunny.clone()], json!({})),
        ("repair".into(), JobKind::Repair, vec![bunny.clone()], json!({})),
    ];
    for m in ["laplacian", "taubin", "implicit", "mcf", "inflate", "tangential"] {
        jobs.push((format!("smooth {m}"), JobKind::Smooth, vec![bunny.clone()], json!({ "method": m })));
    }
    for m in ["fair", "highlight"] {
        jobs.push((
            format!("smooth {m}"),
            JobKind::Smooth,
            vec![homer.clone()],
            json!({ "method": m, "region_all": true }),
        ));
    }
    jobs.push((
        "morph spherical".into(),
        JobKind::Morph,
        vec![load("fandisk.obj"), homer.clone()],
        json!({}),
    ));
    jobs.push((
        "morph planar".into(),
        JobKind::Morph,
        vec![load("woody.obj"), load("alligator.obj")],
        json!({}),
    ));

    println!("| job | run (ms) | worst overshoot (ms) | stage it ran on in | results |");
    println!("|---|---|---|---|---|");
    for (name, kind, inputs, params) in &jobs {
        let (full, _, res) = timed(*kind, inputs, params, None);
        if res != "ok" {
            println!("| {name} | failed: {res} | | | |");
            continue;
        }
        let mut worst = (Duration::ZERO, String::new());
        let mut kinds = std::collections::BTreeSet::new();
        for i in 1..=samples {
            let d = full.mul_f64(i as f64 / (samples + 1) as f64);
            let (e, stage, res) = timed(*kind, inputs, params, Some(d));
            kinds.insert(res);
            let over = e.saturating_sub(d);
            if over > worst.0 {
                worst = (over, stage);
            }
        }
        println!(
            "| {name} | {:.0} | {:.1} | {} | {:?} |",
            full.as_secs_f64() * 1e3,
            worst.0.as_secs_f64() * 1e3,
            worst.1,
            kinds
        );
    }
}
