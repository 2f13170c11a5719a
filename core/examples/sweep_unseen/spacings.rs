//! Curves laid out in ways not seen before (session 8): stars of 6 and 12 curves meeting at a
//! pole, a tiny loop inside one template face, two curves 1/13 of a segment apart, glTF strips placed
//! by node transforms, OBJ segment soup and repeated indices, curves in other units or turned, an
//! icosphere onto homer's sections, and networks that define no deformation (one straight line,
//! all points at one place but two).

use meshwork_core::fit::testdata::{circle, great_circles, polylines};
use meshwork_core::geometry::{cross, norm};
use meshwork_core::mesh::Mesh;
use meshwork_core::shapes::icosphere;

use crate::support::{
    case, equator_and_meridians, fit_inputs, icosphere_vs_sections_of, lines_of, on_icosphere, read_as,
    sections_of, segments, sphere_sections, unit_repaired, Case, Expect, X, Y, Z,
};

/// `m` with every position multiplied by `s`.
fn scaled(mut m: Mesh, s: f64) -> Mesh {
    for p in &mut m.positions {
        *p = [p[0] * s, p[1] * s, p[2] * s];
    }
    m
}

pub fn spacings() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();

    out.push(case(
        "star: 6 half-meridians at each pole + equator",
        || fit_inputs(icosphere(3, 1.0), polylines(&equator_and_meridians(6, 0.0, 0.0))),
        json!({}),
        Expect::Fit(Some(12)),
    ));

    out.push(case(
        "star: 12 half-meridians at each pole, coarse template",
        || fit_inputs(icosphere(2, 1.0), polylines(&equator_and_meridians(12, 0.0, 0.0))),
        json!({}),
        Expect::Fit(Some(24)),
    ));

    out.push(case(
        "glTF LINE_STRIPs, one node each (TRS) under a scaled parent",
        || {
            let curves = read_as(
                &meshwork_core::fit::testdata::gltf_strips_with_nodes(&lines_of(&sphere_sections(6))),
                "c.gltf",
            )?;
            on_icosphere(curves)
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));

    out.push(case(
        "OBJ segment soup (l with 2 points, own vertices, shuffled)",
        || {
            let c = sphere_sections(6);
            let segs = segments(&c);
            let n = segs.len();
            let mut s = String::new();
            for k in 0..n {
                let e = segs[(k * 11) % n];
                let e = if k % 3 == 0 { [e[1], e[0]] } else { e };
                for v in e {
                    let p = c.positions[v as usize];
                    s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
                }
                s += &format!("l {} {}\n", 2 * k + 1, 2 * k + 2);
            }
            on_icosphere(read_as(s.as_bytes(), "c.obj")?)
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));

    out.push(case(
        "OBJ l repeating indices and duplicate positions",
        || {
            let c = sphere_sections(6);
            let mut s = String::new();
            for p in &c.positions {
                s += &format!("v {} {} {}\nv {} {} {}\n", p[0], p[1], p[2], p[0], p[1], p[2]);
            }
            for l in &c.curves {
                s += "l";
                for (k, &v) in l.iter().enumerate() {
                    // every vertex twice: once by its index, once by its duplicate
                    s += &format!(" {} {}", 2 * v + 1, 2 * v + 2);
                    if k % 5 == 0 {
                        s += &format!(" {}", 2 * v + 2);
                    }
                }
                s += "\n";
            }
            on_icosphere(read_as(s.as_bytes(), "c.obj")?)
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));

    out.push(case(
        "tiny loop (r 0.03) inside one template face + octants",
        || {
            let mut l = lines_of(&sphere_sections(6));
            let d = [0.5f64, 0.6, 0.4];
            let n = norm(d);
            let d = [d[0] / n, d[1] / n, d[2] / n];
            let u = {
                let u = cross(d, Z);
                let k = norm(u);
                [u[0] / k, u[1] / k, u[2] / k]
            };
            let v = cross(d, u);
            let c = [d[0] * 1.02, d[1] * 1.02, d[2] * 1.02];
            l.push(circle(c, u, v, 0.03, 12, 0.0));
            fit_inputs(icosphere(2, 1.0), polylines(&l))
        },
        json!({"alignment": "none"}),
        Expect::Fit(Some(9)),
    ));

    out.push(case(
        "thin band: two parallels 0.01 apart on a coarse template",
        || {
            let mut l = great_circles(1.0, 48, [0.0; 3]);
            l.push(circle([0.0, 0.0, 0.01], X, Y, (1.0f64 - 1e-4).sqrt(), 48, 0.0));
            fit_inputs(icosphere(2, 1.0), polylines(&l))
        },
        json!({"alignment": "none"}),
        Expect::Fit(Some(12)),
    ));

    out.push(case(
        "curves 100× the template (auto)",
        || on_icosphere(scaled(sphere_sections(6), 100.0)),
        json!({}),
        Expect::Fit(Some(8)),
    ));

    out.push(case(
        "curves 1/100 of the template (auto)",
        || on_icosphere(scaled(sphere_sections(6), 0.01)),
        json!({}),
        Expect::Fit(Some(8)),
    ));

    let spot_regions = sections_of("spot").2;

    out.push(case(
        "spot vs its own sections rotated (auto)",
        || {
            let (c, _, _) = sections_of("spot");
            let t = unit_repaired("spot")?;
            let mut c = c;
            let (a, b) = (0.7f64, 0.4f64);
            for p in &mut c.positions {
                let q = [p[0] - 0.5, p[1] - 0.5, p[2] - 0.5];
                let q = [a.cos() * q[0] - a.sin() * q[1], a.sin() * q[0] + a.cos() * q[1], q[2]];
                let q = [q[0], b.cos() * q[1] - b.sin() * q[2], b.sin() * q[1] + b.cos() * q[2]];
                *p = [q[0] + 3.0, q[1] - 1.0, q[2] + 0.5];
            }
            fit_inputs(t, c)
        },
        json!({}),
        Expect::Fit(Some(spot_regions)),
    ));

    out.push(case(
        "icosphere vs sections of homer (auto)",
        || icosphere_vs_sections_of("homer"),
        json!({}),
        Expect::Fit(None),
    ));
    out.push(case(
        "all curves collinear (a straight line)",
        || {
            fit_inputs(
                icosphere(2, 1.0),
                polylines(&[(0..10).map(|k| [k as f64 * 0.2 - 1.0, 0.0, 0.0]).collect()]),
            )
        },
        json!({}),
        Expect::Error(&["curve"]),
    ));

    out.push(case(
        "every curve point identical but two",
        || {
            fit_inputs(
                icosphere(2, 1.0),
                polylines(&[vec![[0.0, 0.0, 1.0]; 10], vec![[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]]),
            )
        },
        json!({}),
        Expect::Error(&["curve"]),
    ));
    out
}
