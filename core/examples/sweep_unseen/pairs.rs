//! Bad correspondence pairs: repeated, two on one curve point, NaN or short coordinates, far from
//! every curve, on a vertex in no face, a negative vertex index.

use meshwork_core::fit::testdata::with_zero_area_face;
use meshwork_core::mesh::Point3;
use meshwork_core::shapes::icosphere;

use crate::support::{case, fit_inputs, pairs_case, vs_octants, Case, Expect};

pub fn pairs() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();
    let p = |v: u32, x: Point3| json!({"template_vertex": v, "curve_point": x});
    // Three good pairs (icosphere vertices 0, 5, 9 on the +x, +y, +z axis points of the
    // sections) followed by the pair under test.
    let three_and = |last: serde_json::Value| {
        json!([p(0, [1.4, 0.0, 0.0]), p(5, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9]), last])
    };
    out.push(pairs_case(
        "the same pair twice",
        json!([
            p(0, [1.4, 0.0, 0.0]),
            p(0, [1.4, 0.0, 0.0]),
            p(5, [0.0, 1.15, 0.0]),
            p(9, [0.0, 0.0, 0.9]),
            p(11, [-1.4, 0.0, 0.0])
        ]),
        &["pairs[1]"],
    ));
    out.push(pairs_case(
        "two pairs on one curve point",
        json!([
            p(0, [1.4, 0.0, 0.0]),
            p(1, [1.4, 0.0, 0.0]),
            p(5, [0.0, 1.15, 0.0]),
            p(9, [0.0, 0.0, 0.9]),
            p(11, [-1.4, 0.0, 0.0])
        ]),
        &["pairs[1]"],
    ));
    out.push(pairs_case(
        "pair curve point NaN (JSON null)",
        json!([{"template_vertex": 0, "curve_point": [null, 0.0, 0.0]}]),
        &["pairs"],
    ));
    out.push(pairs_case(
        "pair curve point with 2 coordinates",
        json!([{"template_vertex": 0, "curve_point": [1.0, 0.0]}]),
        &["pairs"],
    ));
    out.push(pairs_case("pair far from every curve", three_and(p(11, [-50.0, 0.0, 0.0])), &["pairs[3]"]));
    out.push(case(
        "pair on a vertex in no face",
        || vs_octants(with_zero_area_face(3)),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), p(643, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9]), p(11, [-1.4, 0.0, 0.0])]}),
        Expect::Error(&["pairs[1].template_vertex", "no face"]),
    ));
    out.push(pairs_case(
        "negative template vertex",
        json!([p(0, [1.4, 0.0, 0.0]), {"template_vertex": -1, "curve_point": [0, 0, 0]}]),
        &["template_vertex"],
    ));

    out.push(pairs_case(
        "pair template vertex beyond the mesh",
        three_and(p(642, [-1.4, 0.0, 0.0])),
        &["pairs[3]", "642"],
    ));

    out.push(pairs_case(
        "pair template vertex u32 max",
        three_and(json!({"template_vertex": 4294967295u64, "curve_point": [-1.4, 0.0, 0.0]})),
        &["pairs[3]"],
    ));

    out.push(pairs_case(
        "pair template vertex 2^40",
        json!([{"template_vertex": 1099511627776u64, "curve_point": [-1.4, 0.0, 0.0]}]),
        &["pairs"],
    ));

    out.push(pairs_case("pair curve point 1e300", three_and(p(11, [1e300, 0.0, 0.0])), &["pairs[3]"]));

    out.push(pairs_case(
        "3 pairs only (too few centres)",
        json!([p(0, [1.4, 0.0, 0.0]), p(5, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9])]),
        &["pairs"],
    ));
    out.push(case(
        "JSON polylines: a 1-point polyline and a null",
        || {
            let m = meshwork_core::fit::curves::polylines_from_json(
                br#"{"polylines": [[[0,0,1]], [[0,1,0],[null,0,0]]]}"#,
            )
            .expect("json")?;
            fit_inputs(icosphere(2, 1.0), m)
        },
        json!({}),
        Expect::Error(&["polylines[0]"]),
    ));
    out
}
