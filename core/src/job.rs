//! What every job shares: progress/cancellation, per-stage timings, the output, and the one
//! dispatcher the CLI and the HTTP service both call (so both get the same schema, defaults and
//! validation).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Shared between a running job and whoever watches it (CLI progress line, HTTP status endpoint).
/// Cloning is cheap; all clones see the same state. Jobs call [`Progress::check`] in every loop so
/// that cancellation and time limits take effect at the next iteration.
#[derive(Clone, Default)]
pub struct Progress {
    inner: Arc<ProgressInner>,
}

#[derive(Default)]
struct ProgressInner {
    cancelled: AtomicBool,
    deadline: Mutex<Option<Instant>>,
    stage: Mutex<String>,
    fraction_bits: AtomicU64,
    listener: Mutex<Option<Listener>>,
    /// Calls of [`Progress::check`] so far, and the call at which to cancel (0: none).
    checks: AtomicU64,
    cancel_at_check: AtomicU64,
    /// Called at every poll ([`Progress::set_poll_listener`]); the flag spares the lock when unset.
    poll_listener: Mutex<Option<PollListener>>,
    has_poll_listener: AtomicBool,
}

type Listener = Box<dyn Fn(&str, f64) + Send + Sync>;
type PollListener = Box<dyn Fn() + Send + Sync>;

impl Progress {
    pub fn new() -> Self {
        Self::default()
    }

    /// Runs the polled form of a function without a job around it (tests, benchmarks, callers
    /// with nothing to cancel), for functions whose only error is [`Progress::check`]'s: a fresh
    /// `Progress` has no cancel, no deadline and no cancel-at-check, so that error cannot happen.
    /// One place for that argument instead of an `expect` beside every unpolled wrapper.
    pub fn unpolled<T>(f: impl FnOnce(&Progress) -> Result<T>) -> T {
        match f(&Progress::new()) {
            Ok(v) => v,
            Err(e) => unreachable!("a fresh Progress never stops a job, yet the call failed: {e}"),
        }
    }

    /// After `deadline`, [`Progress::check`] fails with [`Error::TimedOut`].
    pub fn set_deadline(&self, deadline: Instant) {
        *lock(&self.inner.deadline) = Some(deadline);
    }

    /// Called on every stage change and fraction update (keep it cheap).
    pub fn set_listener(&self, f: impl Fn(&str, f64) + Send + Sync + 'static) {
        *lock(&self.inner.listener) = Some(Box::new(f));
    }

    /// Called at every poll ([`Progress::check`], directly or through `stage`/`fraction`), before
    /// the cancel test: a measuring tool's hook (`cancel_latency`'s `CANCEL_GAPS` times the work
    /// between two polls, which is what bounds a cancel's overshoot), not a progress display.
    pub fn set_poll_listener(&self, f: impl Fn() + Send + Sync + 'static) {
        *lock(&self.inner.poll_listener) = Some(Box::new(f));
        self.inner.has_poll_listener.store(true, Ordering::Relaxed);
    }

    pub fn cancel(&self) {
        self.inner.cancelled.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.inner.cancelled.load(Ordering::Relaxed)
    }

    /// Err when the job should stop now: cancelled or past its deadline.
    pub fn check(&self) -> Result<()> {
        if self.inner.has_poll_listener.load(Ordering::Relaxed) {
            if let Some(l) = lock(&self.inner.poll_listener).as_ref() {
                l();
            }
        }
        let n = self.inner.checks.fetch_add(1, Ordering::Relaxed) + 1;
        if n == self.inner.cancel_at_check.load(Ordering::Relaxed) {
            self.cancel();
        }
        if self.is_cancelled() {
            return Err(Error::Cancelled);
        }
        if let Some(d) = *lock(&self.inner.deadline) {
            if Instant::now() >= d {
                return Err(Error::TimedOut);
            }
        }
        Ok(())
    }

    /// [`Progress::check`] at every `period`-th index `i` of a loop, nothing otherwise: for loops
    /// whose single iteration is too cheap to pay a check (choose `period` for a few ms).
    pub fn check_every(&self, i: usize, period: usize) -> Result<()> {
        if i % period.max(1) == 0 {
            self.check()
        } else {
            Ok(())
        }
    }

    /// How many times [`Progress::check`] ran (directly or through `stage`/`fraction`): tests
    /// count the polls inside a stage with it.
    pub fn checks(&self) -> u64 {
        self.inner.checks.load(Ordering::Relaxed)
    }

    /// Cancels at the `n`-th call of [`Progress::check`] (counting from 1), which then fails:
    /// a deterministic cancel for tests, at any poll of a job.
    pub fn cancel_at_check(&self, n: u64) {
        self.inner.cancel_at_check.store(n, Ordering::Relaxed);
    }

    /// Enters a new stage (fraction resets to 0) and checks for cancellation.
    pub fn stage(&self, name: &str) -> Result<()> {
        *lock(&self.inner.stage) = name.to_string();
        self.inner.fraction_bits.store(0f64.to_bits(), Ordering::Relaxed);
        self.notify();
        self.check()
    }

    /// Fraction of the current stage done, 0..=1; also checks for cancellation.
    pub fn fraction(&self, f: f64) -> Result<()> {
        self.inner.fraction_bits.store(f.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
        self.notify();
        self.check()
    }

    /// (stage, fraction) as last reported.
    pub fn snapshot(&self) -> (String, f64) {
        (lock(&self.inner.stage).clone(), f64::from_bits(self.inner.fraction_bits.load(Ordering::Relaxed)))
    }

    fn notify(&self) {
        if let Some(l) = lock(&self.inner.listener).as_ref() {
            let (s, f) = self.snapshot();
            l(&s, f);
        }
    }
}

/// Runs `f` on a thread of its own and waits for it, polling `progress` every millisecond: the
/// job stops within a poll of a cancel even while `f` is a call it cannot interrupt (faer's
/// sparse Cholesky, ~0.1–1 s on 100k unknowns). On a cancel the call finishes in the background
/// and its result is dropped (it holds only its own copies of the data).
pub fn interruptible<T: Send + 'static>(
    progress: &Progress,
    f: impl FnOnce() -> T + Send + 'static,
) -> Result<T> {
    use std::sync::mpsc::{sync_channel, RecvTimeoutError};
    progress.check()?;
    let (tx, rx) = sync_channel(1);
    std::thread::Builder::new()
        .name("meshwork-uninterruptible".into())
        .spawn(move || {
            // The receiver is gone when the job was cancelled: nothing to hand the result to.
            let _ = tx.send(f());
        })
        .map_err(|e| Error::Internal(format!("cannot start a worker thread: {e}")))?;
    loop {
        match rx.recv_timeout(std::time::Duration::from_millis(1)) {
            Ok(v) => return Ok(v),
            Err(RecvTimeoutError::Timeout) => progress.check()?,
            Err(RecvTimeoutError::Disconnected) => {
                return Err(Error::Internal("a worker thread panicked".into()));
            }
        }
    }
}

/// Locks a mutex, recovering the data if a panicking thread poisoned it (progress state is plain
/// data; a panic elsewhere must not turn every later status call into a second panic).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Wall-clock time per stage, in the order the stages ran; serialised into every report.
#[derive(Debug, Clone)]
pub struct Stages {
    start: Instant,
    stages: Vec<(String, f64)>,
}

impl Default for Stages {
    fn default() -> Self {
        Self::new()
    }
}

impl Stages {
    pub fn new() -> Self {
        Stages { start: Instant::now(), stages: Vec::new() }
    }

    /// Runs `f` as stage `name`, telling `progress` and recording its duration.
    pub fn run<T>(&mut self, progress: &Progress, name: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        progress.stage(name)?;
        let t = Instant::now();
        let r = f()?;
        self.stages.push((name.to_string(), t.elapsed().as_secs_f64() * 1e3));
        Ok(r)
    }

    pub fn total_ms(&self) -> f64 {
        self.start.elapsed().as_secs_f64() * 1e3
    }

    /// `{"stage": ms, …}` in run order.
    pub fn to_json(&self) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        for (k, v) in &self.stages {
            m.insert(k.clone(), serde_json::json!(round3(*v)));
        }
        serde_json::Value::Object(m)
    }
}

fn round3(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}

/// What a job hands back: zero or more meshes, files the job encoded itself, and a JSON report.
#[derive(Debug, Clone, Default)]
pub struct Output {
    pub meshes: Vec<Mesh>,
    /// Files a plain [`Mesh`] cannot hold (the morph's animated GLB with morph targets). When
    /// present, the service returns the first artifact instead of encoding `meshes[0]`.
    pub artifacts: Vec<Artifact>,
    pub report: serde_json::Value,
}

/// A finished file produced by a job.
#[derive(Debug, Clone)]
pub struct Artifact {
    /// Suggested file name, e.g. `morph.glb`.
    pub name: String,
    pub media_type: String,
    pub bytes: Vec<u8>,
}

/// The jobs the CLI and the service expose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum JobKind {
    /// Validation report only; no mesh out.
    Validate,
    /// Read and write again (format conversion); no change to the mesh.
    Convert,
    Repair,
    Smooth,
    /// Deform a template so that it passes through a curve network (seed 000). Inputs: template, curves.
    Fit,
    /// Morph sequence between meshes of different connectivity (seeds 002/003). Inputs: 2 or more meshes.
    Morph,
}

impl JobKind {
    pub const ALL: [JobKind; 6] =
        [JobKind::Validate, JobKind::Convert, JobKind::Repair, JobKind::Smooth, JobKind::Fit, JobKind::Morph];

    pub fn name(self) -> &'static str {
        match self {
            JobKind::Validate => "validate",
            JobKind::Convert => "convert",
            JobKind::Repair => "repair",
            JobKind::Smooth => "smooth",
            JobKind::Fit => "fit",
            JobKind::Morph => "morph",
        }
    }

    pub fn parse(s: &str) -> Option<JobKind> {
        JobKind::ALL.into_iter().find(|k| k.name() == s)
    }

    /// How many input meshes the job takes (min, max).
    pub fn inputs(self) -> (usize, usize) {
        match self {
            JobKind::Fit => (2, 2),
            JobKind::Morph => (2, 16),
            _ => (1, 1),
        }
    }

    /// Whether the job produces a mesh (validate produces only a report).
    pub fn returns_mesh(self) -> bool {
        !matches!(self, JobKind::Validate)
    }
}

/// Deserialises `params` for a job, naming the offending field on error (its JSON path, e.g.
/// `method` for a bad enum value, `weights[3]` inside a list; unknown fields by their name).
pub fn parse_params<P: serde::de::DeserializeOwned>(params: serde_json::Value) -> Result<P> {
    let params = if params.is_null() { serde_json::Value::Object(Default::default()) } else { params };
    serde_path_to_error::deserialize(params).map_err(|e| {
        let path = e.path().to_string();
        let msg = e.into_inner().to_string();
        let field = if path.is_empty() || path == "." {
            // serde's messages name the field ("unknown field `foo`", "missing field `bar`").
            msg.split('`').nth(1).unwrap_or("params").to_string()
        } else {
            path
        };
        Error::params(field, msg)
    })
}

/// Runs a job on already-read meshes. The one entry point for the CLI and the service.
pub fn run(
    kind: JobKind,
    mut inputs: Vec<Mesh>,
    params: serde_json::Value,
    progress: &Progress,
) -> Result<Output> {
    let (lo, hi) = kind.inputs();
    if inputs.len() < lo || inputs.len() > hi {
        return Err(Error::params(
            "inputs",
            format!("{} takes {lo}..={hi} meshes, got {}", kind.name(), inputs.len()),
        ));
    }
    // Every job but `convert` squares lengths; finite coordinates whose squares overflow would come
    // out as degenerate faces, an empty mesh or an internal error, so they are refused here, once
    // for all formats (the readers refuse NaN and infinity themselves, naming the line or accessor).
    // `convert` only rewrites the numbers, exactly.
    if kind != JobKind::Convert {
        for m in &inputs {
            m.check_coordinate_range()?;
        }
    }
    match kind {
        JobKind::Validate => crate::validate::run(&inputs[0], &parse_params(params)?, progress),
        JobKind::Convert => {
            let _: EmptyParams = parse_params(params)?;
            let mut stages = Stages::new();
            let mesh = stages.run(progress, "convert", || Ok(inputs.swap_remove(0)))?;
            let report = serde_json::json!({
                "vertices": mesh.vertex_count(),
                "faces": mesh.face_count(),
                "total_ms": stages.total_ms(),
                "stages": stages.to_json(),
            });
            Ok(Output { meshes: vec![mesh], report, ..Default::default() })
        }
        JobKind::Repair => crate::repair::run(inputs.swap_remove(0), &parse_params(params)?, progress),
        JobKind::Smooth => crate::smooth::run(inputs.swap_remove(0), &parse_params(params)?, progress),
        JobKind::Fit => crate::fit::run(inputs, &parse_params(params)?, progress),
        JobKind::Morph => crate::morph::run(inputs, &parse_params(params)?, progress),
    }
}

/// Parameters of a job that takes none; unknown fields are still refused.
#[derive(Debug, Clone, Default, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct EmptyParams {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cancel_and_deadline_stop_check() {
        let p = Progress::new();
        assert!(p.check().is_ok());
        p.cancel();
        assert!(matches!(p.check(), Err(Error::Cancelled)));
        let q = Progress::new();
        q.set_deadline(Instant::now());
        assert!(matches!(q.check(), Err(Error::TimedOut)));
    }

    #[test]
    fn unknown_param_is_named() {
        let e = parse_params::<EmptyParams>(serde_json::json!({"bogus": 1})).unwrap_err();
        match e {
            Error::InvalidParams { field, .. } => assert_eq!(field, "bogus"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn bad_value_names_its_field_not_the_value() {
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        enum Method {
            #[serde(rename = "taubin")]
            Taubin,
        }
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct P {
            method: Method,
        }
        match parse_params::<P>(serde_json::json!({"method": "nope"})).unwrap_err() {
            Error::InvalidParams { field, message } => {
                assert_eq!(field, "method");
                assert!(message.contains("nope"), "{message}");
            }
            other => panic!("{other:?}"),
        }
    }
}
