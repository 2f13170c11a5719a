//! Curves through every reader (glTF LINES / LINE_STRIP / LINE_LOOP, GLB from our writer, OBJ `l`
//! with negative indices, PLY edges, JSON) and bad files: NaN / Inf coordinates, empty files, files
//! with no lines or no faces.

use meshwork_core::fit::testdata::{circle, gltf_lines, obj_negative_indices};
use meshwork_core::io::{write, Format};
use meshwork_core::mesh::Point3;
use meshwork_core::shapes::icosphere;

use crate::support::{
    case, fit_inputs, on_icosphere, read_as, segments, sphere_sections, Case, Expect, O, X, Y,
};

pub fn readers() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();
    out.push(case(
        "glTF LINES (segment pairs)",
        || {
            let c = sphere_sections(6);
            let idx: Vec<u32> = segments(&c).concat();
            on_icosphere(read_as(&gltf_lines(&c.positions, &idx, 1), "c.gltf")?)
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "glTF LINES shuffled segments",
        || {
            let c = sphere_sections(6);
            let segs = segments(&c);
            // Reverse every other segment and interleave: no two consecutive ones share an end.
            let mut idx = Vec::new();
            let n = segs.len();
            for k in 0..n {
                let s = segs[(k * 7) % n];
                if k % 2 == 0 {
                    idx.extend_from_slice(&[s[1], s[0]]);
                } else {
                    idx.extend_from_slice(&s);
                }
            }
            on_icosphere(read_as(&gltf_lines(&c.positions, &idx, 1), "c.gltf")?)
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "glTF LINE_LOOP circles (3 great circles)",
        || {
            // Three loops, each its own primitive would be nicer; one loop per file is enough to
            // cover the mode: here one loop per circle concatenated is not expressible, so the
            // equator only, plus the pole circles in a LINES file would be two files. One loop.
            let lines = [circle(O, X, Y, 1.2, 40, 0.0)];
            let pts: Vec<Point3> = lines[0][..40].to_vec();
            let idx: Vec<u32> = (0..40).collect();
            on_icosphere(read_as(&gltf_lines(&pts, &idx, 2), "c.gltf")?)
        },
        json!({"coplanar_centres": "augment"}),
        Expect::Fit(Some(2)),
    ));
    out.push(case(
        "OBJ l with negative indices",
        || on_icosphere(read_as(&obj_negative_indices(&sphere_sections(6)), "c.obj")?),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "glTF LINE_STRIP from our writer (GLB)",
        || {
            let bytes = write(&sphere_sections(6), Format::Glb)?;
            on_icosphere(read_as(&bytes, "c.glb")?)
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "curves as PLY edges",
        || {
            let c = sphere_sections(6);
            let mut s = format!(
                "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n",
                c.positions.len()
            );
            let segs = segments(&c);
            s += &format!("element edge {}\nproperty int vertex1\nproperty int vertex2\nend_header\n", segs.len());
            for p in &c.positions {
                s += &format!("{} {} {}\n", p[0], p[1], p[2]);
            }
            for e in &segs {
                s += &format!("{} {}\n", e[0], e[1]);
            }
            on_icosphere(read_as(s.as_bytes(), "c.ply")?)
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "OBJ curve vertex NaN",
        || fit_inputs(icosphere(2, 1.0), read_as(b"v 0 0 1\nv nan 0 0\nv 0 1 0\nl 1 2 3\n", "c.obj")?),
        json!({}),
        Expect::Error(&["line 2"]),
    ));
    out.push(case(
        "OBJ curve vertex inf",
        || fit_inputs(icosphere(2, 1.0), read_as(b"v 0 0 1\nv 1 0 0\nv 0 inf 0\nl 1 2 3\n", "c.obj")?),
        json!({}),
        Expect::Error(&["line 3"]),
    ));
    out.push(case(
        "JSON polyline 1e999",
        || {
            let m = meshwork_core::fit::curves::polylines_from_json(
                br#"{"polylines": [[[0,0,1],[1,0,0]], [[0,1,0],[1e999,0,0]]]}"#,
            )
            .expect("json")?;
            fit_inputs(icosphere(2, 1.0), m)
        },
        json!({}),
        Expect::Error(&["line 1 column 49"]),
    ));
    out.push(case(
        "template vertex NaN (OBJ)",
        || {
            let mut t = String::from_utf8(write(&icosphere(1, 1.0), Format::Obj)?).unwrap_or_default();
            t = t.replacen("v ", "v NaN 0 0 #", 1);
            fit_inputs(read_as(t.as_bytes(), "t.obj")?, sphere_sections(4))
        },
        json!({}),
        Expect::Error(&["line"]),
    ));
    out.push(case(
        "empty curves file",
        || fit_inputs(icosphere(2, 1.0), read_as(b"", "c.obj")?),
        json!({}),
        Expect::Error(&["empty"]),
    ));
    out.push(case(
        "curves file with vertices only",
        || fit_inputs(icosphere(2, 1.0), read_as(b"v 0 0 0\nv 1 0 0\n", "c.obj")?),
        json!({}),
        Expect::Error(&["polylines"]),
    ));
    out.push(case(
        "empty template file",
        || fit_inputs(read_as(b"", "t.obj")?, sphere_sections(4)),
        json!({}),
        Expect::Error(&["empty"]),
    ));
    out.push(case(
        "template with only points (no faces)",
        || fit_inputs(read_as(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "t.obj")?, sphere_sections(4)),
        json!({}),
        Expect::Error(&["faces"]),
    ));
    out.push(case(
        "curves file is a triangle mesh (no lines)",
        || fit_inputs(icosphere(2, 1.0), icosphere(2, 1.2)),
        json!({}),
        Expect::Error(&["polylines"]),
    ));
    out
}
