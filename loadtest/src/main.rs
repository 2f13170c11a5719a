//! `loadtest`: drives a running `meshwork serve` with concurrent clients (keep-alive, closed loop)
//! and prints throughput, the answer mix (2xx / 503 / other / transport errors) and latency
//! percentiles. `loadtest inprocess` runs the same job in this process (read → job → write), the
//! baseline for the service-overhead figure. Scenarios and figures: docs/benchmarks.md.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "loadtest", about = "Load generator for the meshwork service")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// POST the file to /v1/{job} from N concurrent clients
    Http {
        #[arg(long, default_value = "http://127.0.0.1:8080")]
        url: String,
        #[arg(long, default_value = "validate")]
        job: String,
        /// Mesh file sent as the raw body
        #[arg(long)]
        file: PathBuf,
        /// Content-Type of the body (default from the extension)
        #[arg(long)]
        content_type: Option<String>,
        /// Extra query string (job params, format), e.g. "method=taubin&iterations=10"
        #[arg(long, default_value = "")]
        query: String,
        #[arg(long, default_value_t = 8)]
        concurrency: usize,
        /// Seconds to run
        #[arg(long, default_value_t = 10.0)]
        duration: f64,
        /// Server pid: sample its RSS (VmRSS/VmHWM from /proc) during the run
        #[arg(long)]
        server_pid: Option<u32>,
        /// Bearer token
        #[arg(long)]
        api_key: Option<String>,
    },
    /// Run the job in this process (read, run, write GLB) `repeat` times; print the timings
    Inprocess {
        #[arg(long, default_value = "validate")]
        job: String,
        #[arg(long)]
        file: PathBuf,
        /// Params JSON
        #[arg(long, default_value = "{}")]
        params: String,
        #[arg(long, default_value_t = 5)]
        repeat: usize,
    },
    /// Write a test mesh: a torus of NU×NV vertices (triangles), e.g. 400×250 = 100k vertices
    GenTorus {
        #[arg(long, default_value_t = 400)]
        nu: usize,
        #[arg(long, default_value_t = 250)]
        nv: usize,
        /// Output file; format from the extension
        #[arg(short, long)]
        output: PathBuf,
    },
}

#[derive(Default)]
struct Tally {
    latencies_ms: Vec<f64>,
    ok: u64,
    busy_503: u64,
    other: Vec<u16>,
    transport: u64,
    bad_503: u64,
}

fn main() {
    match Cli::parse().cmd {
        Cmd::Http { url, job, file, content_type, query, concurrency, duration, server_pid, api_key } => {
            let body =
                Arc::new(std::fs::read(&file).unwrap_or_else(|e| die(&format!("{}: {e}", file.display()))));
            let ctype = content_type.unwrap_or_else(|| {
                meshwork_core::io::Format::from_name(&file.display().to_string())
                    .map_or("application/octet-stream".into(), |f| f.mime().to_string())
            });
            let target = format!("{url}/v1/{job}{}{query}", if query.is_empty() { "" } else { "?" });
            run_http(
                &target,
                body,
                &ctype,
                concurrency,
                Duration::from_secs_f64(duration),
                server_pid,
                api_key,
            );
        }
        Cmd::Inprocess { job, file, params, repeat } => run_inprocess(&job, &file, &params, repeat),
        Cmd::GenTorus { nu, nv, output } => {
            let mesh = meshwork_core::shapes::torus(nu, nv, 1.0, 0.3, false);
            let name = output.display().to_string();
            let format =
                meshwork_core::io::Format::from_name(&name).unwrap_or_else(|| die("unknown extension"));
            let bytes = meshwork_core::io::write(&mesh, format).unwrap_or_else(|e| die(&e.to_string()));
            std::fs::write(&output, bytes).unwrap_or_else(|e| die(&e.to_string()));
            println!("{name}: {} vertices, {} faces", mesh.vertex_count(), mesh.face_count());
        }
    }
}

fn die(msg: &str) -> ! {
    eprintln!("loadtest: {msg}");
    std::process::exit(2)
}

#[allow(clippy::too_many_arguments)]
fn run_http(
    target: &str,
    body: Arc<Vec<u8>>,
    ctype: &str,
    concurrency: usize,
    duration: Duration,
    server_pid: Option<u32>,
    api_key: Option<String>,
) {
    let stop = Arc::new(AtomicBool::new(false));
    let cpu0 = server_pid.and_then(|p| cpu_seconds(&p.to_string()));
    let start = Instant::now();
    let sampler = server_pid.map(|pid| {
        let stop = stop.clone();
        std::thread::spawn(move || {
            let mut peak_rss = 0u64;
            let mut samples = Vec::new();
            while !stop.load(Ordering::Relaxed) {
                if let Some(kb) = proc_status_kb(pid, "VmRSS:") {
                    peak_rss = peak_rss.max(kb);
                    samples.push(kb);
                }
                std::thread::sleep(Duration::from_millis(200));
            }
            (peak_rss, samples, proc_status_kb(pid, "VmHWM:"))
        })
    });
    let workers: Vec<_> = (0..concurrency)
        .map(|_| {
            let (stop, body, target, ctype, key) =
                (stop.clone(), body.clone(), target.to_string(), ctype.to_string(), api_key.clone());
            std::thread::spawn(move || client_loop(&target, &body, &ctype, key.as_deref(), &stop))
        })
        .collect();
    std::thread::sleep(duration);
    stop.store(true, Ordering::Relaxed);
    let mut all = Tally::default();
    for w in workers {
        let t = w.join().unwrap_or_default();
        all.latencies_ms.extend(t.latencies_ms);
        all.ok += t.ok;
        all.busy_503 += t.busy_503;
        all.other.extend(t.other);
        all.transport += t.transport;
        all.bad_503 += t.bad_503;
    }
    let secs = start.elapsed().as_secs_f64();
    let n = all.latencies_ms.len();
    all.latencies_ms.sort_by(f64::total_cmp);
    let pct = |p: f64| {
        if n == 0 {
            f64::NAN
        } else {
            all.latencies_ms[((p / 100.0) * (n - 1) as f64).round() as usize]
        }
    };
    println!("target          {target}");
    println!("concurrency     {concurrency}, {secs:.1} s");
    println!("answered        {n}  ({:.0} req/s)", n as f64 / secs);
    println!("  2xx           {}  ({:.0} req/s)", all.ok, all.ok as f64 / secs);
    println!("  503 busy      {}  (all with Retry-After: {})", all.busy_503, all.bad_503 == 0);
    println!("  other status  {}  {:?}", all.other.len(), summarize(&all.other));
    println!("transport errs  {}", all.transport);
    println!(
        "latency ms      p50 {:.2}  p95 {:.2}  p99 {:.2}  max {:.2}",
        pct(50.0),
        pct(95.0),
        pct(99.0),
        pct(100.0)
    );
    if let (Some(c0), Some(c1)) = (cpu0, server_pid.and_then(|p| cpu_seconds(&p.to_string()))) {
        println!(
            "server CPU      {:.2} s, {:.2} ms per answered request",
            c1 - c0,
            (c1 - c0) * 1e3 / n.max(1) as f64
        );
    }
    if let Some(s) = sampler {
        if let Ok((peak, samples, hwm)) = s.join() {
            let first = samples.first().copied().unwrap_or(0);
            let last = samples.last().copied().unwrap_or(0);
            println!(
                "server RSS MiB  start {:.1}  end {:.1}  peak sampled {:.1}  VmHWM {:.1}",
                first as f64 / 1024.0,
                last as f64 / 1024.0,
                peak as f64 / 1024.0,
                hwm.unwrap_or(0) as f64 / 1024.0
            );
        }
    }
}

fn summarize(codes: &[u16]) -> Vec<(u16, usize)> {
    let mut m = std::collections::BTreeMap::new();
    for c in codes {
        *m.entry(*c).or_insert(0) += 1;
    }
    m.into_iter().collect()
}

fn client_loop(target: &str, body: &[u8], ctype: &str, key: Option<&str>, stop: &AtomicBool) -> Tally {
    let agent: ureq::Agent = ureq::Agent::config_builder()
        .http_status_as_error(false)
        .timeout_global(Some(Duration::from_secs(600)))
        .build()
        .into();
    let mut t = Tally::default();
    let auth = key.map(|k| format!("Bearer {k}"));
    while !stop.load(Ordering::Relaxed) {
        let t0 = Instant::now();
        let mut req = agent.post(target).header("content-type", ctype);
        if let Some(a) = &auth {
            req = req.header("authorization", a);
        }
        match req.send(body) {
            Ok(mut r) => {
                let status = r.status().as_u16();
                let retry = r.headers().contains_key("retry-after");
                let _ = r.body_mut().with_config().limit(1 << 30).read_to_vec();
                t.latencies_ms.push(t0.elapsed().as_secs_f64() * 1e3);
                match status {
                    200..=299 => t.ok += 1,
                    503 => {
                        t.busy_503 += 1;
                        if !retry {
                            t.bad_503 += 1;
                        }
                    }
                    s => t.other.push(s),
                }
            }
            Err(_) => {
                t.transport += 1;
                std::thread::sleep(Duration::from_millis(10));
            }
        }
    }
    t
}

/// CPU seconds (user + system) a process has used, from /proc (clock ticks at 100 Hz).
fn cpu_seconds(pid: &str) -> Option<f64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let rest = s.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    // After the command name: state is field 3, utime 14, stime 15 (1-based over the whole line).
    let ut: f64 = f.get(11)?.parse().ok()?;
    let st: f64 = f.get(12)?.parse().ok()?;
    Some((ut + st) / 100.0)
}

fn proc_status_kb(pid: u32, key: &str) -> Option<u64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    s.lines().find(|l| l.starts_with(key))?.split_whitespace().nth(1)?.parse().ok()
}

fn run_inprocess(job: &str, file: &PathBuf, params: &str, repeat: usize) {
    use meshwork_core::io::{self, Format, ReadOptions};
    use meshwork_core::job::{self, JobKind, Progress};
    let kind = JobKind::parse(job).unwrap_or_else(|| die(&format!("unknown job {job}")));
    let params: serde_json::Value =
        serde_json::from_str(params).unwrap_or_else(|e| die(&format!("params: {e}")));
    let bytes = std::fs::read(file).unwrap_or_else(|e| die(&format!("{}: {e}", file.display())));
    let mut times = Vec::new();
    let cpu0 = cpu_seconds("self");
    for _ in 0..repeat.max(1) {
        let t = Instant::now();
        let mesh = io::read(&bytes, &ReadOptions::default()).unwrap_or_else(|e| die(&e.to_string())).mesh;
        let out = job::run(kind, vec![mesh], params.clone(), &Progress::new())
            .unwrap_or_else(|e| die(&e.to_string()));
        if kind.returns_mesh() {
            let _ = io::write(&out.meshes[0], Format::Glb).unwrap_or_else(|e| die(&e.to_string()));
        }
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    if let (Some(c0), Some(c1)) = (cpu0, cpu_seconds("self")) {
        println!("in-process CPU: {:.2} ms per run", (c1 - c0) * 1e3 / times.len() as f64);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "in-process {job} on {}: {} runs, median {:.1} ms, min {:.1} ms",
        file.display(),
        times.len(),
        times[times.len() / 2],
        times[0]
    );
}
