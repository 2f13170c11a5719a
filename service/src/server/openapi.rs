//! The OpenAPI 3.1 document, generated from the code: parameter schemas from the jobs' params types
//! (utoipa derives), the job list from `JobKind::ALL`, the error types from `problem::KINDS`.
//! `openapi/openapi.json` is this document, checked in; a test fails when they differ.

use meshwork_core::fit::FitParams;
use meshwork_core::io::Format;
use meshwork_core::job::{EmptyParams, JobKind};
use meshwork_core::morph::MorphParams;
use meshwork_core::repair::RepairParams;
use meshwork_core::smooth::SmoothParams;
use meshwork_core::validate::ValidateParams;
use serde_json::{json, Map, Value};
use utoipa::OpenApi;

use super::problem::{Problem, KINDS};
use super::store::{JobStatus, Links, State};

#[derive(OpenApi)]
#[openapi(
    info(
        title = "Meshwork",
        description = "Mesh processing jobs (validate, convert, repair, smooth, fit, morph) over HTTP. \
Synchronous: `POST /v1/{job}` answers with the result. Asynchronous: `POST /v1/jobs` answers 202 with \
`Location`. Errors are RFC 9457 `application/problem+json`; see docs/api.md.",
        license(name = "MIT OR Apache-2.0")
    ),
    components(schemas(
        ValidateParams,
        EmptyParams,
        RepairParams,
        SmoothParams,
        FitParams,
        MorphParams,
        Problem,
        JobStatus,
        Links,
        State,
        JobKind,
        Format
    ))
)]
struct Schemas;

/// Name of the params schema of a job.
fn params_schema(kind: JobKind) -> &'static str {
    match kind {
        JobKind::Validate => "ValidateParams",
        JobKind::Convert => "EmptyParams",
        JobKind::Repair => "RepairParams",
        JobKind::Smooth => "SmoothParams",
        JobKind::Fit => "FitParams",
        JobKind::Morph => "MorphParams",
    }
}

const MESH_TYPES: &[&str] = &[
    "model/gltf-binary",
    "model/gltf+json",
    "model/obj",
    "application/x-ply",
    "model/stl",
    "application/x-off",
];

pub fn problem_description(kind: &str) -> &'static str {
    match kind {
        "unsupported-format" => "The bytes are not a mesh format Meshwork reads (glTF/GLB, OBJ, PLY, STL, OFF).",
        "malformed-input" => "The file breaks its format's rules; `location` (and `line`, `byte` or `gltf_path`) says where.",
        "external-reference" => "A glTF `uri` names a file or URL; uploaded glTF may only use data: URIs or the GLB chunk.",
        "invalid-mesh" => "The mesh is readable but unusable (NaN coordinates, index out of range); `face`/`vertex` says where.",
        "invalid-params" => "A parameter failed validation; `field` names it.",
        "too-large" => "A configured limit was exceeded (body bytes, vertices, faces, iterations, frames, curve points); `what`, `limit`, `actual`.",
        "unsupported-topology" => "The mesh's topology does not allow the job (not manifold, wrong genus, open where closed is needed).",
        "numerical-failure" => "A numerical step failed on this input (singular system, no convergence).",
        "cancelled" => "The job was cancelled (DELETE, client disconnect, or shutdown).",
        "timed-out" => "The job exceeded the per-job time limit (counted from admission).",
        "internal" => "A bug on the server's side (including a panic inside a job); other jobs are unaffected.",
        "bad-request" => "The request itself is malformed (multipart, query string, missing mesh).",
        "unauthorized" => "An API key is configured and the request lacks `Authorization: Bearer <key>`.",
        "not-found" => "No such endpoint or job id.",
        "unknown-job" => "No job of that name.",
        "method-not-allowed" => "The endpoint exists but not with this method.",
        "not-acceptable" => "The `Accept` header allows no format Meshwork writes.",
        "conflict" => "The job's state does not allow this (result of an unfinished job, cancelling a finished one).",
        "gone" => "The job's result expired (TTL) or was evicted (memory bound).",
        "queue-full" => "Admission is full (running + queued jobs); retry after `Retry-After` seconds.",
        "shutting-down" => "The server is shutting down and admits no new jobs.",
        _ => "",
    }
}

fn problem_ref() -> Value {
    json!({"$ref": "#/components/schemas/Problem"})
}

/// Error responses, one per status, each listing its problem types.
fn error_responses(kinds: &[&str]) -> Map<String, Value> {
    let mut by_status: std::collections::BTreeMap<u16, Vec<&str>> = Default::default();
    for (k, s, _) in KINDS {
        if kinds.contains(k) {
            by_status.entry(*s).or_default().push(k);
        }
    }
    let mut m = Map::new();
    for (status, ks) in by_status {
        let list: Vec<String> = ks.iter().map(|k| format!("`/problems/{k}`")).collect();
        let mut resp = json!({
            "description": format!("Problem types: {}", list.join(", ")),
            "content": {"application/problem+json": {"schema": problem_ref()}},
        });
        if status == 503 {
            resp["headers"] =
                json!({"Retry-After": {"description": "Seconds to wait", "schema": {"type": "integer"}}});
        }
        m.insert(status.to_string(), resp);
    }
    m
}

const JOB_ERRORS: &[&str] = &[
    "unsupported-format",
    "malformed-input",
    "external-reference",
    "invalid-mesh",
    "invalid-params",
    "too-large",
    "unsupported-topology",
    "numerical-failure",
    "timed-out",
    "internal",
    "bad-request",
    "unauthorized",
    "unknown-job",
    "not-acceptable",
    "queue-full",
    "shutting-down",
];

fn query(name: &str, description: &str, schema: Value) -> Value {
    json!({"name": name, "in": "query", "required": false, "description": description, "schema": schema})
}

fn format_param() -> Value {
    query(
        "format",
        "Output format; overrides `Accept`. Default glb.",
        json!({"type": "string", "enum": ["glb", "gltf", "obj", "ply", "stl", "off"]}),
    )
}

fn binary() -> Value {
    json!({"type": "string", "format": "binary"})
}

fn sync_path(kind: JobKind, schemas: &Map<String, Value>) -> Value {
    let name = kind.name();
    let pschema = params_schema(kind);
    let (lo, hi) = kind.inputs();
    let mut params = vec![
        format_param(),
        query("report", "`inline`: answer multipart/mixed with the JSON report then the mesh. Default `link`: the mesh, with the report at the `Link` header's URL.", json!({"type": "string", "enum": ["link", "inline"]})),
        query("params", "All parameters as one JSON object (individual query parameters override its keys).", json!({"type": "string", "contentMediaType": "application/json"})),
    ];
    // Every params field may also be given as its own query parameter, same name as in JSON.
    if let Some(props) = schemas.get(pschema).and_then(|s| s.get("properties")).and_then(Value::as_object) {
        for (field, s) in props {
            let d = s
                .get("description")
                .and_then(Value::as_str)
                .unwrap_or("Job parameter (see the params schema).");
            params.push(query(field, d, s.clone()));
        }
    }
    let mesh_parts = if kind == JobKind::Fit {
        json!({"template": binary(), "curves": binary()})
    } else if hi > 1 {
        json!({"mesh": {"type": "array", "items": binary(), "minItems": lo, "maxItems": hi}})
    } else {
        json!({"mesh": binary()})
    };
    let mut form = json!({"type": "object", "properties": mesh_parts});
    form["properties"]["params"] = json!({"$ref": format!("#/components/schemas/{pschema}")});
    let mut content = Map::new();
    content.insert(
        "multipart/form-data".into(),
        json!({"schema": form, "encoding": {"params": {"contentType": "application/json"}}}),
    );
    if hi == 1 {
        for t in MESH_TYPES.iter().chain(["application/octet-stream"].iter()) {
            content.insert(t.to_string(), json!({"schema": binary()}));
        }
    }
    let ok = if kind.returns_mesh() {
        let mut c = Map::new();
        let types: Vec<&str> =
            if kind == JobKind::Morph { vec!["model/gltf-binary"] } else { MESH_TYPES.to_vec() };
        for t in types {
            c.insert(t.into(), json!({"schema": binary()}));
        }
        c.insert("multipart/mixed".into(), json!({"schema": {"type": "object", "properties": {"report": {"type": "object"}, "mesh": binary()}}}));
        json!({
            "description": "The result mesh (or, with `report=inline`, the report and the mesh).",
            "headers": {
                "Link": {"description": "`</v1/jobs/{id}/report>; rel=\"report\"`", "schema": {"type": "string"}},
                "X-Meshwork-Job-Id": {"schema": {"type": "string"}}
            },
            "content": c,
        })
    } else {
        json!({"description": "The JSON report.", "content": {"application/json": {"schema": {"type": "object"}}}})
    };
    let mut responses = error_responses(JOB_ERRORS);
    responses.insert("200".into(), ok);
    let inputs = match (kind, lo, hi) {
        (JobKind::Fit, _, _) => {
            "Inputs: `template` and `curves` parts (or two `mesh` parts in that order).".to_string()
        }
        (_, 1, 1) => "Input: one `mesh` part, or the mesh as the raw body with its Content-Type.".to_string(),
        _ => format!("Inputs: {lo} to {hi} `mesh` parts, in order."),
    };
    json!({"post": {
        "tags": ["jobs"],
        "operationId": format!("run_{name}"),
        "summary": format!("Run `{name}` synchronously"),
        "description": format!("{inputs} Parameters: `params` part (JSON, schema {pschema}) or query parameters."),
        "parameters": params,
        "requestBody": {"required": true, "content": content},
        "responses": responses,
        "security": [{}, {"bearerAuth": []}],
    }})
}

fn status_resp(desc: &str) -> Value {
    json!({"description": desc, "content": {"application/json": {"schema": {"$ref": "#/components/schemas/JobStatus"}}}})
}

fn id_param() -> Value {
    json!({"name": "id", "in": "path", "required": true, "schema": {"type": "string"}, "description": "Job id (32 hex digits)"})
}

fn with_errors(mut ok: Map<String, Value>, kinds: &[&str]) -> Value {
    for (k, v) in error_responses(kinds) {
        ok.insert(k, v);
    }
    Value::Object(ok)
}

fn async_paths() -> Map<String, Value> {
    let mut p = Map::new();
    let mut submit_errors = JOB_ERRORS.to_vec();
    submit_errors.retain(|k| !matches!(*k, "timed-out" | "unsupported-format" | "malformed-input"));
    let mut jobs_errors: Vec<&str> = vec!["not-found", "unauthorized", "conflict", "gone"];
    p.insert("/v1/jobs".into(), json!({"post": {
        "tags": ["jobs"], "operationId": "submit_job",
        "summary": "Submit a job asynchronously",
        "description": "Same inputs as the synchronous endpoints plus the job name (`?job=smooth`, a `job` part, or `\"job\"` in params). Answers 202 at once with `Location: /v1/jobs/{id}`.",
        "parameters": [query("job", "Job kind", json!({"$ref": "#/components/schemas/JobKind"})), format_param(),
                        query("params", "Parameters as one JSON object", json!({"type": "string"}))],
        "requestBody": {"required": true, "content": {
            "multipart/form-data": {"schema": {"type": "object", "properties": {
                "job": {"$ref": "#/components/schemas/JobKind"},
                "mesh": {"type": "array", "items": binary()},
                "template": binary(), "curves": binary(),
                "params": {"type": "object"}}}},
            "application/octet-stream": {"schema": binary()}}},
        "responses": with_errors({
            let mut m = Map::new();
            m.insert("202".into(), {
                let mut r = status_resp("Admitted");
                r["headers"] = json!({"Location": {"schema": {"type": "string"}}});
                r
            });
            m
        }, &submit_errors),
        "security": [{}, {"bearerAuth": []}],
    }}));
    p.insert("/v1/jobs/{id}".into(), json!({
        "parameters": [id_param()],
        "get": {"tags": ["jobs"], "operationId": "job_status", "summary": "Job status: state, stage, progress",
                "responses": with_errors({let mut m = Map::new(); m.insert("200".into(), status_resp("Status")); m}, &["not-found", "unauthorized"]),
                "security": [{}, {"bearerAuth": []}]},
        "delete": {"tags": ["jobs"], "operationId": "cancel_job", "summary": "Cancel a queued or running job",
                "responses": with_errors({let mut m = Map::new(); m.insert("202".into(), status_resp("Cancellation requested; the job stops at its next check")); m}, &["not-found", "conflict", "unauthorized"]),
                "security": [{}, {"bearerAuth": []}]},
    }));
    let mut result_ok = Map::new();
    let mut c = Map::new();
    for t in MESH_TYPES {
        c.insert(t.to_string(), json!({"schema": binary()}));
    }
    result_ok.insert("200".into(), json!({"description": "The result file", "content": c}));
    jobs_errors.extend([
        "cancelled",
        "timed-out",
        "internal",
        "unsupported-format",
        "malformed-input",
        "invalid-params",
    ]);
    p.insert("/v1/jobs/{id}/result".into(), json!({"parameters": [id_param()], "get": {
        "tags": ["jobs"], "operationId": "job_result", "summary": "The result of a succeeded job",
        "description": "409 while queued/running; a failed job answers with its own problem; 410 once expired or evicted.",
        "responses": with_errors(result_ok, &jobs_errors), "security": [{}, {"bearerAuth": []}]}}));
    let mut report_ok = Map::new();
    report_ok.insert("200".into(), json!({"description": "The JSON report", "content": {"application/json": {"schema": {"type": "object"}}}}));
    p.insert("/v1/jobs/{id}/report".into(), json!({"parameters": [id_param()], "get": {
        "tags": ["jobs"], "operationId": "job_report", "summary": "The report of a finished job (sync jobs keep theirs too)",
        "responses": with_errors(report_ok, &jobs_errors), "security": [{}, {"bearerAuth": []}]}}));
    p
}

fn ops_paths() -> Map<String, Value> {
    let mut p = Map::new();
    let simple = |id: &str, summary: &str, ctype: &str, schema: Value| {
        json!({"get": {"tags": ["operations"], "operationId": id, "summary": summary,
            "responses": {"200": {"description": "OK", "content": {ctype: {"schema": schema}}}}}})
    };
    p.insert("/healthz".into(), simple("healthz", "Liveness", "application/json", json!({"type": "object"})));
    let mut ready = simple(
        "readyz",
        "Readiness: not shutting down and a job slot is free",
        "application/json",
        json!({"type": "object"}),
    );
    ready["get"]["responses"]["503"] =
        json!({"description": "Not ready", "content": {"application/json": {"schema": {"type": "object"}}}});
    p.insert("/readyz".into(), ready);
    p.insert(
        "/metrics".into(),
        simple("metrics", "Prometheus metrics", "text/plain", json!({"type": "string"})),
    );
    p.insert(
        "/openapi.json".into(),
        simple("openapi", "This document", "application/json", json!({"type": "object"})),
    );
    p.insert("/docs".into(), simple("docs", "API reference page", "text/html", json!({"type": "string"})));
    let mut prob =
        simple("problem_type", "Describes a problem type", "application/json", json!({"type": "object"}));
    prob["parameters"] =
        json!([{"name": "kind", "in": "path", "required": true, "schema": {"type": "string"}}]);
    p.insert("/problems/{kind}".into(), prob);
    p
}

/// The whole document as JSON.
pub fn document() -> Value {
    let mut doc = serde_json::to_value(Schemas::openapi()).unwrap_or_else(|_| json!({}));
    let schemas = doc["components"]["schemas"].as_object().cloned().unwrap_or_default();
    let mut paths = Map::new();
    for kind in JobKind::ALL {
        paths.insert(format!("/v1/{}", kind.name()), sync_path(kind, &schemas));
    }
    paths.extend(async_paths());
    paths.extend(ops_paths());
    doc["paths"] = Value::Object(paths);
    doc["components"]["securitySchemes"] = json!({"bearerAuth": {"type": "http", "scheme": "bearer",
        "description": "Required only when the server runs with an API key"}});
    // The problem types, listed where clients look for them.
    let types: Vec<Value> = KINDS.iter().map(|(k, _, _)| json!(format!("/problems/{k}"))).collect();
    doc["components"]["schemas"]["Problem"]["properties"]["type"]["enum"] = Value::Array(types);
    doc["x-problem-types"] = Value::Array(
        KINDS
            .iter()
            .map(|(k, s, t)| json!({"type": format!("/problems/{k}"), "status": s, "title": t, "description": problem_description(k)}))
            .collect(),
    );
    doc["tags"] = json!([{"name": "jobs", "description": "Run mesh jobs"}, {"name": "operations", "description": "Health, metrics, docs"}]);
    doc
}

pub fn document_json() -> String {
    serde_json::to_string_pretty(&document()).unwrap_or_default() + "\n"
}
