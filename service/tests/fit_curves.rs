//! The fit endpoint with curve networks in every accepted format (OBJ `l`, glTF LINE_STRIP, JSON
//! polylines) and with malformed curve files. The network is three great circles sampled so that
//! no polyline has a vertex at their six crossings: the 8 octant regions only close when the
//! crossings are inserted (truth by hand: three great circles cut a sphere into 8 parts).

mod common;

use common::{inline_report, post_fit_on_icosphere, Server};
use meshwork_core::fit::testdata::{great_circles, polylines};
use meshwork_core::io::{write, Format};

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
        let r = inline_report(&post_fit_on_icosphere(&s, name, &bytes, "{}"));
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
        let r = post_fit_on_icosphere(&s, name, bytes, "{}");
        assert!((400..500).contains(&r.status), "{name}: {} {}", r.status, r.text());
        assert_eq!(r.header("content-type"), Some("application/problem+json"));
        let p = r.json();
        let text = p.to_string();
        assert!(text.contains(where_), "{name}: expected {where_} in {text}");
    }
}
