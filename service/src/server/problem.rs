//! RFC 9457 problem details. Every error the service returns is `application/problem+json` with a
//! stable `type` (`/problems/<kind>`, relative to the server; `GET /problems/<kind>` describes it).
//! Core errors keep their `Error::kind()` slug; the service adds its own kinds (queue full, auth, …).

use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use meshwork_core::error::{Error, Location};
use serde::Serialize;
use serde_json::{Map, Value};

pub const MEDIA_TYPE: &str = "application/problem+json";

/// One problem document.
#[derive(Debug, Clone, Serialize, serde::Deserialize, utoipa::ToSchema)]
pub struct Problem {
    /// Stable URI naming the kind of failure, e.g. `/problems/malformed-input`.
    #[serde(rename = "type")]
    pub type_: String,
    pub title: String,
    pub status: u16,
    /// What went wrong and where (line, accessor, face index, parameter, limit).
    pub detail: String,
    /// Extension members: `kind`, and where relevant `location`, `format`, `field`, `limit`,
    /// `actual`, `what`, `job_id`.
    #[serde(flatten)]
    #[schema(value_type = Object)]
    pub extra: Map<String, Value>,
    #[serde(skip)]
    pub retry_after: Option<u64>,
    /// Close the connection after answering (the request body was not read to its end).
    #[serde(skip)]
    pub close: bool,
}

/// Every problem kind: (slug, HTTP status, title). The OpenAPI document and `/problems/{kind}`
/// are generated from this table.
pub const KINDS: &[(&str, u16, &str)] = &[
    ("unsupported-format", 415, "Unsupported mesh format"),
    ("malformed-input", 422, "Malformed mesh file"),
    ("external-reference", 422, "External reference refused"),
    ("invalid-mesh", 422, "Invalid mesh"),
    ("invalid-params", 422, "Invalid parameters"),
    ("too-large", 413, "Limit exceeded"),
    ("unsupported-topology", 422, "Unsupported topology"),
    ("numerical-failure", 422, "Numerical failure"),
    ("cancelled", 409, "Job cancelled"),
    ("timed-out", 504, "Job exceeded its time limit"),
    ("internal", 500, "Internal error"),
    ("bad-request", 400, "Bad request"),
    ("unauthorized", 401, "Missing or wrong bearer token"),
    ("not-found", 404, "Not found"),
    ("unknown-job", 404, "Unknown job kind"),
    ("method-not-allowed", 405, "Method not allowed"),
    ("not-acceptable", 406, "Cannot produce the requested media type"),
    ("conflict", 409, "Job state does not allow this"),
    ("gone", 410, "Job result expired or evicted"),
    ("queue-full", 503, "Server busy: admission queue full"),
    ("shutting-down", 503, "Server shutting down"),
];

impl Problem {
    pub fn new(kind: &str, detail: impl Into<String>) -> Problem {
        let (status, title) = KINDS
            .iter()
            .find(|(k, _, _)| *k == kind)
            .map(|(_, s, t)| (*s, *t))
            .unwrap_or((500, "Internal error"));
        let mut extra = Map::new();
        extra.insert("kind".into(), Value::String(kind.into()));
        Problem {
            type_: format!("/problems/{kind}"),
            title: title.into(),
            status,
            detail: detail.into(),
            extra,
            retry_after: None,
            close: false,
        }
    }

    pub fn with(mut self, key: &str, v: impl Into<Value>) -> Problem {
        self.extra.insert(key.into(), v.into());
        self
    }

    pub fn kind(&self) -> &str {
        self.extra.get("kind").and_then(Value::as_str).unwrap_or("internal")
    }

    pub fn status(&self) -> StatusCode {
        StatusCode::from_u16(self.status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR)
    }

    pub fn not_found(detail: impl Into<String>) -> Problem {
        Problem::new("not-found", detail)
    }

    pub fn bad_request(detail: impl Into<String>) -> Problem {
        Problem::new("bad-request", detail)
    }
}

impl From<&Error> for Problem {
    fn from(e: &Error) -> Problem {
        let p = Problem::new(e.kind(), e.to_string());
        match e {
            Error::Malformed { format, location, .. } => p.with("format", *format).with_location(location),
            Error::ExternalReference { location, .. } | Error::InvalidMesh { location, .. } => {
                p.with_location(location)
            }
            Error::InvalidParams { field, .. } => p.with("field", field.as_str()),
            Error::TooLarge { what, limit, actual } => {
                p.with("what", what.as_str()).with("limit", *limit).with("actual", *actual)
            }
            _ => p,
        }
    }
}

impl From<Error> for Problem {
    fn from(e: Error) -> Problem {
        Problem::from(&e)
    }
}

impl Problem {
    /// `location` as text plus a structured member (`line`, `byte`, `accessor`, `face`, `vertex`).
    fn with_location(self, l: &Location) -> Problem {
        let p = self.with("location", l.to_string());
        match l {
            Location::Line(n) => p.with("line", *n),
            Location::Byte(n) => p.with("byte", *n),
            Location::Gltf(s) => p.with("gltf_path", s.as_str()),
            Location::Face(n) => p.with("face", *n),
            Location::Vertex(n) => p.with("vertex", *n),
        }
    }
}

impl IntoResponse for Problem {
    fn into_response(self) -> Response {
        let status = self.status();
        let (retry, close) = (self.retry_after, self.close);
        let body = serde_json::to_vec(&self).unwrap_or_else(|_| b"{}".to_vec());
        let mut r = (status, body).into_response();
        r.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static(MEDIA_TYPE));
        if let Some(s) = retry {
            r.headers_mut().insert(header::RETRY_AFTER, HeaderValue::from(s));
        }
        if close {
            r.headers_mut().insert(header::CONNECTION, HeaderValue::from_static("close"));
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_core_error_kind_has_a_row() {
        let errors = [
            Error::UnsupportedFormat(String::new()),
            Error::malformed("obj", Location::Line(3), "x"),
            Error::ExternalReference {
                location: Location::Gltf("buffers[0]".into()),
                message: String::new(),
            },
            Error::InvalidMesh { location: Location::Face(1), message: String::new() },
            Error::params("a", "b"),
            Error::TooLarge { what: "vertices".into(), limit: 1, actual: 2 },
            Error::Topology(String::new()),
            Error::numerical("s", "m"),
            Error::Cancelled,
            Error::TimedOut,
            Error::Internal(String::new()),
        ];
        for e in &errors {
            assert!(KINDS.iter().any(|(k, _, _)| *k == e.kind()), "{}", e.kind());
        }
        let p = Problem::from(&errors[1]);
        assert_eq!((p.status, p.type_.as_str()), (422, "/problems/malformed-input"));
        assert_eq!(p.extra["line"], 3);
        assert_eq!(Problem::from(&errors[9]).status, 504);
    }

    /// Every core error kind, its HTTP status as docs/api.md promises it (written out here, not
    /// read from `KINDS`), and the member naming where or what, when the kind has one.
    #[test]
    fn every_core_error_kind_maps_to_its_status_and_names_where() {
        let cases: Vec<(Error, u16, Option<(&str, serde_json::Value)>)> = vec![
            (Error::UnsupportedFormat("xyz".into()), 415, None),
            (Error::malformed("ply", Location::Byte(17), "short"), 422, Some(("byte", 17.into()))),
            (
                Error::ExternalReference {
                    location: Location::Gltf("buffers[0]".into()),
                    message: "uri".into(),
                },
                422,
                Some(("gltf_path", "buffers[0]".into())),
            ),
            (
                Error::InvalidMesh { location: Location::Vertex(4), message: "NaN".into() },
                422,
                Some(("vertex", 4.into())),
            ),
            (Error::params("time_step", "must be > 0"), 422, Some(("field", "time_step".into()))),
            (
                Error::TooLarge { what: "vertices".into(), limit: 10, actual: 11 },
                413,
                Some(("limit", 10.into())),
            ),
            (Error::Topology("genus 1".into()), 422, None),
            (Error::numerical("factor", "not positive definite"), 422, None),
            (Error::Cancelled, 409, None),
            (Error::TimedOut, 504, None),
            (Error::Internal("bug".into()), 500, None),
        ];
        for (e, status, member) in &cases {
            let p = Problem::from(e);
            assert_eq!(p.status, *status, "{}", e.kind());
            assert_eq!(p.type_, format!("/problems/{}", e.kind()));
            assert_eq!(p.kind(), e.kind());
            assert_eq!(p.detail, e.to_string(), "the detail is the core message, which says where");
            if let Some((key, value)) = member {
                assert_eq!(&p.extra[*key], value, "{}: {key}", e.kind());
            }
        }
        assert_eq!(Problem::from(&cases[2].0).extra["location"], "buffers[0]");
    }
}
