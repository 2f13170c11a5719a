//! Curve networks nobody drew for us: gaps just over the weld tolerance, partial networks, one
//! closed loop, a curve far away, curves drawn twice or retracing themselves, hand-drawn curves off
//! the surface, a long chord among short segments, a figure-8 crossing itself.

use std::f64::consts::PI;

use meshwork_core::fit::testdata::{circle, polylines, quarter_arcs_with_gap, tilted_wave};
use meshwork_core::geometry::norm;
use meshwork_core::mesh::Point3;

use crate::support::{bumpy, case, lines_of, on_icosphere, sphere_sections, Case, Expect, AXES, O, X, Y, Z};

pub fn networks() -> Vec<Case> {
    use serde_json::json;
    let none = || json!({"alignment": "none"});
    let gc = |n: usize, ph: [f64; 3]| meshwork_core::fit::testdata::great_circles(1.0, n, ph);
    let mut out = Vec::new();
    out.push(case(
        "JSON polylines with gaps 3× join tolerance",
        || {
            let c = quarter_arcs_with_gap(AXES, 3e-6 * 2.0 * (AXES[0].powi(2) + AXES[1].powi(2)).sqrt());
            on_icosphere(c)
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "gaps 1% of diagonal (ends near ends)",
        || on_icosphere(quarter_arcs_with_gap(AXES, 0.035)),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "curves 8% off the surface + partial net",
        || {
            // Upper half only: the equator and two half meridians → 4 + 1 regions.
            let mut lines = vec![circle(O, X, Y, 1.08, 48, 0.0)];
            lines.push(meshwork_core::fit::testdata::arc(O, X, Z, 1.08, 0.0, PI, 24));
            lines.push(meshwork_core::fit::testdata::arc(O, Y, Z, 1.08, 0.0, PI, 24));
            on_icosphere(polylines(&lines))
        },
        json!({}),
        Expect::Fit(Some(5)),
    ));
    out.push(case(
        "single closed loop (planar)",
        || on_icosphere(polylines(&[circle(O, X, Y, 1.0, 48, 0.1)])),
        none(),
        Expect::Error(&["plane"]),
    ));
    out.push(case(
        "single closed loop (planar, augment)",
        || on_icosphere(polylines(&[circle(O, X, Y, 1.0, 48, 0.1)])),
        json!({"alignment": "none", "coplanar_centres": "augment"}),
        Expect::Fit(Some(2)),
    ));
    out.push(case(
        "single closed loop, non-planar (tilted wave)",
        || {
            let pts = tilted_wave(60, true);
            on_icosphere(polylines(&[pts]))
        },
        none(),
        Expect::Fit(Some(2)),
    ));
    out.push(case(
        "a fourth curve 10 diagonals away",
        || {
            let mut lines = lines_of(&sphere_sections(6));
            lines.push(circle([30.0, 0.0, 0.0], X, Y, 0.5, 12, 0.0));
            on_icosphere(polylines(&lines))
        },
        json!({}),
        Expect::Error(&["curve 3"]),
    ));
    out.push(case(
        "equator drawn twice (other sampling)",
        move || {
            let mut l = gc(48, [0.0; 3]);
            l.push(circle(O, X, Y, 1.0, 37, 0.03));
            on_icosphere(polylines(&l))
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "every polyline also reversed",
        || {
            let mut l = lines_of(&sphere_sections(6));
            let rev: Vec<Vec<Point3>> = l.iter().map(|x| x.iter().rev().copied().collect()).collect();
            l.extend(rev);
            on_icosphere(polylines(&l))
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "a polyline retracing itself",
        || {
            let mut l = lines_of(&sphere_sections(6));
            let back: Vec<Point3> = l[0].iter().rev().take(l[0].len() / 2).copied().collect();
            l[0].extend(back.into_iter().skip(1));
            on_icosphere(polylines(&l))
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "hand-drawn: curves on a 2% bumpy sphere",
        move || {
            let l: Vec<Vec<Point3>> =
                gc(40, [0.0; 3]).into_iter().map(|c| c.into_iter().map(bumpy).collect()).collect();
            on_icosphere(polylines(&l))
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "hand-drawn: each curve its own 1.5% wobble",
        move || {
            let l: Vec<Vec<Point3>> = gc(40, [0.02, 0.05, 0.09])
                .into_iter()
                .enumerate()
                .map(|(i, c)| {
                    let n = c.len();
                    c.into_iter()
                        .enumerate()
                        .map(|(k, p)| {
                            let t = std::f64::consts::TAU * k as f64 / (n - 1) as f64;
                            let r = 1.0 + 0.015 * (3.0 * t + i as f64).sin();
                            [p[0] * r, p[1] * r, p[2] * r]
                        })
                        .collect()
                })
                .collect();
            on_icosphere(polylines(&l))
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "one 90-degree chord among short segments",
        || {
            let mut l = lines_of(&sphere_sections(12));
            // The first quarter of the first polyline (between two junctions) as one segment.
            let q = 12;
            let first = l[0][0];
            l[0].drain(1..q);
            assert!(meshwork_core::geometry::dist(first, l[0][0]) == 0.0);
            on_icosphere(polylines(&l))
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "figure-8 crossing itself (no shared vertex)",
        || {
            let n = 64;
            let l: Vec<Point3> = (0..=n)
                .map(|k| {
                    let t = std::f64::consts::TAU * (k as f64 + 0.37) / n as f64;
                    let d = [t.sin(), t.sin() * t.cos(), 0.7];
                    let r = norm(d);
                    [d[0] / r, d[1] / r, d[2] / r]
                })
                .collect();
            on_icosphere(polylines(&[l]))
        },
        json!({}),
        Expect::Fit(Some(3)),
    ));
    out
}
