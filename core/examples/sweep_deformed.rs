//! Sweep (by hand, not in CI) of the fit on a realistic use: each shared mesh, repaired and in the
//! unit box, fitted to its own plane sections (the sweep's planes) carried by a smooth non-rigid
//! deformation: none ("ident"), `testdata::bend`, or `testdata::twist` (0.7 rad per unit length with an
//! anisotropic scale, "twist"); the deformation keeps the topology, so the truth is the
//! deformed template and its section regions are the template's. Alignment automatic, or 12
//! user pairs at section crossings (`testdata::crossing_pairs`, as `bench_fit`). Prints the
//! report's flips, edges and regions and, counted here against the truth: `against`, output faces
//! whose normal opposes the closest truth face's (meaningful only where `dev` is small: a part
//! displaced by more than its thickness meets the other side), and `dev`, the largest distance
//! of an output vertex to the truth surface. "ok" is the job's own bar: 0 flipped faces and every
//! segment an edge chain (`against` is shown, not judged: a few faces at creases or thin parts
//! are against the truth even on the undeformed rows, where the fit is all but exact).
//!
//! `SWEEP_SET=heldout` runs the held-out family instead (`testdata::heldout`): other maps (ident,
//! taper, wave, bulge) and oblique section planes, which no repair was tuned on. Judge a change on
//! both sets: the first one selected `main`'s repairs over sessions 12–16.
//!
//! `cargo run --release -p meshwork-core --example sweep_deformed [NAME-SUBSTRING]`
use std::time::Instant;

use meshwork_core::fit::testdata::{
    bend, bulge, crossing_pairs, oblique_planes, plane_sections, section_regions, sweep_planes, taper,
    to_unit_box, twist, wave, TruthSurface,
};
use meshwork_core::geometry::{dot, triangle_cross};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::job::{self, JobKind};
use meshwork_core::mesh::Point3;
use meshwork_core::repair::{self, RepairParams};
use meshwork_core::Progress;

/// A smooth map carrying the sections (and the truth) from the template.
type Deform = fn(Point3) -> Point3;

fn main() {
    let filter = std::env::args().nth(1).unwrap_or_default();
    let names = [
        "spot",
        "cow",
        "homer",
        "fandisk",
        "rocker-arm",
        "teapot",
        "suzanne",
        "beetle",
        "alligator",
        "woody",
        "stanford-bunny",
    ];
    let heldout = std::env::var("SWEEP_SET").is_ok_and(|s| s == "heldout");
    let deforms: Vec<(&str, Deform)> = if heldout {
        vec![("idented", |p| p), ("tapered", taper), ("waved", wave), ("bulged", bulge)]
    } else {
        vec![("idented", |p| p), ("bended", |p| bend(p, 1.0)), ("twisted", twist)]
    };
    for name in names {
        let Ok(bytes) = std::fs::read(format!("../shared/meshes/{name}.obj")) else { continue };
        let raw = read(&bytes, &ReadOptions { name_hint: Some("x.obj".into()), ..Default::default() })
            .expect("read")
            .mesh;
        let params = RepairParams { fill_holes: false, ..Default::default() };
        let mut t = repair::run(raw, &params, &Progress::new()).expect("repair").meshes.remove(0);
        to_unit_box(&mut t);
        for &(dname, d) in &deforms {
            for align in ["auto", "pairs"] {
                let label = format!("{name} vs {dname} self ({align})");
                if !label.contains(&filter) {
                    continue;
                }
                let mut truth = t.clone();
                truth.positions = t.positions.iter().map(|&p| d(p)).collect();
                // Sections of the template carried by the deformation (curved, not planar), as
                // bench_fit builds its case: the regions are the template's.
                let planes = if heldout { oblique_planes(&t.positions) } else { sweep_planes(&t) };
                let sections = plane_sections(&t, &planes);
                let want = section_regions(&t, &planes);
                let mut curves = sections.clone();
                curves.positions = sections.positions.iter().map(|&p| d(p)).collect();
                // Flat meshes (alligator, woody) have coplanar sections: the in-plane polynomial.
                let p = if align == "auto" {
                    serde_json::json!({ "coplanar_centres": "augment" })
                } else {
                    serde_json::json!({ "coplanar_centres": "augment", "pairs": crossing_pairs(&sections, &t, 12, d) })
                };
                let clock = Instant::now();
                let curves_in = curves.clone();
                let out = job::run(JobKind::Fit, vec![t.clone(), curves], p, &Progress::new());
                let secs = clock.elapsed().as_secs_f64();
                match out {
                    Err(e) => println!("{label:<40} {secs:6.2}s ERROR {e}"),
                    Ok(o) => {
                        let m = &o.meshes[0];
                        let r = &o.report;
                        // Against the truth: the normal of the closest truth face at each output
                        // face's centroid; distance: each output vertex to the truth surface.
                        let surface = TruthSurface::new(&truth);
                        let against = surface.faces_against(m);
                        let dev = surface.max_distance(m);
                        if std::env::var("SWEEP_DETAIL").is_ok() {
                            eprintln!(
                                "  alignment {}\n  untangle {}\n  cleanup {}\n  retriangulation {}\n  folds {}\n  stages {}\n  turned_faces {}",
                                r["alignment"], r["untangle"], r["cleanup"], r["retriangulation"], r["folds"], r["stages"], r["turned_faces"]
                            );
                        }
                        if std::env::var("SWEEP_ORDER").is_ok() {
                            let i = &r["fine"]["insertion"];
                            println!(
                                "  order {label}: closest {} walked {} stretched {} before the approach {} stretched {}",
                                i["out_of_order_closest"], i["out_of_order"], i["stretched"],
                                r["fine"]["approach"]["out_of_order_before"],
                                r["fine"]["approach"]["stretched_before"]
                            );
                        }
                        if let Ok(dir) = std::env::var("SWEEP_DUMP") {
                            dump(&dir, &t, &curves_in, m, r);
                        }
                        if std::env::var("SWEEP_FOLDS").is_ok() {
                            print_folds(m);
                        }
                        let ok = r["flipped_faces"] == 0 && r["segments_as_edges"] == 1.0;
                        println!(
                            "{label:<40} {secs:6.2}s {} flips {} (fine {} pre-smooth {} fine surface {} inverted {}) against {against} edges {:.5} regions {}/{want} folded {} dev {dev:.2e} ambiguous {} pieces {} holes {} separated {} realisable {:.5}",
                            if ok { "ok " } else { "BAD" },
                            r["flipped_faces"],
                            r["flipped_faces_after_fine"],
                            r["flipped_faces_before_smoothing"],
                            r["flipped_faces_against_fine_surface"],
                            r["faces_inverted_by_maps"],
                            r["segments_as_edges"].as_f64().unwrap_or(0.0),
                            r["regions"],
                            r["folded_edges"],
                            r["alignment"]["ambiguous"],
                            r["retriangulation"]["failed_pieces"],
                            r["retriangulation"]["off_surface_segments"],
                            r["segments_not_edges"]["separated"],
                            r["segments_as_edges_realisable"].as_f64().unwrap_or(0.0),
                        );
                    }
                }
            }
        }
    }
}

/// Diagnostic (`SWEEP_FOLDS=1`): every pair of faces on an edge whose normals are over 150°
/// apart, with their corners, which of them are on output curve chains, and the positions.
fn print_folds(m: &meshwork_core::mesh::Mesh) {
    use std::collections::HashMap;
    let tris = m.faces.triangles();
    let on_curve: std::collections::HashSet<u32> = m.curves.iter().flatten().copied().collect();
    let mut by_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let n = |f: usize| {
        let t = tris[f];
        triangle_cross(m.positions[t[0] as usize], m.positions[t[1] as usize], m.positions[t[2] as usize])
    };
    for (e, fs) in &by_edge {
        if fs.len() != 2 {
            continue;
        }
        let (a, b) = (n(fs[0]), n(fs[1]));
        let c = dot(a, b) / (dot(a, a) * dot(b, b)).sqrt();
        if c < (150f64).to_radians().cos() {
            let mark = |v: u32| format!("{v}{}", if on_curve.contains(&v) { "*" } else { "" });
            eprintln!(
                "  fold edge {e:?} cos {c:.6} faces {:?} {:?} / {:?} {:?}",
                fs[0],
                tris[fs[0]].map(mark),
                fs[1],
                tris[fs[1]].map(mark)
            );
            for v in tris[fs[0]].iter().chain(&tris[fs[1]]) {
                eprintln!("    v{v} {:?}", m.positions[*v as usize]);
            }
        }
    }
}

/// `SWEEP_DUMP=DIR`: the case's template, curves and output as OBJ and the report as JSON, for a
/// look at one row by hand (name filter first).
fn dump(
    dir: &str,
    template: &meshwork_core::mesh::Mesh,
    curves: &meshwork_core::mesh::Mesh,
    out: &meshwork_core::mesh::Mesh,
    report: &serde_json::Value,
) {
    use meshwork_core::io::{write, Format};
    std::fs::create_dir_all(dir).expect("dump dir");
    for (name, m) in [("template", template), ("curves", curves), ("out", out)] {
        std::fs::write(format!("{dir}/{name}.obj"), write(m, Format::Obj).expect("write")).expect("dump");
    }
    std::fs::write(format!("{dir}/report.json"), serde_json::to_string_pretty(report).expect("json"))
        .expect("dump");
}
