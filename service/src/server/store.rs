//! Where jobs live between submission and retrieval. Bounded in count and in result bytes: when
//! either bound is passed, the oldest finished jobs lose their result first (their status then
//! says `removed: "evicted"`), and finished jobs older than the TTL lose it too (`"expired"`).
//! The small status record outlives its result so a client learns why the result is gone.

use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use meshwork_core::job::Progress;
use serde::Serialize;
use serde_json::Value;

use super::problem::Problem;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum State {
    Queued,
    Running,
    Succeeded,
    Failed,
    Cancelled,
}

impl State {
    pub fn finished(self) -> bool {
        matches!(self, State::Succeeded | State::Failed | State::Cancelled)
    }
}

/// An encoded result file.
pub struct ResultFile {
    pub bytes: Vec<u8>,
    pub media_type: String,
    pub extension: String,
}

struct Record {
    kind: &'static str,
    state: State,
    progress: Progress,
    created: SystemTime,
    started: Option<SystemTime>,
    finished: Option<(SystemTime, Instant)>,
    result: Option<Arc<ResultFile>>,
    report: Option<Arc<Value>>,
    problem: Option<Problem>,
    removed: Option<&'static str>,
    /// Bytes this record holds (result + report), counted against the store's bound.
    bytes: usize,
}

/// What `GET /v1/jobs/{id}` returns.
#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct JobStatus {
    /// Random 128-bit id, hex.
    pub id: String,
    /// Job kind (`smooth`, …).
    pub job: String,
    pub state: State,
    /// Current stage as reported by the job.
    pub stage: String,
    /// Fraction of the current stage done, 0..1 (1 when succeeded).
    pub progress: f64,
    /// Seconds since the Unix epoch.
    pub created_at: f64,
    pub started_at: Option<f64>,
    pub finished_at: Option<f64>,
    /// When the result will expire (Unix seconds), for finished jobs still holding one.
    pub expires_at: Option<f64>,
    /// `expired` (TTL passed) or `evicted` (memory bound; oldest first) when the result is gone.
    pub removed: Option<String>,
    /// The failure, for failed and cancelled jobs.
    pub error: Option<Problem>,
    /// Relative URLs: `result`, `report`.
    pub links: Links,
}

#[derive(Debug, Clone, Serialize, utoipa::ToSchema)]
pub struct Links {
    #[serde(rename = "self")]
    pub self_: String,
    pub result: String,
    pub report: String,
}

pub struct Store {
    inner: Mutex<Inner>,
    ttl: Duration,
    max_bytes: usize,
    max_jobs: usize,
    tombstone_min: Duration,
}

struct Inner {
    map: HashMap<String, Record>,
    /// Finished ids, oldest first (eviction and expiry order).
    finished: VecDeque<String>,
    bytes: usize,
}

fn unix(t: SystemTime) -> f64 {
    t.duration_since(UNIX_EPOCH).map(|d| d.as_secs_f64()).unwrap_or(0.0)
}

/// A random 128-bit id in hex.
pub fn new_id() -> String {
    let mut b = [0u8; 16];
    if getrandom::fill(&mut b).is_err() {
        // No OS randomness is a broken host; fall back to time + counter rather than fail requests.
        let n = SystemTime::now().duration_since(UNIX_EPOCH).map(|d| d.as_nanos()).unwrap_or(0);
        static C: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let c = C.fetch_add(1, std::sync::atomic::Ordering::Relaxed) as u128;
        b = (n ^ (c << 64)).to_le_bytes();
    }
    b.iter().map(|x| format!("{x:02x}")).collect()
}

impl Store {
    pub fn new(ttl: Duration, max_bytes: usize, max_jobs: usize) -> Store {
        Store {
            inner: Mutex::new(Inner { map: HashMap::new(), finished: VecDeque::new(), bytes: 0 }),
            ttl,
            max_bytes,
            max_jobs: max_jobs.max(1),
            tombstone_min: Duration::from_secs(600),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub fn insert(&self, kind: &'static str, progress: Progress) -> String {
        let id = new_id();
        let rec = Record {
            kind,
            state: State::Queued,
            progress,
            created: SystemTime::now(),
            started: None,
            finished: None,
            result: None,
            report: None,
            problem: None,
            removed: None,
            bytes: 0,
        };
        self.lock().map.insert(id.clone(), rec);
        id
    }

    pub fn set_running(&self, id: &str) {
        if let Some(r) = self.lock().map.get_mut(id) {
            r.state = State::Running;
            r.started = Some(SystemTime::now());
        }
    }

    /// Records the outcome. `result` is kept only for async jobs (sync ones already sent it).
    pub fn finish(&self, id: &str, outcome: Result<(Option<ResultFile>, Value), Problem>) {
        let mut g = self.lock();
        let inner = &mut *g;
        let Some(r) = inner.map.get_mut(id) else { return };
        r.finished = Some((SystemTime::now(), Instant::now()));
        match outcome {
            Ok((result, report)) => {
                r.state = State::Succeeded;
                r.bytes = result.as_ref().map_or(0, |f| f.bytes.len()) + approx_json_bytes(&report);
                r.result = result.map(Arc::new);
                r.report = Some(Arc::new(report));
            }
            Err(p) => {
                r.state = if p.kind() == "cancelled" { State::Cancelled } else { State::Failed };
                r.problem = Some(p);
            }
        }
        inner.bytes += r.bytes;
        inner.finished.push_back(id.to_string());
        self.enforce_bounds(inner);
    }

    /// Oldest finished first: drop results past the byte bound, drop records past the count bound.
    fn enforce_bounds(&self, inner: &mut Inner) {
        let mut i = 0;
        while inner.bytes > self.max_bytes && i < inner.finished.len() {
            let id = inner.finished[i].clone();
            if let Some(r) = inner.map.get_mut(&id) {
                if r.bytes > 0 {
                    inner.bytes -= r.bytes;
                    drop_result(r, "evicted");
                }
            }
            i += 1;
        }
        while inner.map.len() > self.max_jobs {
            let Some(id) = inner.finished.pop_front() else { break };
            if let Some(r) = inner.map.remove(&id) {
                inner.bytes -= r.bytes;
            }
        }
    }

    /// Expires results older than the TTL, and forgets records once the TTL has passed a second
    /// time (at least 10 minutes) so that clients can still learn why a result is gone.
    /// `finished` is in finish order, so ages only decrease along it.
    pub fn sweep(&self) {
        let mut g = self.lock();
        let inner = &mut *g;
        let now = Instant::now();
        let age = |r: &Record| r.finished.map_or(Duration::ZERO, |(_, t)| now.saturating_duration_since(t));
        let forget_after = self.ttl + self.ttl.max(self.tombstone_min);
        while let Some(id) = inner.finished.front() {
            match inner.map.get(id) {
                Some(r) if age(r) < forget_after => break,
                Some(_) => {
                    if let Some(r) = inner.map.remove(id) {
                        inner.bytes -= r.bytes;
                    }
                }
                None => {}
            }
            inner.finished.pop_front();
        }
        for id in inner.finished.iter() {
            let Some(r) = inner.map.get_mut(id) else { continue };
            if age(r) < self.ttl {
                break;
            }
            if r.removed.is_none() {
                inner.bytes -= r.bytes;
                drop_result(r, "expired");
            }
        }
    }

    pub fn status(&self, id: &str) -> Option<JobStatus> {
        let g = self.lock();
        g.map.get(id).map(|r| self.view(id, r))
    }

    fn view(&self, id: &str, r: &Record) -> JobStatus {
        let (stage, mut progress) = r.progress.snapshot();
        if r.state == State::Succeeded {
            progress = 1.0;
        }
        let base = format!("/v1/jobs/{id}");
        JobStatus {
            id: id.to_string(),
            job: r.kind.to_string(),
            state: r.state,
            stage,
            progress,
            created_at: unix(r.created),
            started_at: r.started.map(unix),
            finished_at: r.finished.map(|(t, _)| unix(t)),
            expires_at: match (r.finished, r.removed) {
                (Some((t, _)), None) => Some(unix(t) + self.ttl.as_secs_f64()),
                _ => None,
            },
            removed: r.removed.map(String::from),
            error: r.problem.clone(),
            links: Links { result: format!("{base}/result"), report: format!("{base}/report"), self_: base },
        }
    }

    /// The result file, or why there is none.
    pub fn result(&self, id: &str) -> Result<Arc<ResultFile>, Problem> {
        let g = self.lock();
        let r = g.map.get(id).ok_or_else(|| unknown(id))?;
        if let Some(f) = &r.result {
            return Ok(f.clone());
        }
        Err(self.why_not(id, r, "result"))
    }

    pub fn report(&self, id: &str) -> Result<Arc<Value>, Problem> {
        let g = self.lock();
        let r = g.map.get(id).ok_or_else(|| unknown(id))?;
        if let Some(v) = &r.report {
            return Ok(v.clone());
        }
        Err(self.why_not(id, r, "report"))
    }

    fn why_not(&self, id: &str, r: &Record, what: &str) -> Problem {
        if let Some(how) = r.removed {
            return Problem::new("gone", format!("the {what} of job {id} was {how}")).with("job_id", id);
        }
        match r.state {
            State::Queued | State::Running => {
                Problem::new("conflict", format!("job {id} is still {:?}", r.state).to_lowercase())
                    .with("job_id", id)
            }
            State::Failed | State::Cancelled => {
                r.problem.clone().unwrap_or_else(|| Problem::new("internal", ""))
            }
            // A sync job's result went back in its response and is not kept.
            State::Succeeded => {
                Problem::not_found(format!("job {id} keeps no {what} (it was returned synchronously)"))
            }
        }
    }

    /// Requests cancellation; 409 when the job already finished.
    pub fn cancel(&self, id: &str) -> Result<JobStatus, Problem> {
        let g = self.lock();
        let r = g.map.get(id).ok_or_else(|| unknown(id))?;
        if r.state.finished() {
            return Err(Problem::new(
                "conflict",
                format!("job {id} already finished ({:?})", r.state).to_lowercase(),
            )
            .with("job_id", id));
        }
        r.progress.cancel();
        Ok(self.view(id, r))
    }

    /// Cancels every unfinished job (end of the shutdown grace period).
    pub fn cancel_all(&self) -> usize {
        let g = self.lock();
        let mut n = 0;
        for r in g.map.values().filter(|r| !r.state.finished()) {
            r.progress.cancel();
            n += 1;
        }
        n
    }

    pub fn held_bytes(&self) -> usize {
        self.lock().bytes
    }
}

fn unknown(id: &str) -> Problem {
    Problem::not_found(format!("no job with id {id} (never existed, or forgotten after its TTL)"))
}

fn drop_result(r: &mut Record, how: &'static str) {
    r.result = None;
    r.report = None;
    r.bytes = 0;
    r.removed = Some(how);
}

fn approx_json_bytes(v: &Value) -> usize {
    serde_json::to_vec(v).map_or(0, |b| b.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(n: usize) -> ResultFile {
        ResultFile { bytes: vec![0; n], media_type: "model/gltf-binary".into(), extension: "glb".into() }
    }

    #[test]
    fn ids_are_128_bit_hex_and_distinct() {
        let (a, b) = (new_id(), new_id());
        assert_eq!(a.len(), 32);
        assert!(a.chars().all(|c| c.is_ascii_hexdigit()));
        assert_ne!(a, b);
    }

    #[test]
    fn oldest_result_is_evicted_first_and_status_says_so() {
        let s = Store::new(Duration::from_secs(60), 2500, 100);
        let a = s.insert("smooth", Progress::new());
        let b = s.insert("smooth", Progress::new());
        s.finish(&a, Ok((Some(file(1000)), Value::Null)));
        s.finish(&b, Ok((Some(file(1000)), Value::Null)));
        assert!(s.result(&a).is_ok());
        let c = s.insert("smooth", Progress::new());
        s.finish(&c, Ok((Some(file(1000)), Value::Null)));
        let e = s.result(&a).err().unwrap();
        assert_eq!(e.status, 410);
        assert_eq!(s.status(&a).unwrap().removed.as_deref(), Some("evicted"));
        assert!(s.result(&b).is_ok() && s.result(&c).is_ok());
        assert!(s.held_bytes() <= 2500);
    }

    #[test]
    fn ttl_expires_then_forgets() {
        let mut s = Store::new(Duration::from_millis(200), 1 << 20, 100);
        let a = s.insert("convert", Progress::new());
        s.finish(&a, Ok((Some(file(10)), serde_json::json!({"x": 1}))));
        s.sweep();
        assert!(s.result(&a).is_ok(), "not expired before the TTL");
        std::thread::sleep(Duration::from_millis(250));
        s.sweep();
        assert_eq!(s.status(&a).unwrap().removed.as_deref(), Some("expired"));
        assert_eq!(s.report(&a).err().unwrap().status, 410);
        s.tombstone_min = Duration::ZERO;
        std::thread::sleep(Duration::from_millis(200));
        s.sweep();
        assert!(s.status(&a).is_none());
        assert_eq!(s.held_bytes(), 0);
    }

    #[test]
    fn cancel_running_ok_finished_conflict() {
        let s = Store::new(Duration::from_secs(60), 1 << 20, 100);
        let p = Progress::new();
        let a = s.insert("smooth", p.clone());
        s.set_running(&a);
        assert!(s.cancel(&a).is_ok());
        assert!(p.is_cancelled());
        s.finish(&a, Err(Problem::new("cancelled", "job cancelled")));
        assert_eq!(s.status(&a).unwrap().state, State::Cancelled);
        assert_eq!(s.cancel(&a).err().unwrap().status, 409);
        assert_eq!(s.cancel("nope").err().unwrap().status, 404);
    }

    #[test]
    fn record_count_is_bounded() {
        let s = Store::new(Duration::from_secs(60), 1 << 20, 3);
        let ids: Vec<_> = (0..5)
            .map(|_| {
                let id = s.insert("validate", Progress::new());
                s.finish(&id, Ok((None, Value::Null)));
                id
            })
            .collect();
        assert!(s.status(&ids[0]).is_none() && s.status(&ids[1]).is_none());
        assert!(s.status(&ids[4]).is_some());
    }
}
