//! Job endpoints: synchronous `POST /v1/{job}`, asynchronous `POST /v1/jobs`, and the job
//! resource (`GET/DELETE /v1/jobs/{id}`, `/result`, `/report`).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use axum::extract::{Path, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use meshwork_core::io::Format;
use meshwork_core::job::Progress;
use serde_json::Value;
use tokio::sync::{oneshot, OwnedSemaphorePermit};

use super::input::{self, Parsed, QueryOpts};
use super::problem::Problem;
use super::store::ResultFile;
use super::Shared;
use crate::runner::{self, Kind};

/// Jobs currently executing on the pool (the rest of the admitted ones are queued).
static RUNNING: AtomicUsize = AtomicUsize::new(0);

type Outcome = Result<(Option<ResultFile>, Value), Problem>;

pub fn describe_metrics() {
    metrics::describe_counter!("meshwork_jobs_total", "Finished jobs by job kind and outcome");
    metrics::describe_histogram!("meshwork_job_duration_seconds", "Job run time (read, job, encode) by kind");
    metrics::describe_counter!("meshwork_rejected_total", "Submissions refused at admission, by reason");
    metrics::describe_counter!("meshwork_bytes_in_total", "Mesh bytes received");
    metrics::describe_counter!("meshwork_bytes_out_total", "Result bytes sent");
    metrics::describe_gauge!("meshwork_jobs_running", "Jobs executing now");
    metrics::describe_gauge!("meshwork_queue_depth", "Admitted jobs waiting for a worker");
    metrics::describe_gauge!("meshwork_store_bytes", "Bytes of results held for async clients");
}

/// Sets the gauges just before `/metrics` renders them.
pub fn gauge_snapshot(st: &Shared) {
    let running = RUNNING.load(Ordering::Relaxed);
    let admitted = st.cfg.admitted().saturating_sub(st.gate.available_permits());
    metrics::gauge!("meshwork_jobs_running").set(running as f64);
    metrics::gauge!("meshwork_queue_depth").set(admitted.saturating_sub(running) as f64);
    metrics::gauge!("meshwork_store_bytes").set(st.store.held_bytes() as f64);
}

/// A permit, or 503 at once: the gate never makes a request wait.
fn admit(st: &Shared) -> Result<OwnedSemaphorePermit, Problem> {
    if st.shutting_down.load(Ordering::SeqCst) {
        metrics::counter!("meshwork_rejected_total", "reason" => "shutting_down").increment(1);
        let mut p = Problem::new("shutting-down", "the server is shutting down and accepts no new jobs");
        p.retry_after = Some(5);
        return Err(p);
    }
    st.gate.clone().try_acquire_owned().map_err(|_| {
        metrics::counter!("meshwork_rejected_total", "reason" => "queue_full").increment(1);
        let mut p = Problem::new(
            "queue-full",
            format!(
                "{} jobs are admitted (running + queued), the configured maximum; retry later",
                st.cfg.admitted()
            ),
        )
        .with("limit", st.cfg.admitted());
        p.retry_after = Some(1);
        p
    })
}

fn kind_of(st: &Shared, name: &str) -> Result<Kind, Problem> {
    Kind::parse(name, st.cfg.debug_jobs).ok_or_else(|| {
        Problem::new(
            "unknown-job",
            format!("no job `{name}` (validate, convert, repair, smooth, fit, morph)"),
        )
        .with("field", "job")
    })
}

/// Cancels the job if the request future is dropped (client went away) before it finished.
struct CancelOnDrop(Option<Progress>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        if let Some(p) = self.0.take() {
            p.cancel();
        }
    }
}

/// Starts a job on the pool. Sync callers get the outcome through the channel (the store keeps
/// only the report); async ones read it from the store.
fn launch(
    st: &Shared,
    kind: Kind,
    parsed: Parsed,
    format: Format,
    keep_result: bool,
    permit: OwnedSemaphorePermit,
) -> (String, Progress, oneshot::Receiver<Outcome>) {
    let progress = Progress::new();
    progress.set_deadline(Instant::now() + Duration::from_secs_f64(st.cfg.job_timeout_secs));
    let id = st.store.insert(kind.name(), progress.clone());
    metrics::counter!("meshwork_bytes_in_total").increment(parsed.bytes_in as u64);
    let (tx, rx) = oneshot::channel();
    let (st2, id2, p2) = (st.clone(), id.clone(), progress.clone());
    st.pool.spawn(move || {
        let _permit = permit;
        RUNNING.fetch_add(1, Ordering::Relaxed);
        st2.store.set_running(&id2);
        let t = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| execute(&st2, kind, parsed, format, &p2)))
            .unwrap_or_else(|_| Err(Problem::new("internal", format!("the {} job panicked", kind.name()))));
        RUNNING.fetch_sub(1, Ordering::Relaxed);
        let outcome_label = match &outcome {
            Ok(_) => "succeeded".to_string(),
            Err(p) => p.kind().to_string(),
        };
        metrics::counter!("meshwork_jobs_total", "job" => kind.name(), "outcome" => outcome_label)
            .increment(1);
        metrics::histogram!("meshwork_job_duration_seconds", "job" => kind.name())
            .record(t.elapsed().as_secs_f64());
        if keep_result {
            st2.store.finish(&id2, outcome);
        } else {
            let for_store = match &outcome {
                Ok((_, report)) => Ok((None, report.clone())),
                Err(p) => Err(p.clone()),
            };
            st2.store.finish(&id2, for_store);
            let _ = tx.send(outcome);
        }
    });
    (id, progress, rx)
}

/// Runs on a pool thread: read, run, encode (all CPU work stays off the async runtime).
fn execute(st: &Shared, kind: Kind, parsed: Parsed, format: Format, progress: &Progress) -> Outcome {
    let done = runner::execute(kind, parsed.inputs, parsed.params, &st.cfg.limits, progress)?;
    let file = if kind.returns_mesh() {
        let (bytes, media_type, extension) = runner::encode(&done.output, format)?;
        Some(ResultFile { bytes, media_type, extension })
    } else {
        None
    };
    Ok((file, done.output.report))
}

fn job_headers(h: &mut HeaderMap, id: &str) {
    if let Ok(v) = HeaderValue::from_str(id) {
        h.insert("x-meshwork-job-id", v);
    }
    if let Ok(v) = HeaderValue::from_str(&format!("</v1/jobs/{id}/report>; rel=\"report\"")) {
        h.insert(header::LINK, v);
    }
}

/// `POST /v1/{job}`: runs the job and answers with the result (or the report for validate).
pub async fn submit_sync(State(st): State<Shared>, Path(job): Path<String>, req: Request) -> Response {
    match sync_inner(st, job, req).await {
        Ok(r) => r,
        Err(p) => p.into_response(),
    }
}

async fn sync_inner(st: Shared, job: String, req: Request) -> Result<Response, Problem> {
    let pre = (|| {
        let kind = kind_of(&st, &job)?;
        let q = input::parse_query(req.uri().query())?;
        let format = input::choose_format(q.format.as_deref(), req.headers())?;
        Ok::<_, Problem>((kind, q, format, admit(&st)?))
    })();
    let (kind, q, format, permit) = match pre {
        Ok(x) => x,
        Err(p) => return Ok(refused_early(p, req).await),
    };
    let parsed = input::parse_body(req, &q, &st.cfg.limits).await?;
    let (id, progress, rx) = launch(&st, kind, parsed, format, false, permit);
    let mut guard = CancelOnDrop(Some(progress));
    let outcome = rx.await;
    guard.0 = None;
    let (file, report) = match outcome {
        Ok(Ok(x)) => x,
        Ok(Err(p)) => return Err(p.with("job_id", id.as_str())),
        Err(_) => {
            return Err(
                Problem::new("internal", "the job ended without an outcome").with("job_id", id.as_str())
            )
        }
    };
    let mut resp = match file {
        None => Json(report).into_response(),
        Some(f) if q.report_inline => multipart_mixed(&report, &f, kind.name()),
        Some(f) => file_response(f, kind.name()),
    };
    job_headers(resp.headers_mut(), &id);
    Ok(resp)
}

/// An error response to a submission refused before its body was read: read (and drop) a bounded
/// amount of the body first, so that closing the socket does not reset the connection under the
/// client before it has read the answer; close the connection when the body was too big to drain.
async fn refused_early(p: Problem, req: Request) -> Response {
    let mut p = p;
    p.close = !input::drain(req.into_body()).await;
    p.into_response()
}

fn file_response(f: ResultFile, name: &str) -> Response {
    metrics::counter!("meshwork_bytes_out_total").increment(f.bytes.len() as u64);
    let disp = format!("attachment; filename=\"{name}.{}\"", f.extension);
    ([(header::CONTENT_TYPE, f.media_type), (header::CONTENT_DISPOSITION, disp)], f.bytes).into_response()
}

/// `multipart/mixed`: part 1 the JSON report (`name="report"`), part 2 the mesh (`name="mesh"`).
fn multipart_mixed(report: &Value, f: &ResultFile, name: &str) -> Response {
    let boundary = format!("meshwork-{}", super::store::new_id());
    let json = serde_json::to_vec(report).unwrap_or_default();
    let mut body = Vec::with_capacity(json.len() + f.bytes.len() + 512);
    body.extend_from_slice(
        format!("--{boundary}\r\nContent-Type: application/json\r\nContent-Disposition: inline; name=\"report\"\r\n\r\n")
            .as_bytes(),
    );
    body.extend_from_slice(&json);
    body.extend_from_slice(
        format!(
            "\r\n--{boundary}\r\nContent-Type: {}\r\nContent-Disposition: attachment; name=\"mesh\"; filename=\"{name}.{}\"\r\n\r\n",
            f.media_type, f.extension
        )
        .as_bytes(),
    );
    body.extend_from_slice(&f.bytes);
    body.extend_from_slice(format!("\r\n--{boundary}--\r\n").as_bytes());
    metrics::counter!("meshwork_bytes_out_total").increment(body.len() as u64);
    ([(header::CONTENT_TYPE, format!("multipart/mixed; boundary={boundary}"))], body).into_response()
}

/// `POST /v1/jobs`: admits the job and answers 202 with `Location` at once.
pub async fn submit_async(State(st): State<Shared>, req: Request) -> Response {
    match async_inner(st, req).await {
        Ok(r) => r,
        Err(p) => p.into_response(),
    }
}

async fn async_inner(st: Shared, req: Request) -> Result<Response, Problem> {
    let pre = (|| {
        let q: QueryOpts = input::parse_query(req.uri().query())?;
        // A job named in the query is checked before the upload is read.
        if let Some(j) = &q.job {
            kind_of(&st, j)?;
        }
        let format = input::choose_format(q.format.as_deref(), req.headers())?;
        Ok::<_, Problem>((q, format, admit(&st)?))
    })();
    let (q, format, permit) = match pre {
        Ok(x) => x,
        Err(p) => return Ok(refused_early(p, req).await),
    };
    let parsed = input::parse_body(req, &q, &st.cfg.limits).await?;
    let job = parsed.job.clone().ok_or_else(|| {
        Problem::new("invalid-params", "name the job: `?job=smooth`, a `job` part, or `\"job\"` in params")
            .with("field", "job")
    })?;
    let kind = kind_of(&st, &job)?;
    let (id, _progress, _rx) = launch(&st, kind, parsed, format, true, permit);
    let status = st.store.status(&id).ok_or_else(|| Problem::new("internal", "job vanished"))?;
    let mut resp = (StatusCode::ACCEPTED, Json(status)).into_response();
    if let Ok(v) = HeaderValue::from_str(&format!("/v1/jobs/{id}")) {
        resp.headers_mut().insert(header::LOCATION, v);
    }
    job_headers(resp.headers_mut(), &id);
    Ok(resp)
}

pub async fn status(State(st): State<Shared>, Path(id): Path<String>) -> Response {
    match st.store.status(&id) {
        Some(s) => Json(s).into_response(),
        None => Problem::not_found(format!("no job with id {id}")).into_response(),
    }
}

pub async fn result(State(st): State<Shared>, Path(id): Path<String>) -> Response {
    match st.store.result(&id) {
        Ok(f) => {
            metrics::counter!("meshwork_bytes_out_total").increment(f.bytes.len() as u64);
            let disp = format!("attachment; filename=\"{id}.{}\"", f.extension);
            (
                [(header::CONTENT_TYPE, f.media_type.clone()), (header::CONTENT_DISPOSITION, disp)],
                f.bytes.clone(),
            )
                .into_response()
        }
        Err(p) => p.into_response(),
    }
}

pub async fn report(State(st): State<Shared>, Path(id): Path<String>) -> Response {
    match st.store.report(&id) {
        Ok(v) => Json(v.as_ref().clone()).into_response(),
        Err(p) => p.into_response(),
    }
}

/// `DELETE /v1/jobs/{id}`: 202 (the job stops at its next check), 409 when already finished.
pub async fn cancel(State(st): State<Shared>, Path(id): Path<String>) -> Response {
    match st.store.cancel(&id) {
        Ok(s) => (StatusCode::ACCEPTED, Json(s)).into_response(),
        Err(p) => p.into_response(),
    }
}
