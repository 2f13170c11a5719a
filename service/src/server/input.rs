//! Turning an HTTP request into job inputs: multipart form (mesh parts + `params` part) or a raw
//! mesh body with `Content-Type`, params from the query string; and choosing the output format.

use axum::extract::{FromRequest, Multipart, Request};
use axum::http::{header, HeaderMap};
use meshwork_core::io::Format;
use serde_json::{Map, Value};

use super::problem::Problem;
use crate::params::{merge, parse_value};
use crate::runner::{Input, Limits};

/// What a request carries.
pub struct Parsed {
    pub inputs: Vec<Input>,
    pub params: Map<String, Value>,
    /// `job` from the query, a `job` part or the params' `job` key (async submissions).
    pub job: Option<String>,
    pub bytes_in: usize,
}

/// Options from the query string.
#[derive(Default)]
pub struct QueryOpts {
    pub format: Option<String>,
    pub report_inline: bool,
    pub job: Option<String>,
    /// `?params=` JSON, then the other keys on top.
    pub params: Map<String, Value>,
}

pub fn parse_query(query: Option<&str>) -> Result<QueryOpts, Problem> {
    let mut q = QueryOpts::default();
    let Some(query) = query else { return Ok(q) };
    let pairs: Vec<(String, String)> = serde_urlencoded_pairs(query)?;
    let mut loose = Map::new();
    for (k, v) in pairs {
        match k.as_str() {
            "format" => q.format = Some(v),
            "report" => match v.as_str() {
                "inline" => q.report_inline = true,
                "link" => q.report_inline = false,
                _ => {
                    return Err(Problem::bad_request(format!("report must be `inline` or `link`, got `{v}`")))
                }
            },
            "job" => q.job = Some(v),
            "params" => q.params = json_object(&v, "the `params` query value")?,
            _ => {
                loose.insert(k, parse_value(&v));
            }
        }
    }
    q.params = merge(std::mem::take(&mut q.params), loose);
    Ok(q)
}

fn serde_urlencoded_pairs(query: &str) -> Result<Vec<(String, String)>, Problem> {
    // axum's Query extractor is serde_urlencoded underneath; use it on the raw string.
    axum::extract::Query::<Vec<(String, String)>>::try_from_uri(
        &format!("/?{query}").parse().map_err(|_| Problem::bad_request("unparseable query string"))?,
    )
    .map(|q| q.0)
    .map_err(|e| Problem::bad_request(format!("query string: {e}")))
}

fn json_object(text: &str, what: &str) -> Result<Map<String, Value>, Problem> {
    match serde_json::from_str::<Value>(text) {
        Ok(Value::Object(m)) => Ok(m),
        Ok(_) => {
            Err(Problem::new("invalid-params", format!("{what} must be a JSON object"))
                .with("field", "params"))
        }
        Err(e) => {
            Err(Problem::new("invalid-params", format!("{what} is not JSON: {e}")).with("field", "params"))
        }
    }
}

/// Reads the body (multipart or raw). `query_params` are merged over a `params` part.
pub async fn parse_body(req: Request, q: &QueryOpts, limits: &Limits) -> Result<Parsed, Problem> {
    let limit = limits.max_body_bytes;
    if let Some(len) = content_length(req.headers()) {
        if len > limit {
            let mut p = body_too_large(limit, len);
            p.close = !drain(req.into_body()).await;
            return Err(p);
        }
    }
    let ctype =
        req.headers().get(header::CONTENT_TYPE).and_then(|v| v.to_str().ok()).unwrap_or("").to_string();
    let mut parsed = if ctype.to_ascii_lowercase().starts_with("multipart/form-data") {
        parse_multipart(req, limit).await?
    } else {
        let body = axum::body::to_bytes(req.into_body(), limit.min(usize::MAX as u64) as usize)
            .await
            .map_err(|e| {
                let mut p = too_large_or_bad(e, limit);
                p.close = true;
                p
            })?;
        if body.is_empty() {
            return Err(Problem::bad_request(
                "no mesh in the request: send the file as the body (with Content-Type) or as multipart `mesh` parts",
            ));
        }
        let name_hint = Format::from_mime(&ctype).map(|f| f.extension().to_string());
        Parsed {
            bytes_in: body.len(),
            inputs: vec![Input { bytes: body.to_vec(), name_hint }],
            params: Map::new(),
            job: None,
        }
    };
    parsed.params = merge(std::mem::take(&mut parsed.params), q.params.clone());
    if let Some(j) = parsed.params.remove("job") {
        parsed.job.get_or_insert(j.as_str().unwrap_or_default().to_string());
    }
    if let Some(j) = &q.job {
        parsed.job = Some(j.clone());
    }
    Ok(parsed)
}

/// Reads and drops up to 4 MiB of a body we refuse, for at most 2 s; true when it reached the end.
pub async fn drain(body: axum::body::Body) -> bool {
    use http_body_util::BodyExt;
    const CAP: usize = 4 << 20;
    let mut body = body;
    let mut seen = 0usize;
    let work = async {
        while let Some(frame) = body.frame().await {
            match frame {
                Ok(f) => {
                    seen += f.data_ref().map_or(0, |d| d.len());
                    if seen > CAP {
                        return false;
                    }
                }
                Err(_) => return false,
            }
        }
        true
    };
    tokio::time::timeout(std::time::Duration::from_secs(2), work).await.unwrap_or(false)
}

fn content_length(h: &HeaderMap) -> Option<u64> {
    h.get(header::CONTENT_LENGTH)?.to_str().ok()?.parse().ok()
}

fn body_too_large(limit: u64, actual: u64) -> Problem {
    Problem::new("too-large", format!("request body exceeds the limit: {actual} > {limit} bytes"))
        .with("what", "body bytes")
        .with("limit", limit)
        .with("actual", actual)
}

fn too_large_or_bad(e: axum::Error, limit: u64) -> Problem {
    let mut src: Option<&(dyn std::error::Error + 'static)> = Some(&e);
    while let Some(s) = src {
        if s.is::<http_body_util::LengthLimitError>() {
            return Problem::new("too-large", format!("request body exceeds the limit of {limit} bytes"))
                .with("what", "body bytes")
                .with("limit", limit);
        }
        src = s.source();
    }
    Problem::bad_request(format!("reading the request body: {e}"))
}

async fn parse_multipart(req: Request, limit: u64) -> Result<Parsed, Problem> {
    let mut mp = Multipart::from_request(req, &())
        .await
        .map_err(|e| Problem::bad_request(format!("multipart: {}", e.body_text())))?;
    let mut meshes = Vec::new();
    let (mut template, mut curves) = (None, None);
    let mut params = Map::new();
    let mut job = None;
    let mut bytes_in = 0usize;
    loop {
        let field = match mp.next_field().await {
            Ok(Some(f)) => f,
            Ok(None) => break,
            Err(e) => {
                let mut p = multipart_error(e, limit);
                p.close = true;
                return Err(p);
            }
        };
        let name = field.name().unwrap_or("").to_string();
        let file_name = field.file_name().map(str::to_string);
        let ctype = field.content_type().map(str::to_string);
        let data = field.bytes().await.map_err(|e| multipart_error(e, limit))?;
        bytes_in += data.len();
        let hint =
            file_name.or_else(|| ctype.as_deref().and_then(Format::from_mime).map(|f| f.extension().into()));
        match name.as_str() {
            "mesh" | "meshes" | "mesh[]" | "meshes[]" => {
                meshes.push(Input { bytes: data.to_vec(), name_hint: hint })
            }
            "template" => template = Some(Input { bytes: data.to_vec(), name_hint: hint }),
            "curves" => curves = Some(Input { bytes: data.to_vec(), name_hint: hint }),
            "params" => {
                let text = std::str::from_utf8(&data).map_err(|_| {
                    Problem::new("invalid-params", "the params part is not UTF-8").with("field", "params")
                })?;
                params = json_object(text, "the params part")?;
            }
            "job" => job = Some(String::from_utf8_lossy(&data).trim().to_string()),
            other => {
                return Err(Problem::bad_request(format!(
                    "unknown multipart part `{other}` (expected mesh, template, curves, params, job)"
                )))
            }
        }
    }
    // fit: `template` then `curves` (or two `mesh` parts in that order).
    let mut inputs = Vec::new();
    inputs.extend(template);
    inputs.extend(curves);
    inputs.extend(meshes);
    if inputs.is_empty() {
        return Err(Problem::bad_request("no mesh part in the multipart body (name parts `mesh`)"));
    }
    Ok(Parsed { inputs, params, job, bytes_in })
}

fn multipart_error(e: axum::extract::multipart::MultipartError, limit: u64) -> Problem {
    if e.status() == axum::http::StatusCode::PAYLOAD_TOO_LARGE {
        Problem::new("too-large", format!("request body exceeds the limit of {limit} bytes"))
            .with("what", "body bytes")
            .with("limit", limit)
    } else {
        Problem::bad_request(format!("multipart: {}", e.body_text()))
    }
}

/// `?format=` wins; else the first acceptable type in `Accept`; else GLB. `None` = nothing we
/// can produce was acceptable (406).
pub fn choose_format(format: Option<&str>, headers: &HeaderMap) -> Result<Format, Problem> {
    if let Some(f) = format {
        return Format::from_name(f).ok_or_else(|| {
            Problem::bad_request(format!("unknown format `{f}` (glb, gltf, obj, ply, stl, off)"))
        });
    }
    let Some(accept) = headers.get(header::ACCEPT).and_then(|v| v.to_str().ok()) else {
        return Ok(Format::Glb);
    };
    let mut ranges: Vec<(f32, &str)> = accept
        .split(',')
        .map(|r| {
            let mut it = r.split(';');
            let mt = it.next().unwrap_or("").trim();
            let q = it
                .filter_map(|p| p.trim().strip_prefix("q="))
                .find_map(|q| q.parse::<f32>().ok())
                .unwrap_or(1.0);
            (q, mt)
        })
        .filter(|(q, _)| *q > 0.0)
        .collect();
    ranges.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, mt) in ranges {
        if mt == "*/*" || mt == "model/*" || mt == "application/*" {
            return Ok(Format::Glb);
        }
        // A report-only client (`Accept: application/json`, multipart) still gets the default mesh.
        if mt == "application/json" || mt.starts_with("multipart/") {
            return Ok(Format::Glb);
        }
        if let Some(f) = Format::from_mime(mt) {
            return Ok(f);
        }
    }
    Err(Problem::new(
        "not-acceptable",
        format!("cannot produce any of `{accept}`; use model/gltf-binary, model/gltf+json, model/obj, …"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use axum::http::HeaderValue;

    #[test]
    fn query_params_use_json_names_and_override_params_json() {
        let q = parse_query(Some(
            "method=taubin&iterations=5&params=%7B%22iterations%22%3A2%2C%22lambda%22%3A0.5%7D&format=obj",
        ))
        .unwrap();
        assert_eq!(
            Value::Object(q.params),
            serde_json::json!({"iterations": 5, "lambda": 0.5, "method": "taubin"})
        );
        assert_eq!(q.format.as_deref(), Some("obj"));
    }

    #[test]
    fn accept_header_picks_format_by_quality() {
        let mut h = HeaderMap::new();
        assert_eq!(choose_format(None, &h).unwrap(), Format::Glb);
        h.insert(header::ACCEPT, HeaderValue::from_static("model/gltf-binary;q=0.5, model/obj"));
        assert_eq!(choose_format(None, &h).unwrap(), Format::Obj);
        assert_eq!(choose_format(Some("gltf"), &h).unwrap(), Format::Gltf);
        h.insert(header::ACCEPT, HeaderValue::from_static("image/png"));
        assert_eq!(choose_format(None, &h).unwrap_err().status, 406);
    }
}
