//! Fit sweep over curve networks that are not plane sections: sparse and oversampled curves,
//! noise, near-duplicate points, crossings without a shared vertex, T-junctions, dangling curves,
//! degenerate polylines, non-planar curves (helix, loxodrome), a torus, an open template with a
//! hole, a quad template, and the same case scaled and moved far from the origin. Every case is
//! built from closed-form curves on a closed-form surface (`fit::testdata`), so the region count
//! is known by hand and the output's distance to the surface is measured against the formula.
//!
//! Prints per case: template / curve vertices, flips, segments as edges, regions found / expected,
//! max curve residual (relative to the curves' bbox diagonal), max distance of the output vertices
//! to the analytic surface (same unit), min angle after smoothing, the report's network notes
//! (welds, merged near-duplicates, inserted crossings, T-junctions) and the time, or the error.
//!
//! Run from the repository root:
//! `CARGO_TARGET_DIR=/work/target-release cargo run --release -p meshwork-core --example sweep_networks [NAME…]`
//! (`SWEEP_FAILED=1` also prints the segments that could not be made edge chains; `SWEEP_OUT=DIR`
//! writes each output and its curves as OBJ to DIR and prints the faces per region.)

use std::f64::consts::{FRAC_PI_2, PI};
use std::time::Instant;

use meshwork_core::fit::testdata::{
    arc, circle, ellipsoid_distance, ellipsoid_sections, helix, jitter, loxodrome, open_cylinder,
    paraboloid_with_hole, polylines,
};
use meshwork_core::fit::{run, FitParams};
use meshwork_core::geometry::{norm, Aabb};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::{icosphere, torus};
use meshwork_core::Progress;

const X: Point3 = [1.0, 0.0, 0.0];
const Y: Point3 = [0.0, 1.0, 0.0];
const Z: Point3 = [0.0, 0.0, 1.0];
const O: Point3 = [0.0, 0.0, 0.0];
const AXES: [f64; 3] = [1.4, 1.15, 0.9];
/// Radius of the target sphere (the template icosphere has radius 1).
const R: f64 = 1.3;

struct Case {
    name: String,
    template: Mesh,
    curves: Mesh,
    regions: usize,
    /// Distance of a point to the surface the curves lie on (before any noise).
    surface: Box<dyn Fn(Point3) -> f64>,
    params: FitParams,
}

fn case(
    name: &str,
    template: Mesh,
    curves: Mesh,
    regions: usize,
    surface: impl Fn(Point3) -> f64 + 'static,
) -> Case {
    Case {
        name: name.into(),
        template,
        curves,
        regions,
        surface: Box::new(surface),
        params: FitParams::default(),
    }
}

fn sphere(p: Point3) -> f64 {
    (norm(p) - R).abs()
}

fn ellipsoid(p: Point3) -> f64 {
    ellipsoid_distance(p, AXES)
}

fn great_circles(n: usize, phases: [f64; 3]) -> Vec<Vec<Point3>> {
    meshwork_core::fit::testdata::great_circles(R, n, phases)
}

fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    let ico3 = icosphere(3, 1.0);
    // Density: 4 points per loop (the octahedron's edges span many template faces) and 8, then
    // several curve points per template face.
    out.push(case("octants-4pt", ico3.clone(), ellipsoid_sections([R; 3], 1), 8, sphere));
    out.push(case("octants-8pt", ico3.clone(), ellipsoid_sections([R; 3], 2), 8, sphere));
    out.push(case("ellipsoid-dense", icosphere(2, 1.0), ellipsoid_sections(AXES, 64), 8, ellipsoid));
    // Noise: every non-axis point moved by up to 1e-3 of the bbox diagonal.
    let mut noisy = ellipsoid_sections(AXES, 16);
    let axis_points: Vec<u32> = (0..noisy.positions.len() as u32)
        .filter(|&i| noisy.positions[i as usize].iter().filter(|c| **c == 0.0).count() == 2)
        .collect();
    let diag = Aabb::of(&noisy.positions).map_or(1.0, |b| b.diagonal());
    jitter(&mut noisy, 1e-3 * diag, 7, &axis_points);
    out.push(case("ellipsoid-noisy", ico3.clone(), noisy, 8, ellipsoid));
    // Two consecutive curve points 2e-5 apart (5e-6 of the diagonal: above the weld tolerance, like
    // the headline case's pair 1e-6 apart on a smaller network).
    let mut dup = ellipsoid_sections(AXES, 16);
    let (a, b) = (dup.curves[0][3], dup.curves[0][4]);
    let (pa, pb) = (dup.positions[a as usize], dup.positions[b as usize]);
    let d = meshwork_core::geometry::sub(pb, pa);
    dup.positions.push(meshwork_core::geometry::add(pa, meshwork_core::geometry::scale(d, 2e-5 / norm(d))));
    let id = (dup.positions.len() - 1) as u32;
    dup.curves[0].insert(4, id);
    out.push(case("near-duplicate", ico3.clone(), dup, 8, ellipsoid));
    // Crossings without a shared vertex.
    out.push(case(
        "crossing-unshared",
        ico3.clone(),
        polylines(&great_circles(32, [0.05, 0.11, 0.07])),
        8,
        sphere,
    ));
    out.push(case(
        "crossing-sparse",
        ico3.clone(),
        polylines(&great_circles(8, [0.2, 0.31, 0.13])),
        8,
        sphere,
    ));
    // T-junction: a half meridian from the equator over the pole back to the equator; its ends are
    // on the sphere, between equator vertices (off the equator's chords by their sag).
    let equator = circle(O, X, Y, R, 32, 0.05);
    let half = arc(O, X, Z, R, 0.0, PI, 16);
    out.push(case("t-junction", ico3.clone(), polylines(&[equator.clone(), half.clone()]), 3, sphere));
    // The same with the ends exactly on the equator's chords.
    let mut on_chord = half.clone();
    for e in [0, on_chord.len() - 1] {
        let p = on_chord[e];
        let best = equator
            .windows(2)
            .map(|w| closest_on_segment(p, w[0], w[1]))
            .min_by(|a, b| {
                meshwork_core::geometry::dist(*a, p).total_cmp(&meshwork_core::geometry::dist(*b, p))
            })
            .unwrap();
        on_chord[e] = best;
    }
    out.push(case("t-junction-exact", ico3.clone(), polylines(&[equator.clone(), on_chord]), 3, sphere));
    // Dangling curves: one starting at an equator vertex and ending inside the north region, one
    // floating in the south: neither splits a region.
    let eq0 = circle(O, X, Y, R, 32, 0.0);
    let up = arc(O, X, Z, R, 0.0, PI / 3.0, 8);
    let zc = -0.6;
    let south = arc([0.0, 0.0, zc], X, Y, (R * R - zc * zc).sqrt(), 0.3, 2.3, 10);
    out.push(case("dangling", ico3.clone(), polylines(&[eq0.clone(), up, south]), 2, sphere));
    // Degenerate polylines next to a good network: a one-point loop, a zero-length segment, a
    // repeated polyline.
    let mut degenerate = great_circles(16, [0.0; 3]);
    let p = [R * 0.6, R * 0.64, R * (1.0f64 - 0.36 - 0.4096).sqrt()];
    degenerate.push(vec![p, p]);
    let mut rep = degenerate[0].clone();
    rep.insert(5, rep[5]);
    degenerate.push(rep);
    degenerate.push(degenerate[1].clone());
    out.push(case("degenerate-polylines", ico3.clone(), polylines(&degenerate), 8, sphere));
    // Non-planar curves: a loxodrome across the equator (crossing not at a vertex), open ends.
    let lox = loxodrome(R, 1.2, 1.5, 41);
    out.push(case("loxodrome", ico3.clone(), polylines(&[circle(O, X, Y, R, 48, 0.03), lox]), 2, sphere));
    // Helix on an open cylinder, crossing two circles at shared vertices, ends on the rims.
    let cyl = |p: Point3| ((p[0] * p[0] + p[1] * p[1]).sqrt() - 1.15).abs();
    let hel = helix(1.15, 0.0, 2.0, 2.0, 120);
    let rings = [circle([0.0, 0.0, 0.5], X, Y, 1.15, 40, 0.0), circle([0.0, 0.0, 1.5], X, Y, 1.15, 40, 0.0)];
    out.push(case(
        "helix-cylinder",
        open_cylinder(32, 12, 1.0, 2.0),
        polylines(&[rings[0].clone(), rings[1].clone(), hel]),
        3,
        cyl,
    ));
    // Torus (genus 1): two tube circles and the outer and inner equators, 4 regions.
    let rt = 0.45;
    let tor = move |p: Point3| (((p[0] * p[0] + p[1] * p[1]).sqrt() - 1.0).hypot(p[2]) - rt).abs();
    let torus_curves = polylines(&[
        circle(X, X, Z, rt, 16, 0.0),
        circle([-1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], Z, rt, 16, 0.0),
        circle(O, X, Y, 1.0 + rt, 48, 0.0),
        circle(O, X, Y, 1.0 - rt, 24, 0.0),
    ]);
    out.push(case("torus", torus(40, 16, 1.0, 0.4, false), torus_curves.clone(), 4, tor));
    out.push(case("torus-quads", torus(40, 16, 1.0, 0.4, true), torus_curves, 4, tor));
    // An open template with a hole: a circle around the hole and a cut from it to the rim.
    let a = 0.3;
    let para = move |p: Point3| {
        let rho2 = p[0] * p[0] + p[1] * p[1];
        (p[2] - a * rho2).abs() / (1.0 + 4.0 * a * a * rho2).sqrt()
    };
    let ring = circle([0.0, 0.0, a * 0.36], X, Y, 0.6, 32, 0.0);
    let cut: Vec<Point3> = (0..=8)
        .map(|i| {
            let r = 0.6 + 0.4 * i as f64 / 8.0;
            [r, 0.0, a * r * r]
        })
        .collect();
    out.push(case("paraboloid-hole", paraboloid_with_hole(24, 0.25, 0.25), polylines(&[ring, cut]), 2, para));
    // Scale and offset: the 8-point octants scaled by 1e-3 and 1e3 and moved by 1e6.
    for (label, s, t) in [("scale-1e-3", 1e-3, 0.0), ("scale-1e3", 1e3, 0.0), ("offset-1e6", 1.0, 1e6)] {
        let map = move |p: Point3| [p[0] * s + t, p[1] * s + t, p[2] * s + t];
        let mut tm = ico3.clone();
        tm.positions.iter_mut().for_each(|p| *p = map(*p));
        let mut cv = ellipsoid_sections([R; 3], 2);
        cv.positions.iter_mut().for_each(|p| *p = map(*p));
        let surf = move |p: Point3| sphere([(p[0] - t) / s, (p[1] - t) / s, (p[2] - t) / s]) * s;
        out.push(case(&format!("octants-8pt-{label}"), tm, cv, 8, surf));
    }
    let _ = FRAC_PI_2;
    out
}

fn closest_on_segment(p: Point3, a: Point3, b: Point3) -> Point3 {
    use meshwork_core::geometry::{add, dot, norm2, scale, sub};
    let ab = sub(b, a);
    let t = (dot(sub(p, a), ab) / norm2(ab)).clamp(0.0, 1.0);
    add(a, scale(ab, t))
}

/// The non-zero counts of the report's `network` object, short.
fn notes(net: &serde_json::Value) -> String {
    let Some(m) = net.as_object() else { return String::new() };
    m.iter()
        .filter(|(k, v)| {
            !matches!(k.as_str(), "input_polylines" | "input_points" | "feature_points")
                && v.as_f64().map_or(v.as_array().is_some_and(|a| !a.is_empty()), |x| x != 0.0)
        })
        .map(|(k, v)| match v.as_f64() {
            Some(x) if x.fract() != 0.0 => format!("{k}={x:.1e}"),
            _ => format!("{k}={v}"),
        })
        .collect::<Vec<_>>()
        .join(" ")
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    let only: Vec<String> = std::env::args().skip(1).collect();
    println!(
        "{:<26} {:>6} {:>6} {:>5} {:>7} {:>7} {:>9} {:>9} {:>7} {:>7}  notes",
        "case", "tmplV", "curveV", "flips", "edges%", "regions", "residual", "surf dev", "minang", "time s"
    );
    for c in
        cases().into_iter().filter(|c| only.is_empty() || only.iter().any(|o| c.name.contains(o.as_str())))
    {
        let diag = Aabb::of(&c.curves.positions).map_or(1.0, |b| b.diagonal());
        let t = Instant::now();
        let got = run(vec![c.template.clone(), c.curves.clone()], &c.params, &Progress::new());
        let secs = t.elapsed().as_secs_f64();
        match got {
            Err(e) => println!("{:<26} ERROR {e}", c.name),
            Ok(out) => {
                let r = &out.report;
                if std::env::var("SWEEP_FAILED").is_ok() {
                    eprintln!("{}: {}", c.name, r["retriangulation"]["failed"]);
                }
                if let Ok(dir) = std::env::var("SWEEP_OUT") {
                    // The output (one group per region) and the curves, to look at.
                    let obj = meshwork_core::io::write(&out.meshes[0], meshwork_core::io::Format::Obj);
                    let _ = std::fs::write(format!("{dir}/{}.obj", c.name), obj.unwrap_or_default());
                    let curves = meshwork_core::io::write(&c.curves, meshwork_core::io::Format::Obj);
                    let _ =
                        std::fs::write(format!("{dir}/{}-curves.obj", c.name), curves.unwrap_or_default());
                    let sizes: Vec<usize> = (0..out.meshes[0].groups.len())
                        .map(|g| {
                            (0..out.meshes[0].faces.len())
                                .filter(|&f| out.meshes[0].faces.group(f) as usize == g)
                                .count()
                        })
                        .collect();
                    eprintln!(
                        "{}: faces per region {sizes:?}, alignment {}",
                        c.name, r["alignment"]["method"]
                    );
                }
                let dev = out.meshes[0].positions.iter().map(|&p| (c.surface)(p)).fold(0.0, f64::max) / diag;
                let net = &r["network"];
                println!(
                    "{:<26} {:>6} {:>6} {:>8} {:>7.2} {:>3}/{:<3} {:>9.2e} {:>9.2e} {:>7.2} {:>7.2}  {}",
                    c.name,
                    c.template.positions.len(),
                    r["curve_vertices"],
                    format!("{}({})", r["flipped_faces"], r["flipped_faces_against_fine_surface"]),
                    100.0 * r["segments_as_edges"].as_f64().unwrap_or(f64::NAN),
                    r["regions"],
                    c.regions,
                    r["curve_residual_max"].as_f64().unwrap_or(f64::NAN) / diag,
                    dev,
                    r["min_angle_deg_after_smoothing"].as_f64().unwrap_or(f64::NAN),
                    secs,
                    notes(net),
                );
            }
        }
    }
}
