//! Prints the smooth job's stage timings for one mesh and params (profiling aid): the run with
//! the smallest total of `REPS` runs (default 2).
//! usage: bench_smooth_stages MESH.obj '{"method": "taubin"}' [REPS]
use meshwork_core::job::{run, JobKind, Progress};
use std::time::Instant;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    faer::set_global_parallelism(faer::Par::Seq);
    let t = Instant::now();
    let bytes = std::fs::read(&a[1]).unwrap();
    let m = meshwork_core::io::read(&bytes, &Default::default()).unwrap().mesh;
    eprintln!("read {:.0} ms", t.elapsed().as_secs_f64() * 1e3);
    let p: serde_json::Value = serde_json::from_str(a.get(2).map(String::as_str).unwrap_or("{}")).unwrap();
    let reps: usize = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(2);
    let mut best: Option<serde_json::Value> = None;
    for _ in 0..reps {
        let out = run(JobKind::Smooth, vec![m.clone()], p.clone(), &Progress::new()).unwrap();
        let total = out.report["total_ms"].as_f64().unwrap();
        if best.as_ref().is_none_or(|b| total < b["total_ms"].as_f64().unwrap()) {
            best = Some(out.report);
        }
    }
    let r = best.unwrap();
    println!("{} total {:.1} solver {}", r["stages"], r["total_ms"].as_f64().unwrap(), r["solver"]);
}
