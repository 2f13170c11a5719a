//! Bad correspondence pairs: repeated, two on one curve point, NaN or short coordinates, far from
//! every curve, on a vertex in no face, a negative vertex index.

use meshwork_core::fit::testdata::with_zero_area_face;
use meshwork_core::mesh::Point3;
use meshwork_core::shapes::icosphere;

use crate::support::{case, sphere_sections, Case, Expect};

pub fn pairs() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();
    let p = |v: u32, x: Point3| json!({"template_vertex": v, "curve_point": x});
    out.push(case(
        "the same pair twice",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), p(0, [1.4, 0.0, 0.0]), p(5, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9]), p(11, [-1.4, 0.0, 0.0])]}),
        Expect::Error(&["pairs[1]"]),
    ));
    out.push(case(
        "two pairs on one curve point",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), p(1, [1.4, 0.0, 0.0]), p(5, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9]), p(11, [-1.4, 0.0, 0.0])]}),
        Expect::Error(&["pairs[1]"]),
    ));
    out.push(case(
        "pair curve point NaN (JSON null)",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [{"template_vertex": 0, "curve_point": [null, 0.0, 0.0]}]}),
        Expect::Error(&["pairs"]),
    ));
    out.push(case(
        "pair curve point with 2 coordinates",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [{"template_vertex": 0, "curve_point": [1.0, 0.0]}]}),
        Expect::Error(&["pairs"]),
    ));
    out.push(case(
        "pair far from every curve",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), p(5, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9]), p(11, [-50.0, 0.0, 0.0])]}),
        Expect::Error(&["pairs[3]"]),
    ));
    out.push(case(
        "pair on a vertex in no face",
        || Ok(vec![with_zero_area_face(3), sphere_sections(6)]),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), p(643, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9]), p(11, [-1.4, 0.0, 0.0])]}),
        Expect::Error(&["pairs[1].template_vertex", "no face"]),
    ));
    out.push(case(
        "negative template vertex",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), {"template_vertex": -1, "curve_point": [0, 0, 0]}]}),
        Expect::Error(&["template_vertex"]),
    ));

    out.push(case(
        "pair template vertex beyond the mesh",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), p(5, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9]), p(642, [-1.4, 0.0, 0.0])]}),
        Expect::Error(&["pairs[3]", "642"]),
    ));

    out.push(case(
        "pair template vertex u32 max",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), p(5, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9]), {"template_vertex": 4294967295u64, "curve_point": [-1.4, 0.0, 0.0]}]}),
        Expect::Error(&["pairs[3]"]),
    ));

    out.push(case(
        "pair template vertex 2^40",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [{"template_vertex": 1099511627776u64, "curve_point": [-1.4, 0.0, 0.0]}]}),
        Expect::Error(&["pairs"]),
    ));

    out.push(case(
        "pair curve point 1e300",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), p(5, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9]), p(11, [1e300, 0.0, 0.0])]}),
        Expect::Error(&["pairs[3]"]),
    ));

    out.push(case(
        "3 pairs only (too few centres)",
        || Ok(vec![icosphere(3, 1.0), sphere_sections(6)]),
        json!({"pairs": [p(0, [1.4, 0.0, 0.0]), p(5, [0.0, 1.15, 0.0]), p(9, [0.0, 0.0, 0.9])]}),
        Expect::Error(&["pairs"]),
    ));
    out.push(case(
        "JSON polylines: a 1-point polyline and a null",
        || {
            let m = meshwork_core::fit::curves::polylines_from_json(
                br#"{"polylines": [[[0,0,1]], [[0,1,0],[null,0,0]]]}"#,
            )
            .expect("json")?;
            Ok(vec![icosphere(2, 1.0), m])
        },
        json!({}),
        Expect::Error(&["polylines[0]"]),
    ));
    out
}
