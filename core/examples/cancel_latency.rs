//! How long each job runs on after it is cancelled: the time between `Progress::cancel` (called
//! from another thread, as the service's cancel endpoint does) and the job's return, sampled at
//! cancel times spread over its run. A long overshoot names a stage whose loops do not poll
//! `progress.check()` (the service's time limit and cancel rely on it).
//!
//! `CARGO_TARGET_DIR=/work/target-release cargo run --release -p meshwork-core --example cancel_latency [SAMPLES] [FILTER]`
//! (meshes from `../shared/meshes/`; FILTER keeps the jobs whose name contains it;
//! `CANCEL_EACH=1` prints every cancel's stage and overshoots on stderr; `CANCEL_GAPS=1` instead
//! runs each job once and prints, per stage, the longest CPU stretch between two polls,
//! see [`stage_gaps`]). The inputs
//! are ~100k-vertex meshes: the bunny split once (139k vertices), homer split twice (96k).
//!
//! Two overshoots per cancel: wall time, and the CPU time all threads of this process spent from
//! the cancel to the return (Linux `/proc/self/task/*/schedstat`). On a shared machine the wall
//! time mostly measures how long the job waited for a core; the CPU time is the work it did
//! before it noticed the cancel, which is what the polling controls.

use std::time::{Duration, Instant};

mod bench_support;
use bench_support::process_cpu;

use meshwork_core::fit::testdata::{bend, plane_sections};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::job::{run, JobKind};
use meshwork_core::shapes::subdivide_midpoint;
use meshwork_core::{Mesh, Progress};
use serde_json::{json, Value};

fn load(name: &str) -> Mesh {
    let path = format!("../shared/meshes/{name}");
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    read(&bytes, &ReadOptions::default()).unwrap_or_else(|e| panic!("{path}: {e}")).mesh
}

/// What one run gave: wall and CPU time from the cancel to the return (0 when the job ended
/// first; the run time without a cancel), the stage at return, the error kind or "ok".
struct Timed {
    wall: Duration,
    cpu: Duration,
    stage: String,
    result: String,
}

/// Runs the job, cancelling it `cancel_after` after the start when given.
fn timed(kind: JobKind, inputs: &[Mesh], params: &Value, cancel_after: Option<Duration>) -> Timed {
    let progress = Progress::new();
    let inputs = inputs.to_vec();
    let (t, cpu0) = (Instant::now(), process_cpu());
    let (r, end, cancelled_at) = std::thread::scope(|s| {
        // The canceller notes when it really cancelled: under load its wake-up can be late.
        let canceller = cancel_after.map(|d| {
            let p = progress.clone();
            s.spawn(move || {
                std::thread::sleep(d.saturating_sub(t.elapsed()));
                p.cancel();
                (Instant::now(), process_cpu())
            })
        });
        let r = run(kind, inputs, params.clone(), &progress);
        let end = (Instant::now(), process_cpu());
        (r, end, canceller.and_then(|h| h.join().ok()))
    });
    let (t0, c0) = cancelled_at.unwrap_or((t, cpu0));
    Timed {
        wall: end.0.saturating_duration_since(t0),
        cpu: end.1.saturating_sub(c0),
        stage: progress.snapshot().0,
        result: r.err().map(|e| e.kind().to_string()).unwrap_or_else(|| "ok".into()),
    }
}

/// Runs the job once with a poll listener that notes the process CPU time at every poll
/// (`Progress::check`, directly or through a stage entry or a fraction report) and returns, per
/// stage in run order, the polls made in it and the longest CPU stretch from one poll to the next
/// (the last one of a stage runs to the next stage's entry, so work after a stage's last poll
/// counts for it). A deterministic bound on a cancel's overshoot, whatever the load.
///
/// (Before session 10 this timed progress *reports* only, so a stage polling with plain `check`
/// showed more than its real gap.)
fn stage_gaps(kind: JobKind, inputs: &[Mesh], params: &Value) -> Vec<(String, usize, Duration)> {
    use std::sync::{Arc, Mutex};
    let progress = Progress::new();
    let marks: Arc<Mutex<Vec<(String, Duration)>>> = Arc::default();
    let stage: Arc<Mutex<String>> = Arc::default();
    {
        let stage = stage.clone();
        progress.set_listener(move |s, _| *stage.lock().unwrap_or_else(|e| e.into_inner()) = s.to_string());
    }
    {
        let marks = marks.clone();
        progress.set_poll_listener(move || {
            let cpu = process_cpu();
            let s = stage.lock().unwrap_or_else(|e| e.into_inner()).clone();
            marks.lock().unwrap_or_else(|e| e.into_inner()).push((s, cpu));
        });
    }
    let r = run(kind, inputs.to_vec(), params.clone(), &progress);
    let end = process_cpu();
    if let Err(e) = r {
        eprintln!("  {kind:?}: {e}");
    }
    let marks = marks.lock().unwrap_or_else(|e| e.into_inner()).clone();
    let mut out: Vec<(String, usize, Duration)> = Vec::new();
    for (i, (stage, t)) in marks.iter().enumerate() {
        let next = marks.get(i + 1).map_or(end, |m| m.1);
        let gap = next.saturating_sub(*t);
        match out.last_mut() {
            Some(last) if last.0 == *stage => {
                last.1 += 1;
                last.2 = last.2.max(gap);
            }
            _ => out.push((stage.clone(), 1, gap)),
        }
    }
    out
}

/// The fit's inputs: homer split twice (96k vertices) and bent plane sections of it.
fn fit_inputs(homer: &Mesh) -> Vec<Mesh> {
    let planes: Vec<([f64; 3], f64)> = [0.3013, 0.4517, 0.6021, 0.7519, 0.9011]
        .iter()
        .map(|&y| ([0.0, 1.0, 0.0], y))
        .chain([([1.0, 0.0, 0.0], 0.4987), ([0.0, 0.0, 1.0], 0.4919)])
        .collect();
    let mut curves = plane_sections(homer, &planes);
    for p in curves.positions.iter_mut() {
        *p = bend(*p, 1.0);
    }
    vec![subdivide_midpoint(homer, 2), curves]
}

/// The `k` vertices with the largest y (a connected cap of an upright model).
fn highest(mesh: &Mesh, k: usize) -> Vec<u32> {
    let mut v: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
    v.sort_by(|&a, &b| mesh.positions[b as usize][1].total_cmp(&mesh.positions[a as usize][1]));
    v.truncate(k);
    v
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    let args: Vec<String> = std::env::args().collect();
    let samples: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(12);
    let filter = args.get(2).cloned().unwrap_or_default();
    // CANCEL_EACH=1: every cancel on stderr (where each stage's overshoots are).
    let each = std::env::var("CANCEL_EACH").is_ok();
    let bunny = subdivide_midpoint(&load("stanford-bunny.obj"), 1);
    let homer = load("homer.obj");
    let homer96 = subdivide_midpoint(&homer, 2);
    let mut jobs: Vec<(String, JobKind, Vec<Mesh>, Value)> = vec![
        ("validate".into(), JobKind::Validate, vec![bunny.clone()], json!({})),
        ("convert".into(), JobKind::Convert, vec![bunny.clone()], json!({})),
        ("repair".into(), JobKind::Repair, vec![bunny.clone()], json!({})),
    ];
    for m in ["laplacian", "taubin", "implicit", "mcf", "inflate", "tangential"] {
        jobs.push((format!("smooth {m}"), JobKind::Smooth, vec![bunny.clone()], json!({ "method": m })));
    }
    // Fairing takes a region: the highest vertices (highlight's QP is capped at 50k unknowns).
    jobs.push((
        "smooth fair".into(),
        JobKind::Smooth,
        vec![homer96.clone()],
        json!({ "method": "fair", "region": highest(&homer96, 48_000) }),
    ));
    jobs.push((
        "smooth highlight".into(),
        JobKind::Smooth,
        vec![homer96.clone()],
        json!({ "method": "highlight", "region": highest(&homer96, 30_000) }),
    ));
    jobs.push(("fit".into(), JobKind::Fit, fit_inputs(&homer), json!({})));
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

    if std::env::var("CANCEL_GAPS").is_ok() {
        println!("| job | stage | polls | longest CPU stretch between two polls (ms) |");
        println!("|---|---|---|---|");
        for (name, kind, inputs, params) in jobs.iter().filter(|j| j.0.contains(&filter)) {
            let mut gaps = stage_gaps(*kind, inputs, params);
            gaps.sort_by(|a, b| b.2.cmp(&a.2));
            for (stage, reports, gap) in gaps.iter().take(samples as usize) {
                println!("| {name} | {stage} | {reports} | {:.1} |", gap.as_secs_f64() * 1e3);
            }
        }
        return;
    }
    println!("| job | vertices | run (ms) | worst overshoot, wall (ms) | stage | worst overshoot, CPU (ms) | stage | results |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, kind, inputs, params) in jobs.iter().filter(|j| j.0.contains(&filter)) {
        let verts: Vec<String> = inputs.iter().map(|m| m.vertex_count().to_string()).collect();
        let t = Instant::now();
        if let Err(e) = run(*kind, inputs.clone(), params.clone(), &Progress::new()) {
            println!("| {name} | {} | failed: {e} | | | | | |", verts.join(" + "));
            continue;
        }
        let full = t.elapsed();
        let (mut wall, mut cpu) = ((Duration::ZERO, String::new()), (Duration::ZERO, String::new()));
        let mut kinds = std::collections::BTreeSet::new();
        for i in 1..=samples {
            let d = full.mul_f64(i as f64 / (samples + 1) as f64);
            let r = timed(*kind, inputs, params, Some(d));
            if each {
                eprintln!(
                    "  {name}: cancel at {:.0} ms: {} in {}, wall {:.1} ms, CPU {:.1} ms",
                    d.as_secs_f64() * 1e3,
                    r.result,
                    r.stage,
                    r.wall.as_secs_f64() * 1e3,
                    r.cpu.as_secs_f64() * 1e3
                );
            }
            kinds.insert(r.result);
            if r.wall > wall.0 {
                wall = (r.wall, r.stage.clone());
            }
            if r.cpu > cpu.0 {
                cpu = (r.cpu, r.stage);
            }
        }
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        println!(
            "| {name} | {} | {:.0} | {:.1} | {} | {:.1} | {} | {:?} |",
            verts.join(" + "),
            ms(full),
            ms(wall.0),
            wall.1,
            ms(cpu.0),
            cpu.1,
            kinds
        );
    }
}
