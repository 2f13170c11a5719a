//! Server configuration. Precedence: flags > environment (`MESHWORK_*`) > TOML file > the embedded
//! defaults in `config.default.toml` (which also document every key).

use std::path::PathBuf;

use serde::Deserialize;

use crate::runner::Limits;

const DEFAULTS: &str = include_str!("../config.default.toml");

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    pub bind: String,
    pub workers: usize,
    pub queue: usize,
    pub job_timeout_secs: f64,
    pub result_ttl_secs: f64,
    pub store_bytes: u64,
    pub store_jobs: usize,
    pub api_key: String,
    pub cors_origins: Vec<String>,
    pub shutdown_grace_secs: f64,
    pub debug_jobs: bool,
    pub log: String,
    pub limits: Limits,
}

/// `meshwork serve` flags; each also reads its environment variable (clap: flag > env).
#[derive(clap::Args, Debug, Default, Clone)]
pub struct ServeArgs {
    /// TOML configuration file
    #[arg(long, env = "MESHWORK_CONFIG")]
    pub config: Option<PathBuf>,
    /// Address to listen on, e.g. 0.0.0.0:8080 (port 0 = any free port)
    #[arg(long, env = "MESHWORK_BIND")]
    pub bind: Option<String>,
    /// Port (replaces the port of --bind)
    #[arg(long, env = "MESHWORK_PORT")]
    pub port: Option<u16>,
    /// Job threads (0 = one per core)
    #[arg(long, env = "MESHWORK_WORKERS")]
    pub workers: Option<usize>,
    /// Jobs admitted beyond the running ones before 503
    #[arg(long, env = "MESHWORK_QUEUE")]
    pub queue: Option<usize>,
    /// Per-job time limit in seconds
    #[arg(long, env = "MESHWORK_JOB_TIMEOUT")]
    pub job_timeout: Option<f64>,
    /// Seconds a finished async job's result is kept
    #[arg(long, env = "MESHWORK_RESULT_TTL")]
    pub result_ttl: Option<f64>,
    /// Memory bound for kept results, bytes
    #[arg(long, env = "MESHWORK_STORE_BYTES")]
    pub store_bytes: Option<u64>,
    /// Bearer token required on /v1/*
    #[arg(long, env = "MESHWORK_API_KEY", hide_env_values = true)]
    pub api_key: Option<String>,
    /// CORS origins, comma separated ("*" for any)
    #[arg(long, env = "MESHWORK_CORS_ORIGINS", value_delimiter = ',')]
    pub cors_origins: Option<Vec<String>>,
    /// Seconds running jobs may finish after SIGTERM
    #[arg(long, env = "MESHWORK_SHUTDOWN_GRACE")]
    pub shutdown_grace: Option<f64>,
    /// Request body limit, bytes
    #[arg(long, env = "MESHWORK_MAX_BODY_BYTES")]
    pub max_body_bytes: Option<u64>,
    #[arg(long, env = "MESHWORK_MAX_VERTICES")]
    pub max_vertices: Option<u64>,
    #[arg(long, env = "MESHWORK_MAX_FACES")]
    pub max_faces: Option<u64>,
    #[arg(long, env = "MESHWORK_MAX_ITERATIONS")]
    pub max_iterations: Option<u64>,
    #[arg(long, env = "MESHWORK_MAX_FRAMES")]
    pub max_frames: Option<u64>,
    #[arg(long, env = "MESHWORK_MAX_CURVE_POINTS")]
    pub max_curve_points: Option<u64>,
    /// Enable the `sleep` and `panic` test jobs
    #[arg(long, env = "MESHWORK_DEBUG_JOBS")]
    pub debug_jobs: bool,
    /// Log filter (RUST_LOG syntax)
    #[arg(long, env = "MESHWORK_LOG")]
    pub log: Option<String>,
}

impl Config {
    /// Embedded defaults, overlaid with the TOML file (if any), then with flags/env.
    pub fn load(args: &ServeArgs) -> Result<Config, String> {
        let mut table: toml::Table = DEFAULTS.parse().map_err(|e| format!("embedded defaults: {e}"))?;
        if let Some(path) = &args.config {
            let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            let file: toml::Table = text.parse().map_err(|e| format!("{}: {e}", path.display()))?;
            overlay(&mut table, file);
        }
        let mut c: Config =
            toml::Value::Table(table).try_into().map_err(|e| format!("configuration: {e}"))?;
        c.apply(args)?;
        Ok(c)
    }

    fn apply(&mut self, a: &ServeArgs) -> Result<(), String> {
        if let Some(b) = &a.bind {
            self.bind = b.clone();
        }
        if let Some(p) = a.port {
            let host = self.bind.rsplit_once(':').map(|(h, _)| h).unwrap_or("127.0.0.1");
            self.bind = format!("{host}:{p}");
        }
        set(&mut self.workers, a.workers);
        set(&mut self.queue, a.queue);
        set(&mut self.job_timeout_secs, a.job_timeout);
        set(&mut self.result_ttl_secs, a.result_ttl);
        set(&mut self.store_bytes, a.store_bytes);
        set(&mut self.api_key, a.api_key.clone());
        set(&mut self.cors_origins, a.cors_origins.clone());
        set(&mut self.shutdown_grace_secs, a.shutdown_grace);
        set(&mut self.limits.max_body_bytes, a.max_body_bytes);
        set(&mut self.limits.max_vertices, a.max_vertices);
        set(&mut self.limits.max_faces, a.max_faces);
        set(&mut self.limits.max_iterations, a.max_iterations);
        set(&mut self.limits.max_frames, a.max_frames);
        set(&mut self.limits.max_curve_points, a.max_curve_points);
        set(&mut self.log, a.log.clone());
        self.debug_jobs |= a.debug_jobs;
        if self.workers == 0 {
            self.workers = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
        }
        for (name, v) in [
            ("job_timeout_secs", self.job_timeout_secs),
            ("result_ttl_secs", self.result_ttl_secs),
            ("shutdown_grace_secs", self.shutdown_grace_secs),
        ] {
            // Bounded so that a Duration and an Instant can hold it: `--job-timeout 1e300` failed
            // every job with a panic, `--result-ttl`/`--shutdown-grace 1e300` the start-up.
            if !(v.is_finite() && v >= 0.0 && v <= MAX_SECS) {
                return Err(format!("{name} must be a number of seconds in [0, {MAX_SECS:e}], got {v}"));
            }
        }
        Ok(())
    }

    /// Jobs admitted at once (running + waiting).
    pub fn admitted(&self) -> usize {
        self.workers + self.queue
    }
}

/// The longest time setting accepted (about 31 years).
const MAX_SECS: f64 = 1e9;

fn set<T>(slot: &mut T, v: Option<T>) {
    if let Some(v) = v {
        *slot = v;
    }
}

/// Recursive table overlay (`top` wins), so a file may set one key of `[limits]`.
fn overlay(base: &mut toml::Table, top: toml::Table) {
    for (k, v) in top {
        match (base.get_mut(&k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(t)) => overlay(b, t),
            (_, v) => {
                base.insert(k, v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_parse_and_listen_on_localhost_8080() {
        let c = Config::load(&ServeArgs::default()).unwrap();
        assert_eq!(c.bind, "127.0.0.1:8080");
        assert!(c.workers >= 1);
        assert_eq!(c.limits.max_iterations, 10_000);
    }

    #[test]
    fn file_then_flags_take_precedence() {
        let dir = std::env::temp_dir().join(format!("mw-config-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("c.toml");
        std::fs::write(&f, "queue = 3\nworkers = 2\n[limits]\nmax_frames = 7\n").unwrap();
        let args =
            ServeArgs { config: Some(f.clone()), workers: Some(5), port: Some(0), ..Default::default() };
        let c = Config::load(&args).unwrap();
        assert_eq!((c.queue, c.workers, c.limits.max_frames), (3, 5, 7));
        assert_eq!(c.limits.max_faces, 10_000_000, "untouched keys keep their defaults");
        assert_eq!(c.bind, "127.0.0.1:0");
        std::fs::write(&f, "queu = 3\n").unwrap();
        let e = Config::load(&ServeArgs { config: Some(f), ..Default::default() }).unwrap_err();
        assert!(e.contains("queu"), "{e}");
    }

    /// Found by the CLI fuzz campaign: `serve --job-timeout 1e300` answered every job with a 500
    /// (the handler panicked converting it to a Duration), `--result-ttl 1e300` and
    /// `--shutdown-grace 1e300` panicked at start-up (exit 101). They are now refused by name.
    #[test]
    fn times_too_long_to_represent_are_refused_by_name() {
        let base = ServeArgs { port: Some(0), ..Default::default() };
        for (args, name) in [
            (ServeArgs { job_timeout: Some(1e300), ..base.clone() }, "job_timeout_secs"),
            (ServeArgs { result_ttl: Some(1e300), ..base.clone() }, "result_ttl_secs"),
            (ServeArgs { shutdown_grace: Some(1e300), ..base.clone() }, "shutdown_grace_secs"),
        ] {
            let e = Config::load(&args).unwrap_err();
            assert!(e.contains(name) && e.contains("1e9"), "{e}");
        }
        let c = Config::load(&ServeArgs { job_timeout: Some(1e9), ..base }).unwrap();
        assert!(std::time::Instant::now()
            .checked_add(std::time::Duration::from_secs_f64(c.job_timeout_secs))
            .is_some());
    }
}
