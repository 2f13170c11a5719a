//! Test harness: starts the real `meshwork` binary on an ephemeral port and talks HTTP to it.
#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

pub const BIN: &str = env!("CARGO_BIN_EXE_meshwork");

pub fn shared_mesh(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes").join(name)
}

pub fn mesh_bytes(name: &str) -> Vec<u8> {
    std::fs::read(shared_mesh(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Runs the `meshwork` command line with `args` to its end.
pub fn run_cli(args: &[&str]) -> std::process::Output {
    Command::new(BIN).args(args).output().expect("run meshwork")
}

/// What a finished command wrote to its standard error, as text.
pub fn stderr_text(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The temporary folder of test file `test` in this process (`meshwork-<test>-<pid>`).
pub fn tmp_dir(test: &str) -> PathBuf {
    std::env::temp_dir().join(format!("meshwork-{test}-{}", std::process::id()))
}

/// `name` in [`tmp_dir`]`(test)`, the folder created on first use.
pub fn tmp_file(test: &str, name: &str) -> PathBuf {
    let d = tmp_dir(test);
    std::fs::create_dir_all(&d).expect("create the test's temporary folder");
    d.join(name)
}

pub struct Server {
    pub child: Child,
    pub url: String,
    agent: ureq::Agent,
}

pub struct Resp {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
}

impl Resp {
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers.iter().find(|(k, _)| k.eq_ignore_ascii_case(name)).map(|(_, v)| v.as_str())
    }
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(&self.body)))
    }
    /// Asserts an RFC 9457 problem with this status and kind; returns it.
    pub fn problem(&self, status: u16, kind: &str) -> serde_json::Value {
        assert_eq!(self.status, status, "{}", String::from_utf8_lossy(&self.body));
        assert_eq!(self.header("content-type"), Some("application/problem+json"));
        let p = self.json();
        assert_eq!(p["type"], format!("/problems/{kind}"), "{p}");
        assert_eq!(p["status"], status);
        assert!(p["title"].as_str().is_some_and(|t| !t.is_empty()));
        assert!(p["detail"].as_str().is_some_and(|t| !t.is_empty()));
        p
    }
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }
}

impl Server {
    /// `meshwork serve --port 0 --debug-jobs <extra>`; waits for the "listening" line.
    pub fn start(extra: &[&str]) -> Server {
        let mut child = Command::new(BIN)
            .args(["serve", "--port", "0", "--debug-jobs", "--log", "warn"])
            .args(extra)
            .env_remove("MESHWORK_API_KEY")
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("start meshwork serve");
        let stdout = child.stdout.take().expect("stdout");
        let mut line = String::new();
        BufReader::new(stdout).read_line(&mut line).expect("read listening line");
        let url = line
            .trim()
            .strip_prefix("meshwork listening on ")
            .unwrap_or_else(|| panic!("unexpected first line: {line:?}"))
            .to_string();
        let agent: ureq::Agent = ureq::Agent::config_builder()
            .http_status_as_error(false)
            .timeout_global(Some(Duration::from_secs(60)))
            .build()
            .into();
        Server { child, url, agent }
    }

    pub fn req(&self, method: &str, path: &str, headers: &[(&str, &str)], body: Option<&[u8]>) -> Resp {
        let uri = format!("{}{}", self.url, path);
        let mut b = ureq::http::Request::builder().method(method).uri(&uri);
        for (k, v) in headers {
            b = b.header(*k, *v);
        }
        let req = b.body(body.map(<[u8]>::to_vec).unwrap_or_default()).expect("request");
        let mut r = self.agent.run(req).unwrap_or_else(|e| panic!("{method} {uri}: {e}"));
        let status = r.status().as_u16();
        let headers =
            r.headers().iter().map(|(k, v)| (k.to_string(), v.to_str().unwrap_or("").to_string())).collect();
        let body = r.body_mut().with_config().limit(1 << 30).read_to_vec().expect("body");
        Resp { status, headers, body }
    }

    pub fn get(&self, path: &str) -> Resp {
        self.req("GET", path, &[], None)
    }

    pub fn post(&self, path: &str, content_type: &str, body: &[u8]) -> Resp {
        self.req("POST", path, &[("content-type", content_type)], Some(body))
    }

    pub fn post_multipart(&self, path: &str, parts: &[Part]) -> Resp {
        let (ct, body) = multipart(parts);
        self.post(path, &ct, &body)
    }

    /// Sends SIGTERM.
    pub fn terminate(&self) {
        let ok = Command::new("kill").args(["-TERM", &self.child.id().to_string()]).status().expect("kill");
        assert!(ok.success());
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub struct Part<'a> {
    pub name: &'a str,
    pub filename: Option<&'a str>,
    pub content_type: &'a str,
    pub data: &'a [u8],
}

pub fn file_part<'a>(name: &'a str, filename: &'a str, data: &'a [u8]) -> Part<'a> {
    Part { name, filename: Some(filename), content_type: "application/octet-stream", data }
}

pub fn json_part<'a>(name: &'a str, json: &'a str) -> Part<'a> {
    Part { name, filename: None, content_type: "application/json", data: json.as_bytes() }
}

pub fn multipart(parts: &[Part]) -> (String, Vec<u8>) {
    let boundary = "XmeshworkTestBoundaryX";
    let mut body = Vec::new();
    for p in parts {
        body.extend_from_slice(
            format!("--{boundary}\r\nContent-Disposition: form-data; name=\"{}\"", p.name).as_bytes(),
        );
        if let Some(f) = p.filename {
            body.extend_from_slice(format!("; filename=\"{f}\"").as_bytes());
        }
        body.extend_from_slice(format!("\r\nContent-Type: {}\r\n\r\n", p.content_type).as_bytes());
        body.extend_from_slice(p.data);
        body.extend_from_slice(b"\r\n");
    }
    body.extend_from_slice(format!("--{boundary}--\r\n").as_bytes());
    (format!("multipart/form-data; boundary={boundary}"), body)
}

/// Posts a fit of the level-3 unit icosphere (as OBJ) to the curve file `curves` named
/// `curves_name` (its extension picks the reader) with `params` (JSON text), asking for an OBJ and
/// the report inline.
pub fn post_fit_on_icosphere(s: &Server, curves_name: &str, curves: &[u8], params: &str) -> Resp {
    let sphere = meshwork_core::shapes::icosphere(3, 1.0);
    let template =
        meshwork_core::io::write(&sphere, meshwork_core::io::Format::Obj).expect("OBJ of an icosphere");
    s.post_multipart(
        "/v1/fit?format=obj&report=inline",
        &[
            file_part("template", "sphere.obj", &template),
            file_part("curves", curves_name, curves),
            json_part("params", params),
        ],
    )
}

/// The report of a job answered with `report=inline`: the first part (JSON) of the
/// multipart/mixed answer, after checking the status is 200.
pub fn inline_report(r: &Resp) -> serde_json::Value {
    assert_eq!(r.status, 200, "{}", r.text());
    let parts = split_mixed(r.header("content-type").expect("content-type"), &r.body);
    serde_json::from_slice(&parts[0].1).expect("the first part is the JSON report")
}

/// Splits a `multipart/mixed` response into (headers, body) parts.
pub fn split_mixed(content_type: &str, body: &[u8]) -> Vec<(String, Vec<u8>)> {
    let boundary = content_type.split("boundary=").nth(1).expect("boundary").trim();
    let delim = format!("--{boundary}");
    let mut parts = Vec::new();
    let mut rest = body;
    loop {
        let Some(start) = find(rest, delim.as_bytes()) else { break };
        rest = &rest[start + delim.len()..];
        if rest.starts_with(b"--") {
            break;
        }
        rest = &rest[2..]; // CRLF
        let hdr_end = find(rest, b"\r\n\r\n").expect("part headers");
        let headers = String::from_utf8_lossy(&rest[..hdr_end]).into_owned();
        let data_start = hdr_end + 4;
        let next = find(&rest[data_start..], format!("\r\n{delim}").as_bytes()).expect("next boundary");
        parts.push((headers, rest[data_start..data_start + next].to_vec()));
        rest = &rest[data_start + next + 2..];
    }
    parts
}

fn find(h: &[u8], n: &[u8]) -> Option<usize> {
    h.windows(n.len()).position(|w| w == n)
}

/// A small valid OBJ (a unit tetrahedron, 4 vertices, 4 faces).
pub const TETRA_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
