//! Prints the smooth job's stage timings for one mesh and params (profiling aid).
//! usage: bench_smooth_stages MESH.obj '{"method": "taubin"}'
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
    for _ in 0..2 {
        let out = run(JobKind::Smooth, vec![m.clone()], p.clone(), &Progress::new()).unwrap();
        println!(
            "{} total {:.0} solver {}",
            out.report["stages"],
            out.report["total_ms"].as_f64().unwrap(),
            out.report["solver"]
        );
    }
}
