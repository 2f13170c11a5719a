//! Timing helpers shared by the `bench_*` examples (a folder module, so Cargo does not take it for
//! an example of its own).
#![allow(dead_code)]

use std::time::Instant;

/// Best wall time of `reps` runs (at least one), in ms, and the last run's result. The best, not the
/// mean: on a shared machine the minimum is the least disturbed measurement of the same work.
pub fn best<T>(reps: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut t = f64::INFINITY;
    let mut r = None;
    for _ in 0..reps.max(1) {
        let s = Instant::now();
        let v = f();
        t = t.min(s.elapsed().as_secs_f64() * 1e3);
        r = Some(v);
    }
    (t, r.expect("at least one run"))
}

/// CPU time of all threads of this process so far (0 where /proc cannot tell): under load the
/// wall time mostly measures waiting for a core, this the work done.
pub fn process_cpu() -> std::time::Duration {
    let ns: u64 = std::fs::read_dir("/proc/self/task")
        .map(|d| {
            d.filter_map(|t| t.ok())
                .filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok())
                .filter_map(|s| s.split_whitespace().next().and_then(|v| v.parse::<u64>().ok()))
                .sum()
        })
        .unwrap_or(0);
    std::time::Duration::from_nanos(ns)
}
