//! End-to-end HTTP tests against the real binary (`meshwork serve --port 0`).

mod common;

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use common::*;
use meshwork_core::io::{read, ReadOptions};

fn read_obj(bytes: &[u8]) -> meshwork_core::Mesh {
    read(bytes, &ReadOptions { name_hint: Some("x.obj".into()), ..Default::default() })
        .expect("readable output")
        .mesh
}

#[test]
fn operational_endpoints() {
    let s = Server::start(&[]);
    let h = s.get("/healthz");
    assert_eq!((h.status, h.json()["status"].as_str()), (200, Some("ok")));
    let r = s.get("/readyz");
    assert_eq!(r.status, 200);
    assert_eq!(r.json()["ready"], true);
    let o = s.get("/openapi.json");
    assert_eq!(o.status, 200);
    assert_eq!(o.json()["openapi"], "3.1.0");
    let d = s.get("/docs");
    assert_eq!(d.status, 200);
    assert!(d.text().contains("<html") || d.text().contains("<!doctype"), "docs page is HTML");
    let p = s.get("/problems/queue-full");
    assert_eq!(p.json()["status"], 503);
    s.get("/nope").problem(404, "not-found");
    s.req("PUT", "/healthz", &[], None).problem(405, "method-not-allowed");
    // A job, then its traces in the metrics.
    assert_eq!(s.post("/v1/convert?format=obj", "model/obj", TETRA_OBJ.as_bytes()).status, 200);
    let m = s.get("/metrics");
    assert_eq!(m.status, 200);
    let text = m.text();
    assert!(text.contains("meshwork_jobs_total{job=\"convert\",outcome=\"succeeded\"} 1"), "{text}");
    assert!(text.contains("meshwork_bytes_in_total"), "{text}");
    assert!(text.contains("meshwork_queue_depth"), "{text}");
    assert!(text.contains("meshwork_job_duration_seconds"), "{text}");
}

#[test]
fn sync_convert_raw_body_and_multipart_with_inline_report() {
    let s = Server::start(&[]);
    // Raw body, format from the query.
    let r = s.post("/v1/convert?format=obj", "model/obj", &mesh_bytes("cow.obj"));
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(r.header("content-type"), Some("model/obj"));
    let m = read_obj(&r.body);
    // Known counts of cow.obj (shared/meshes/README.md).
    assert_eq!((m.vertex_count(), m.face_count()), (2903, 5804));
    // The report stays retrievable at the Link header's URL.
    let id = r.header("x-meshwork-job-id").expect("job id").to_string();
    assert_eq!(r.header("link"), Some(format!("</v1/jobs/{id}/report>; rel=\"report\"").as_str()));
    let rep = s.get(&format!("/v1/jobs/{id}/report"));
    assert_eq!(rep.status, 200);
    assert_eq!(rep.json()["vertices"], 2903);
    assert_eq!(rep.json()["inputs"][0]["format"], "obj");
    // The sync result itself is not kept (it went back in the response).
    s.get(&format!("/v1/jobs/{id}/result")).problem(404, "not-found");

    // Multipart in, Accept picks OBJ, report=inline gives multipart/mixed (report, then mesh).
    let woody = mesh_bytes("woody.obj");
    let (ct, body) = multipart(&[file_part("mesh", "woody.obj", &woody), json_part("params", "{}")]);
    let r = s.req(
        "POST",
        "/v1/convert?report=inline",
        &[("content-type", &ct), ("accept", "model/obj")],
        Some(&body),
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let parts = split_mixed(r.header("content-type").unwrap(), &r.body);
    assert_eq!(parts.len(), 2);
    assert!(parts[0].0.contains("application/json") && parts[0].0.contains("name=\"report\""));
    let report: serde_json::Value = serde_json::from_slice(&parts[0].1).unwrap();
    assert_eq!((report["vertices"].as_u64(), report["faces"].as_u64()), (Some(694), Some(1267)));
    assert!(report["total_ms"].is_number() && report["stages"].is_object());
    assert!(parts[1].0.contains("model/obj"));
    let m = read_obj(&parts[1].1);
    assert_eq!((m.vertex_count(), m.face_count()), (694, 1267));
}

#[test]
fn bad_input_is_problem_json_naming_where() {
    let s = Server::start(&["--max-body-bytes", "100000", "--max-vertices", "500", "--max-iterations", "50"]);
    let tetra = TETRA_OBJ.as_bytes();
    s.post("/v1/frobnicate", "model/obj", tetra).problem(404, "unknown-job");
    // Unknown parameter: named, from the query and from the params part.
    let p = s.post("/v1/convert?bogus=1", "model/obj", tetra).problem(422, "invalid-params");
    assert_eq!(p["field"], "bogus");
    let p = s
        .post_multipart(
            "/v1/convert",
            &[file_part("mesh", "t.obj", tetra), json_part("params", "{\"weird\": true}")],
        )
        .problem(422, "invalid-params");
    assert_eq!(p["field"], "weird");
    s.post_multipart("/v1/convert", &[file_part("mesh", "t.obj", tetra), json_part("params", "[1")])
        .problem(422, "invalid-params");
    // A face index out of range, on line 3.
    let p = s
        .post("/v1/convert?format=obj", "model/obj", b"v 0 0 0\nv 1 0 0\nf 1 2 7\n")
        .problem(422, "invalid-mesh");
    assert_eq!(p["line"], 3, "{p}");
    // A coordinate that is not a number, on line 2.
    let p = s
        .post("/v1/convert?format=obj", "model/obj", b"v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n")
        .problem(422, "malformed-input");
    assert_eq!((p["line"].as_u64(), p["format"].as_str()), (Some(2), Some("obj")), "{p}");
    // Not a mesh at all.
    s.post("/v1/convert", "application/octet-stream", &[0xde, 0xad, 0xbe, 0xef, 0, 1, 2, 3])
        .problem(415, "unsupported-format");
    s.post("/v1/convert", "model/obj", b"").problem(400, "bad-request");
    s.post_multipart("/v1/convert", &[file_part("meshh", "t.obj", tetra)]).problem(400, "bad-request");
    // Limits, with the limit named.
    let big = vec![b'#'; 200_000];
    let p = s.post("/v1/convert", "model/obj", &big).problem(413, "too-large");
    assert_eq!(p["limit"], 100000);
    let p = s.post("/v1/convert?format=obj", "model/obj", &mesh_bytes("woody.obj")).problem(413, "too-large");
    assert!(p["detail"].as_str().unwrap().contains("vertices"), "{p}");
    let p = s.post("/v1/smooth?iterations=51", "model/obj", tetra).problem(413, "too-large");
    assert!(p["detail"].as_str().unwrap().contains("iterations"), "{p}");
    // Output format nobody can produce.
    s.req("POST", "/v1/convert", &[("content-type", "model/obj"), ("accept", "image/png")], Some(tetra))
        .problem(406, "not-acceptable");
    s.post("/v1/convert?format=xyz", "model/obj", tetra).problem(400, "bad-request");
    // Fit needs two inputs.
    let p = s.post("/v1/fit", "model/obj", tetra).problem(422, "invalid-params");
    assert_eq!(p["field"], "inputs");
}

#[test]
fn admission_is_bounded_503_at_once_and_timeout_is_504() {
    // 1 worker + 1 queued: the third concurrent job is refused immediately.
    let s = Server::start(&["--workers", "1", "--queue", "1", "--job-timeout", "1"]);
    let tetra = TETRA_OBJ.as_bytes();
    let a = s.post("/v1/jobs?job=sleep&ms=700", "model/obj", tetra);
    let b = s.post("/v1/jobs?job=sleep&ms=700", "model/obj", tetra);
    assert_eq!((a.status, b.status), (202, 202));
    let t = Instant::now();
    let c = s.post("/v1/jobs?job=sleep&ms=10", "model/obj", tetra);
    c.problem(503, "queue-full");
    assert!(t.elapsed() < Duration::from_millis(500), "503 must come at once");
    assert_eq!(c.header("retry-after"), Some("1"));
    let r = s.get("/readyz");
    assert_eq!((r.status, r.json()["ready"].as_bool()), (503, Some(false)));
    // The time limit counts from admission: b waited ~0.7 s, then runs into the 1 s limit.
    let b_id = b.json()["id"].as_str().unwrap().to_string();
    let st = wait_finished(&s, &b_id);
    assert_eq!(st["state"], "failed", "{st}");
    assert_eq!(st["error"]["type"], "/problems/timed-out");
    let p = s.get(&format!("/v1/jobs/{b_id}/result")).problem(504, "timed-out");
    assert_eq!(p["status"], 504);
    // Sync: a job longer than the limit answers 504.
    s.post("/v1/sleep?ms=3000", "model/obj", tetra).problem(504, "timed-out");
    // Capacity is back.
    assert_eq!(s.post("/v1/sleep?ms=1&format=obj", "model/obj", tetra).status, 200);
}

fn wait_finished(s: &Server, id: &str) -> serde_json::Value {
    let t = Instant::now();
    loop {
        let st = s.get(&format!("/v1/jobs/{id}")).json();
        if ["succeeded", "failed", "cancelled"].contains(&st["state"].as_str().unwrap_or("")) {
            return st;
        }
        assert!(t.elapsed() < Duration::from_secs(20), "job {id} never finished: {st}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn async_flow_status_result_report_and_cancel() {
    let s = Server::start(&[]);
    let tetra = TETRA_OBJ.as_bytes();
    // Job named in the multipart body.
    let r = s.post_multipart(
        "/v1/jobs?format=obj",
        &[
            Part { name: "job", filename: None, content_type: "text/plain", data: b"sleep" },
            file_part("mesh", "t.obj", tetra),
            json_part("params", "{\"ms\": 300}"),
        ],
    );
    assert_eq!(r.status, 202, "{}", r.text());
    let loc = r.header("location").unwrap().to_string();
    let id = r.json()["id"].as_str().unwrap().to_string();
    assert_eq!(loc, format!("/v1/jobs/{id}"));
    assert_eq!(id.len(), 32);
    // Not done yet: result is a 409 conflict; status shows progress.
    s.get(&format!("{loc}/result")).problem(409, "conflict");
    std::thread::sleep(Duration::from_millis(100));
    let st = s.get(&loc).json();
    assert_eq!(st["state"], "running", "{st}");
    assert_eq!(st["stage"], "sleep");
    let f = st["progress"].as_f64().unwrap();
    assert!((0.0..1.0).contains(&f), "{st}");
    let st = wait_finished(&s, &id);
    assert_eq!(st["state"], "succeeded");
    assert_eq!(st["progress"], 1.0);
    assert!(st["expires_at"].as_f64().unwrap() > st["finished_at"].as_f64().unwrap());
    let res = s.get(&format!("{loc}/result"));
    assert_eq!(res.status, 200);
    assert_eq!(read_obj(&res.body).vertex_count(), 4);
    assert!(s.get(&format!("{loc}/report")).json()["slept_ms"].as_f64().unwrap() >= 300.0);
    s.req("DELETE", &loc, &[], None).problem(409, "conflict");

    // Cancel a long job: it stops at its next check.
    let r = s.post("/v1/jobs?job=sleep&ms=20000", "model/obj", tetra);
    let loc = r.header("location").unwrap().to_string();
    let t = Instant::now();
    assert_eq!(s.req("DELETE", &loc, &[], None).status, 202);
    let st = wait_finished(&s, r.json()["id"].as_str().unwrap());
    assert_eq!(st["state"], "cancelled");
    assert!(t.elapsed() < Duration::from_secs(2));
    s.get(&format!("{loc}/result")).problem(409, "cancelled");
    s.get("/v1/jobs/0123456789abcdef0123456789abcdef").problem(404, "not-found");
    // No job named.
    let p = s.post("/v1/jobs", "model/obj", tetra).problem(422, "invalid-params");
    assert_eq!(p["field"], "job");
}

#[test]
fn results_expire_after_the_ttl() {
    let s = Server::start(&["--result-ttl", "1"]);
    let r = s.post("/v1/jobs?job=convert&format=obj", "model/obj", TETRA_OBJ.as_bytes());
    let id = r.json()["id"].as_str().unwrap().to_string();
    wait_finished(&s, &id);
    assert_eq!(s.get(&format!("/v1/jobs/{id}/result")).status, 200);
    std::thread::sleep(Duration::from_millis(2300));
    s.get(&format!("/v1/jobs/{id}/result")).problem(410, "gone");
    assert_eq!(s.get(&format!("/v1/jobs/{id}")).json()["removed"], "expired");
}

#[test]
fn panic_fails_only_its_job() {
    let s = Server::start(&["--workers", "1"]);
    let p = s.post("/v1/panic", "model/obj", TETRA_OBJ.as_bytes()).problem(500, "internal");
    assert!(p["detail"].as_str().unwrap().contains("panicked"));
    // The same single worker still serves.
    assert_eq!(s.post("/v1/convert?format=obj", "model/obj", TETRA_OBJ.as_bytes()).status, 200);
}

#[test]
fn client_disconnect_cancels_sync_job() {
    let s = Server::start(&[]);
    let addr = s.url.trim_start_matches("http://").to_string();
    let mut sock = std::net::TcpStream::connect(&addr).unwrap();
    let body = TETRA_OBJ.as_bytes();
    write!(sock, "POST /v1/sleep?ms=20000 HTTP/1.1\r\nHost: x\r\nContent-Type: model/obj\r\nContent-Length: {}\r\n\r\n", body.len()).unwrap();
    sock.write_all(body).unwrap();
    std::thread::sleep(Duration::from_millis(300));
    drop(sock);
    let t = Instant::now();
    loop {
        let m = s.get("/metrics").text();
        if m.contains("meshwork_jobs_total{job=\"sleep\",outcome=\"cancelled\"} 1") {
            break;
        }
        assert!(t.elapsed() < Duration::from_secs(5), "job not cancelled after disconnect:\n{m}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn bearer_auth_and_cors() {
    let s = Server::start(&["--api-key", "s3cret", "--cors-origins", "https://app.example"]);
    let tetra = TETRA_OBJ.as_bytes();
    let r = s.post("/v1/convert?format=obj", "model/obj", tetra);
    r.problem(401, "unauthorized");
    assert_eq!(r.header("www-authenticate"), Some("Bearer"));
    s.req(
        "POST",
        "/v1/convert?format=obj",
        &[("content-type", "model/obj"), ("authorization", "Bearer nope")],
        Some(tetra),
    )
    .problem(401, "unauthorized");
    let ok = s.req(
        "POST",
        "/v1/convert?format=obj",
        &[("content-type", "model/obj"), ("authorization", "Bearer s3cret")],
        Some(tetra),
    );
    assert_eq!(ok.status, 200);
    // Operational endpoints stay open.
    assert_eq!(s.get("/healthz").status, 200);
    // CORS preflight from the configured origin.
    let pre = s.req(
        "OPTIONS",
        "/v1/smooth",
        &[("origin", "https://app.example"), ("access-control-request-method", "POST")],
        None,
    );
    assert_eq!(pre.header("access-control-allow-origin"), Some("https://app.example"));
    let other = s.req(
        "OPTIONS",
        "/v1/smooth",
        &[("origin", "https://evil.example"), ("access-control-request-method", "POST")],
        None,
    );
    assert_eq!(other.header("access-control-allow-origin"), None);
}

#[test]
fn sigterm_finishes_running_job_then_exits() {
    let mut s = Server::start(&["--shutdown-grace", "10"]);
    let url = s.url.clone();
    let h = std::thread::spawn(move || {
        // A separate raw connection so the request is in flight while SIGTERM arrives.
        let addr = url.trim_start_matches("http://").to_string();
        let mut sock = std::net::TcpStream::connect(addr).unwrap();
        let body = TETRA_OBJ.as_bytes();
        write!(sock, "POST /v1/sleep?ms=800&format=obj HTTP/1.1\r\nHost: x\r\nConnection: close\r\nContent-Type: model/obj\r\nContent-Length: {}\r\n\r\n", body.len()).unwrap();
        sock.write_all(body).unwrap();
        let mut out = String::new();
        let _ = sock.read_to_string(&mut out);
        out
    });
    std::thread::sleep(Duration::from_millis(250));
    s.terminate();
    let out = h.join().unwrap();
    assert!(out.starts_with("HTTP/1.1 200"), "running job must finish: {out}");
    let t = Instant::now();
    loop {
        if let Some(code) = s.child.try_wait().unwrap() {
            assert!(code.success(), "{code:?}");
            break;
        }
        assert!(t.elapsed() < Duration::from_secs(5), "server did not exit after SIGTERM");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn every_format_out_and_back_in() {
    let s = Server::start(&[]);
    let woody = mesh_bytes("woody.obj");
    for (fmt, mime) in [
        ("glb", "model/gltf-binary"),
        ("gltf", "model/gltf+json"),
        ("obj", "model/obj"),
        ("ply", "application/x-ply"),
        ("stl", "model/stl"),
        ("off", "application/x-off"),
    ] {
        let r = s.post(&format!("/v1/convert?format={fmt}"), "model/obj", &woody);
        assert_eq!(r.status, 200, "{fmt}: {}", r.text());
        assert_eq!(r.header("content-type"), Some(mime));
        if fmt == "glb" {
            assert_eq!(&r.body[..4], b"glTF");
        }
        // And back in as a raw body with its media type; woody: 694 vertices, 1267 triangles.
        let back = s.post("/v1/convert?format=obj", mime, &r.body);
        assert_eq!(back.status, 200, "{fmt} back in: {}", back.text());
        let m = read_obj(&back.body);
        assert_eq!(m.face_count(), 1267, "{fmt}");
        if fmt != "stl" {
            // STL stores unshared triangle corners, so only faces survive it as counted.
            assert_eq!(m.vertex_count(), 694, "{fmt}");
        }
    }
    // GLB is the default output.
    let r = s.post("/v1/convert", "model/obj", &woody);
    assert_eq!(r.header("content-type"), Some("model/gltf-binary"));
}

#[test]
fn validate_repair_and_smooth_through_http() {
    let s = Server::start(&[]);
    // Validate answers with the report itself. Bunny: one component, 5 holes in the base.
    let r = s
        .post_multipart("/v1/validate", &[file_part("mesh", "bunny.obj", &mesh_bytes("stanford-bunny.obj"))]);
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(r.header("content-type"), Some("application/json"));
    let v = r.json();
    assert_eq!(
        (v["faces"].as_u64(), v["boundary_loops"].as_u64(), v["components"].as_u64()),
        (Some(69451), Some(5), Some(1)),
        "{v}"
    );
    // cow.obj: closed.
    let v = s.post("/v1/validate", "model/obj", &mesh_bytes("cow.obj")).json();
    assert_eq!((v["vertices"].as_u64(), v["closed"].as_bool()), (Some(2903), Some(true)), "{v}");

    // Repair with params from a JSON part.
    let r = s.post_multipart(
        "/v1/repair?format=obj&report=inline",
        &[file_part("mesh", "suzanne.obj", &mesh_bytes("suzanne.obj")), json_part("params", "{}")],
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let parts = split_mixed(r.header("content-type").unwrap(), &r.body);
    let report: serde_json::Value = serde_json::from_slice(&parts[0].1).unwrap();
    assert!(report["total_ms"].is_number(), "{report}");
    assert!(read_obj(&parts[1].1).face_count() > 0);

    // Smooth with params in the query, GLB out; the report is behind the Link header.
    let fandisk = mesh_bytes("fandisk.obj");
    let r = s.post("/v1/smooth?method=taubin&iterations=5", "model/obj", &fandisk);
    assert_eq!(r.status, 200, "{}", r.text());
    let out = read(&r.body, &ReadOptions::default()).unwrap().mesh;
    assert_eq!(out.vertex_count(), 6475, "fandisk keeps its vertices");
    let link = r.header("link").unwrap();
    let url = link.trim_start_matches('<').split('>').next().unwrap();
    let rep = s.get(url).json();
    for k in ["volume_change", "area_change", "hausdorff", "total_ms"] {
        assert!(rep[k].is_number(), "{k} missing: {rep}");
    }
    assert!(rep["hausdorff"].as_f64().unwrap() > 0.0, "smoothing moved nothing");
    // A bad smoothing parameter is named.
    let p = s.post("/v1/smooth?method=bogus", "model/obj", &fandisk).problem(422, "invalid-params");
    assert_eq!(p["field"], "method", "{p}");
}

fn obj_of(mesh: &meshwork_core::Mesh) -> Vec<u8> {
    meshwork_core::io::write(mesh, meshwork_core::io::Format::Obj).unwrap()
}

#[test]
fn morph_answers_its_animated_glb_and_refuses_genus_one() {
    use meshwork_core::shapes;
    let s = Server::start(&[]);
    let a = obj_of(&shapes::icosphere(2, 1.0));
    let mut e = shapes::icosphere(1, 1.0);
    for p in &mut e.positions {
        p[0] *= 2.0;
    }
    let b = obj_of(&e);
    // Asked for OBJ, but morph's result is the animated GLB it builds (its artifact).
    let r = s.post_multipart(
        "/v1/morph?frames=4&format=obj",
        &[file_part("mesh", "a.obj", &a), file_part("mesh", "b.obj", &b)],
    );
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(r.header("content-type"), Some("model/gltf-binary"));
    assert_eq!(&r.body[..4], b"glTF");
    let glb = read(&r.body, &ReadOptions::default()).expect("our own GLB reads back").mesh;
    assert!(glb.vertex_count() >= 42, "the base mesh holds at least the first input's vertices");
    // A torus is genus 1: the morph refuses it, saying so.
    let t = obj_of(&shapes::torus(12, 8, 1.0, 0.3, false));
    let p = s
        .post_multipart("/v1/morph", &[file_part("mesh", "a.obj", &a), file_part("mesh", "t.obj", &t)])
        .problem(422, "unsupported-topology");
    assert!(p["detail"].as_str().unwrap().contains("genus"), "{p}");
    // Only one input.
    s.post_multipart("/v1/morph", &[file_part("mesh", "a.obj", &a)]).problem(422, "invalid-params");
    // The frames as separate OBJ files in a ZIP.
    let r = s.post_multipart(
        "/v1/morph?frames=3&frames_zip=obj",
        &[file_part("mesh", "a.obj", &a), file_part("mesh", "b.obj", &b)],
    );
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(r.header("content-type"), Some("application/zip"));
    assert_eq!(&r.body[..4], b"PK\x03\x04");
    let end = &r.body[r.body.len() - 22..];
    assert_eq!(u16::from_le_bytes([end[10], end[11]]), 3, "three frames");
}

/// A wavy line across the unit square and a closed circle, as OBJ `l` polylines (the curves of
/// core/tests/fit_plane.rs): they cut the plane into 3 regions.
fn plane_curves_obj() -> String {
    let mut s = String::new();
    for k in 0..=12 {
        let x = k as f64 / 12.0;
        s += &format!("v {x} {} 0\n", 0.2 + 0.04 * (6.0 * x).sin());
    }
    for k in 0..24 {
        let t = std::f64::consts::TAU * k as f64 / 24.0;
        s += &format!("v {} {} 0\n", 0.55 + 0.22 * t.cos(), 0.6 + 0.22 * t.sin());
    }
    s += &format!("l {}\n", (1..=13).map(|i| i.to_string()).collect::<Vec<_>>().join(" "));
    s += &format!("l {} 14\n", (14..=37).map(|i| i.to_string()).collect::<Vec<_>>().join(" "));
    s
}

#[test]
fn fit_takes_template_and_curves_parts() {
    let s = Server::start(&["--max-curve-points", "30"]);
    let template = obj_of(&meshwork_core::shapes::grid(24, 24, 1.0 / 24.0, false));
    let curves = plane_curves_obj();
    let params = r#"{"alignment": "none", "coplanar_centres": "augment"}"#;
    // 38 curve points > the limit of 30: refused before the job runs, naming the limit.
    let p = s
        .post_multipart(
            "/v1/fit",
            &[
                file_part("template", "grid.obj", &template),
                file_part("curves", "c.obj", curves.as_bytes()),
                json_part("params", params),
            ],
        )
        .problem(413, "too-large");
    assert!(p["detail"].as_str().unwrap().contains("curve points"), "{p}");
    let s = Server::start(&[]);
    // Parts in the "wrong" order still map by name.
    let r = s.post_multipart(
        "/v1/fit?format=obj&report=inline",
        &[
            file_part("curves", "c.obj", curves.as_bytes()),
            json_part("params", params),
            file_part("template", "grid.obj", &template),
        ],
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let parts = split_mixed(r.header("content-type").unwrap(), &r.body);
    let report: serde_json::Value = serde_json::from_slice(&parts[0].1).unwrap();
    assert_eq!(report["regions"], 3, "{report}");
    let m = read_obj(&parts[1].1);
    assert_eq!(m.groups.len(), 3, "the three regions survive as OBJ groups");
    assert!(m.positions.iter().all(|p| p[2].abs() < 1e-6), "the plane stays z = 0");
}

#[test]
fn external_reference_in_gltf_is_422_naming_the_buffer() {
    // A glTF whose buffer points at a file beside it: we never open files named by uploads.
    let s = Server::start(&[]);
    let gltf = br#"{"asset":{"version":"2.0"},
        "buffers":[{"uri":"mesh.bin","byteLength":36}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
        "nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0}"#;
    let p = s.post("/v1/convert?format=obj", "model/gltf+json", gltf).problem(422, "external-reference");
    assert_eq!(p["gltf_path"], "buffers[0].uri", "{p}");
    assert!(p["detail"].as_str().unwrap().contains("buffers[0].uri"), "{p}");
}
