//! The fit endpoint with curve networks in every accepted format (OBJ `l`, glTF LINE_STRIP, JSON
//! polylines) and with malformed curve files. The network is three great circles sampled so that
//! no polyline has a vertex at their six crossings: the 8 octant regions only close when the
//! crossings are inserted (truth by hand: three great circles cut a sphere into 8 parts).

mod common;

use common::{file_part, json_part, Server};
use meshwork_core::fit::testdata::{great_circles, polylines};
use meshwork_core::io::{write, Format};
use meshwork_core::shapes::icosphere;

fn fit(s: &Server, curves_name: &str, curves: &[u8]) -> common::Resp {
    let template = write(&icosphere(3, 1.0), Format::Obj).unwrap();
    s.post_multipart(
        "/v1/fit?format=obj&report=inline",
        &[
            file_part("template", "sphere.obj", &template),
            file_part("curves", curves_name, curves),
            json_part("params", "{}"),
        ],
    )
}

fn report(r: &common::Resp) -> serde_json::Value {
    assert_eq!(r.status, 200, "{}", r.text());
    let ct = r.header("content-type").unwrap().to_string();
    let boundary = ct.split("boundary=").nth(1).unwrap().trim_matches('"').to_string();
    let text = String::from_utf8_lossy(&r.body).to_string();
    // The first part of the multipart/mixed answer is the report (JSON).
    let first = text.split(&format!("--{boundary}")).nth(1).unwrap();
    let json = &first[first.find("\r\n\r\n").unwrap() + 4..];
    serde_json::from_str(json.trim_end()).unwrap()
}

#[test]
fn crossing_circles_in_every_curve_format() {
    let s = Server::start(&[]);
    let lines = great_circles(1.3, 32, [0.05, 0.11, 0.07]);
    let mesh = polylines(&lines);
    let json = serde_json::json!({ "polylines": lines }).to_string();
    for (name, bytes) in [
        ("c.obj", write(&mesh, Format::Obj).unwrap()),
        ("c.glb", write(&mesh, Format::Glb).unwrap()),
        ("c.json", json.into_bytes()),
    ] {
        let r = report(&fit(&s, name, &bytes));
        assert_eq!(r["regions"], 8, "{name}: {}", r["network"]);
        assert_eq!(r["network"]["crossings_inserted"], 6, "{name}");
        assert_eq!(r["segments_as_edges"], 1.0, "{name}");
    }
}

#[test]
fn malformed_curve_files_are_problems_naming_where() {
    let s = Server::start(&[]);
    let cases: [(&str, &[u8], &str); 3] = [
        ("c.json", br#"{"polylines": [[[0,0,0],[1,0,0]], [[0,1,0],[1,"x",0]]]}"#, "polylines[1][1]"),
        ("c.json", br#"{"polylines": [[[0,0,0],[1,0,0]], [[0,1,0]]]}"#, "polylines[1]"),
        ("c.obj", b"v 0 0 0\nv 1 0 0\nl 1 2\nl 2 7\n", "line 4"),
    ];
    for (name, bytes, where_) in cases {
        let r = fit(&s, name, bytes);
        assert!((400..500).contains(&r.status), "{name}: {} {}", r.status, r.text());
        assert_eq!(r.header("content-type"), Some("application/problem+json"));
        let p = r.json();
        let text = p.to_string();
        assert!(text.contains(where_), "{name}: expected {where_} in {text}");
    }
}
