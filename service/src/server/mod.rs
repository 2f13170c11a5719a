//! `meshwork serve`: the HTTP job service. Requests are admitted through a bounded gate (503 at
//! once when full), jobs run on a dedicated rayon pool, and every error is problem+json.

mod input;
pub mod jobs;
pub mod openapi;
pub mod problem;
pub mod store;

use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use axum::extract::{DefaultBodyLimit, Path, Request, State};
use axum::http::{header, HeaderValue, Method, StatusCode};
use axum::middleware::Next;
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use metrics_exporter_prometheus::PrometheusHandle;
use tokio::sync::Semaphore;
use tower_http::cors::{AllowOrigin, CorsLayer};

use crate::cli::Failure;
use crate::config::{Config, ServeArgs};
use problem::Problem;
use store::Store;

/// Everything handlers share.
pub struct AppState {
    pub cfg: Config,
    /// Admission: one permit per admitted job (running or waiting for a worker).
    pub gate: Arc<Semaphore>,
    pub pool: rayon::ThreadPool,
    pub store: Store,
    pub metrics: Option<PrometheusHandle>,
    pub shutting_down: AtomicBool,
}

pub type Shared = Arc<AppState>;

/// Entry point of `meshwork serve`.
pub fn serve_main(args: ServeArgs) -> Result<(), Failure> {
    let cfg = Config::load(&args).map_err(|m| Failure { code: 2, message: format!("error[config]: {m}") })?;
    let filter = tracing_subscriber::EnvFilter::try_new(&cfg.log)
        .map_err(|e| Failure { code: 2, message: format!("error[config]: log filter: {e}") })?;
    // Colour codes only on a terminal: in a container or a log file they are noise.
    let ansi = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_ansi(ansi)
        .with_writer(std::io::stderr)
        .try_init();
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| Failure { code: 1, message: format!("error[internal]: tokio runtime: {e}") })?;
    rt.block_on(serve(cfg)).map_err(|m| Failure { code: 1, message: m })
}

pub fn build_state(cfg: Config) -> Result<Shared, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(cfg.workers)
        .thread_name(|i| format!("meshwork-job-{i}"))
        .stack_size(16 << 20)
        .build()
        .map_err(|e| format!("job pool: {e}"))?;
    // A second recorder cannot be installed (tests run several states); metrics then stay off.
    let metrics = metrics_exporter_prometheus::PrometheusBuilder::new()
        .set_buckets(&[0.001, 0.005, 0.01, 0.05, 0.1, 0.5, 1.0, 5.0, 10.0, 60.0, 300.0])
        .ok()
        .and_then(|b| b.install_recorder().ok());
    jobs::describe_metrics();
    Ok(Arc::new(AppState {
        gate: Arc::new(Semaphore::new(cfg.admitted())),
        pool,
        store: Store::new(
            Duration::from_secs_f64(cfg.result_ttl_secs),
            cfg.store_bytes.min(usize::MAX as u64) as usize,
            cfg.store_jobs,
        ),
        metrics,
        shutting_down: AtomicBool::new(false),
        cfg,
    }))
}

async fn serve(cfg: Config) -> Result<(), String> {
    let grace = Duration::from_secs_f64(cfg.shutdown_grace_secs);
    let listener =
        tokio::net::TcpListener::bind(&cfg.bind).await.map_err(|e| format!("bind {}: {e}", cfg.bind))?;
    let addr: SocketAddr = listener.local_addr().map_err(|e| e.to_string())?;
    let state = build_state(cfg)?;
    let app = router(state.clone());
    // The tests read this line to find the port when binding to port 0.
    println!("meshwork listening on http://{addr}");
    tracing::info!(%addr, workers = state.cfg.workers, admitted = state.cfg.admitted(), "listening");

    let sweeper = {
        let st = state.clone();
        tokio::spawn(async move {
            let mut tick = tokio::time::interval(Duration::from_secs(1));
            loop {
                tick.tick().await;
                st.store.sweep();
            }
        })
    };

    let st = state.clone();
    let shutdown = async move {
        shutdown_signal().await;
        tracing::info!("shutdown requested: no new jobs; waiting up to {grace:?} for running ones");
        st.shutting_down.store(true, Ordering::SeqCst);
        // After the grace period, cancel whatever still runs so open requests end promptly.
        let st2 = st.clone();
        tokio::spawn(async move {
            tokio::time::sleep(grace).await;
            let n = st2.store.cancel_all();
            if n > 0 {
                tracing::warn!(n, "grace period over: cancelled running jobs");
            }
        });
    };
    let server = axum::serve(listener, app.into_make_service_with_connect_info::<SocketAddr>())
        .with_graceful_shutdown(shutdown);
    server.await.map_err(|e| e.to_string())?;
    // Async jobs have no open request; wait for them too (they were cancelled after the grace).
    let all = state.cfg.admitted() as u32;
    let _ = tokio::time::timeout(grace + Duration::from_secs(5), state.gate.acquire_many(all)).await;
    sweeper.abort();
    tracing::info!("shut down");
    Ok(())
}

async fn shutdown_signal() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let term = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! { _ = ctrl_c => {}, _ = term => {} }
}

pub fn router(state: Shared) -> Router {
    let api = Router::new()
        .route("/v1/jobs", post(jobs::submit_async))
        .route("/v1/jobs/{id}", get(jobs::status).delete(jobs::cancel))
        .route("/v1/jobs/{id}/result", get(jobs::result))
        .route("/v1/jobs/{id}/report", get(jobs::report))
        .route("/v1/{job}", post(jobs::submit_sync))
        .layer(axum::middleware::from_fn_with_state(state.clone(), auth));
    let mut app = Router::new()
        .merge(api)
        .route("/healthz", get(|| async { Json(serde_json::json!({"status": "ok"})) }))
        .route("/readyz", get(readyz))
        .route("/metrics", get(metrics))
        .route("/openapi.json", get(openapi_json))
        .route("/docs", get(docs))
        .route("/problems/{kind}", get(problem_doc))
        .fallback(|| async { Problem::not_found("no such endpoint") })
        .method_not_allowed_fallback(|| async {
            Problem::new("method-not-allowed", "method not allowed on this endpoint")
        })
        // Our own limit (with a problem+json 413) is the one that counts; axum's 2 MB default must
        // not undercut it (multipart reads through it).
        .layer(DefaultBodyLimit::max(state.cfg.limits.max_body_bytes.min(usize::MAX as u64) as usize))
        .layer(tower_http::catch_panic::CatchPanicLayer::custom(|_| {
            Problem::new("internal", "the request handler panicked").into_response()
        }))
        .layer(tower_http::trace::TraceLayer::new_for_http());
    if let Some(cors) = cors_layer(&state.cfg.cors_origins) {
        app = app.layer(cors);
    }
    app.with_state(state)
}

fn cors_layer(origins: &[String]) -> Option<CorsLayer> {
    if origins.is_empty() {
        return None;
    }
    let allow = if origins.iter().any(|o| o == "*") {
        AllowOrigin::any()
    } else {
        AllowOrigin::list(origins.iter().filter_map(|o| HeaderValue::from_str(o).ok()))
    };
    Some(
        CorsLayer::new()
            .allow_origin(allow)
            .allow_methods([Method::GET, Method::POST, Method::DELETE])
            .allow_headers([header::CONTENT_TYPE, header::AUTHORIZATION, header::ACCEPT])
            .expose_headers([
                header::LOCATION,
                header::LINK,
                header::RETRY_AFTER,
                header::HeaderName::from_static("x-meshwork-job-id"),
            ]),
    )
}

/// Bearer-token check on /v1/* when an API key is configured (constant-time comparison).
async fn auth(State(st): State<Shared>, req: Request, next: Next) -> Response {
    let key = st.cfg.api_key.as_bytes();
    if key.is_empty() || req.method() == Method::OPTIONS {
        return next.run(req).await;
    }
    let given = req
        .headers()
        .get(header::AUTHORIZATION)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.strip_prefix("Bearer "))
        .map(str::as_bytes)
        .unwrap_or(b"");
    let same = given.len() == key.len() && given.iter().zip(key).fold(0u8, |acc, (a, b)| acc | (a ^ b)) == 0;
    if same {
        next.run(req).await
    } else {
        let mut r = Problem::new("unauthorized", "send `Authorization: Bearer <api key>`").into_response();
        r.headers_mut().insert(header::WWW_AUTHENTICATE, HeaderValue::from_static("Bearer"));
        r
    }
}

/// Ready when not shutting down and a job could be admitted now.
async fn readyz(State(st): State<Shared>) -> Response {
    let free = st.gate.available_permits();
    let body = serde_json::json!({
        "ready": !st.shutting_down.load(Ordering::SeqCst) && free > 0,
        "shutting_down": st.shutting_down.load(Ordering::SeqCst),
        "free_slots": free,
        "admitted_max": st.cfg.admitted(),
    });
    let code = if body["ready"] == true { StatusCode::OK } else { StatusCode::SERVICE_UNAVAILABLE };
    (code, Json(body)).into_response()
}

async fn metrics(State(st): State<Shared>) -> Response {
    jobs::gauge_snapshot(&st);
    match &st.metrics {
        Some(h) => ([(header::CONTENT_TYPE, "text/plain; version=0.0.4")], h.render()).into_response(),
        None => Problem::new("internal", "metrics recorder not installed").into_response(),
    }
}

async fn openapi_json() -> Response {
    ([(header::CONTENT_TYPE, "application/json")], openapi::document_json()).into_response()
}

async fn docs() -> Html<String> {
    Html(utoipa_scalar::Scalar::new(openapi::document()).to_html())
}

async fn problem_doc(Path(kind): Path<String>) -> Response {
    match problem::KINDS.iter().find(|(k, _, _)| *k == kind) {
        Some((k, status, title)) => Json(serde_json::json!({
            "type": format!("/problems/{k}"), "title": title, "status": status,
            "description": openapi::problem_description(k),
        }))
        .into_response(),
        None => Problem::not_found(format!("no problem type `{kind}`")).into_response(),
    }
}
