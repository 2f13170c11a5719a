//! Fit sweep over inputs the other sweeps never feed: real files read as they are (quad and n-gon
//! templates, templates in pieces, with seams, several holes or several components, duplicate
//! vertices and zero-area faces), a very coarse template with dense curves, a template of another
//! shape than the curves' source, curves through every reader (glTF LINES / LINE_STRIP /
//! LINE_LOOP, OBJ `l` with negative indices, JSON), gaps just over the weld tolerance, partial
//! networks, one closed loop, a curve far away, NaN / Inf coordinates, empty files and bad pairs.
//!
//! Every case either expects an error (and says which words the message must have) or a fit
//! whose invariants are checked here, independently of the report: every output vertex finite,
//! every face index in range, no face of zero area, OBJ groups = regions, the region count against
//! a count made by hand from the geometry (`–` when there is none), every matched curve vertex on
//! the output (≤ 1e-9 × bbox diagonal), the output not smaller than the template (no silent
//! drop). A panic is caught and printed as PANIC.
//!
//! Run from the repository root:
//! `CARGO_TARGET_DIR=/work/tr-fit-unseen cargo run --release -p meshwork-core --example sweep_unseen [NAME…]`
//! (NAME: any part of a case name; `SWEEP_DUMP=DIR` writes the inputs, the output and the report there; `SWEEP_DETAIL=1` also prints the flip counts by stage, the
//! untangling, clean-up and re-triangulation reports; `SWEEP_PARAMS='{"smooth": false}'` merges
//! parameters into every fitting case; the round icosphere fitted to a flattened ellipsoid's
//! sections, which took minutes, now ends in seconds with the face guard's error.)
//!
//! The cases live in one file per family (`templates`, `shapes`, `readers`, `networks`, `pairs`, `layouts`, `spacings`);
//! `support` has the `Case` type and the shared inputs, `check` the invariants. A new case goes
//! into the family of what it varies (a new file for a new family, listed in `cases()`).

mod check;
mod coarse;
mod densities;
mod features;
mod formats;
mod genus;
mod layouts;
mod networks;
mod pair_counts;
mod pairs;
mod readers;
mod shapes;
mod sources;
mod spacings;
mod support;
mod templates;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Instant;

use meshwork_core::job::{self, JobKind};
use meshwork_core::Progress;

use check::invariants;
use support::{Case, Expect};

/// Every case, family by family.
fn cases() -> Vec<Case> {
    [
        templates::templates(),
        shapes::shapes(),
        coarse::coarse(),
        readers::readers(),
        networks::networks(),
        pairs::pairs(),
        layouts::layouts(),
        spacings::spacings(),
        formats::formats(),
        densities::densities(),
        pair_counts::pair_counts(),
        sources::sources(),
        genus::genus(),
        features::features(),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// One line naming what a case feeds and expects, without fitting: its name, expectation,
/// parameters and a fingerprint of its inputs (`SWEEP_LIST=1`; two listings are equal when the
/// cases are, which is how a rewrite of the case builders is checked).
fn listing(c: &Case) -> String {
    use std::hash::{Hash, Hasher};
    let inputs = match (c.inputs)() {
        Ok(meshes) => {
            let mut h = std::collections::hash_map::DefaultHasher::new();
            format!("{meshes:?}").hash(&mut h);
            let counts: Vec<_> =
                meshes.iter().map(|m| (m.positions.len(), m.faces.len(), m.curves.len())).collect();
            format!("{:016x} {counts:?}", h.finish())
        }
        Err(e) => format!("error {e}"),
    };
    format!("{} | {:?} | {} | {inputs}", c.name, c.expect, c.params)
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    let only: Vec<String> = std::env::args().skip(1).collect();
    let list = std::env::var("SWEEP_LIST").is_ok();
    for c in cases() {
        if !only.is_empty() && !only.iter().any(|o| c.name.contains(o.as_str())) {
            continue;
        }
        if list {
            println!("{}", listing(&c));
            continue;
        }
        let t = Instant::now();
        let result = catch_unwind(AssertUnwindSafe(|| {
            let inputs = (c.inputs)()?;
            // SWEEP_DUMP=DIR: the row's inputs as OBJ, to run again with the CLI.
            if let Ok(dir) = std::env::var("SWEEP_DUMP") {
                use meshwork_core::io::{write, Format};
                let _ = std::fs::create_dir_all(&dir);
                for (name, m) in ["template", "curves"].iter().zip(&inputs) {
                    if let Ok(bytes) = write(m, Format::Obj) {
                        let _ = std::fs::write(format!("{dir}/{name}.obj"), bytes);
                    }
                }
            }
            let keep = (inputs[0].clone(), inputs[1].clone());
            let mut params = c.params.clone();
            if let Ok(extra) = std::env::var("SWEEP_PARAMS") {
                if let (Some(m), Ok(serde_json::Value::Object(e))) =
                    (params.as_object_mut(), serde_json::from_str::<serde_json::Value>(&extra))
                {
                    m.extend(e);
                }
            }
            let out = job::run(JobKind::Fit, inputs, params, &Progress::new());
            // SWEEP_DUMP also gets the output and its report (the CLI's reading of the dumped
            // inputs need not fit the same, bit for bit).
            if let (Ok(dir), Ok(o)) = (std::env::var("SWEEP_DUMP"), &out) {
                use meshwork_core::io::{write, Format};
                if let Ok(bytes) = write(&o.meshes[0], Format::Obj) {
                    let _ = std::fs::write(format!("{dir}/out.obj"), bytes);
                }
                let _ = std::fs::write(format!("{dir}/report.json"), o.report.to_string());
            }
            out.map(|o| (keep, o))
        }));
        let secs = t.elapsed().as_secs_f64();
        let line = match (&c.expect, result) {
            (_, Err(p)) => {
                let msg = p
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| p.downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                format!("PANIC {msg}")
            }
            (Expect::Error(words), Ok(Err(e))) => {
                let text = format!("{e} {e:?}");
                let missing: Vec<_> = words.iter().filter(|w| !text.contains(*w)).collect();
                if missing.is_empty() {
                    format!("ok (error) {e}")
                } else {
                    format!("BAD ERROR (missing {missing:?}) {e}")
                }
            }
            (Expect::Error(_), Ok(Ok((_, o)))) => format!(
                "BAD: expected an error, got a fit: regions {} edges {}",
                o.report["regions"], o.report["segments_as_edges"]
            ),
            (Expect::Fit(_), Ok(Err(e))) => format!("ERROR {e}"),
            (Expect::Fit(regions), Ok(Ok(((template, curves), o)))) => {
                let mut bad = invariants(&template, &curves, &o);
                let r = &o.report;
                if let Some(want) = regions {
                    if r["regions"].as_u64() != Some(*want as u64) {
                        bad.push(format!("regions {} != {want}", r["regions"]));
                    }
                }
                if std::env::var("SWEEP_DETAIL").is_ok() {
                    let mut alignment = r["alignment"].clone();
                    alignment["candidates"] = serde_json::Value::Null;
                    eprintln!("  alignment {alignment}; fine {}; stages {}", r["fine"], r["stages"]);
                    eprintln!(
                        "  refine {}; flips after fine {} / before smoothing {} / final {}; untangle {}; cleanup {}; retriangulation {}",
                        r["refine"],
                        r["flipped_faces_after_fine"],
                        r["flipped_faces_before_smoothing"],
                        r["flipped_faces"],
                        r["untangle"],
                        r["cleanup"],
                        r["retriangulation"]
                    );
                    eprintln!("  stages {}; fine {}", r["stages"], r["fine"]);
                    eprintln!("  zero-area faces {}", r["zero_area_faces"]);
                    eprintln!("  turned_faces {}", r["turned_faces"]);
                    // Truths where they apply: the template itself (cases "vs own sections" with
                    // alignment none), the direction from the curves' centroid (star-shaped truths:
                    // spheres, ellipsoids about their centre).
                    let m = &o.meshes[0];
                    let n = curves.positions.len().max(1) as f64;
                    let centre = [0, 1, 2].map(|k| curves.positions.iter().map(|p| p[k]).sum::<f64>() / n);
                    let radial = meshwork_core::fit::testdata::faces_against(m, |c| {
                        [c[0] - centre[0], c[1] - centre[1], c[2] - centre[2]]
                    });
                    // Cross-template rows: the shared mesh the curves were cut from.
                    let source = c
                        .name
                        .split_once("sections of ")
                        .map(|(_, r)| r.split(' ').next().unwrap_or(""))
                        .or_else(|| {
                            c.name.split_once("'s sections").map(|(l, _)| l.rsplit(' ').next().unwrap_or(""))
                        })
                        .or_else(|| c.name.strip_prefix("coarse ").and_then(|r| r.split(' ').next()));
                    if let Some(name) = source.filter(|n| !support::shared(n).is_empty()) {
                        let (_, raw, _) = support::sections_of(name);
                        eprintln!(
                            "  faces against the source surface ({name}) {}",
                            meshwork_core::fit::testdata::TruthSurface::new(&raw).faces_against(m)
                        );
                    }
                    eprintln!(
                        "  faces against the template surface {}; against the radial direction {}",
                        meshwork_core::fit::testdata::TruthSurface::new(&template).faces_against(m),
                        radial.len()
                    );
                }
                let off = r["retriangulation"]["off_surface_segments"].as_u64().unwrap_or(0);
                let status = match (bad.is_empty(), r["retriangulation"]["failed_pieces"].as_u64()) {
                    (true, _) if off > 0 => format!("ok ({off} segments over a hole)"),
                    (true, Some(n)) if n > 0 => format!("ok ({n} segments between unjoined pieces)"),
                    (true, _) => "ok".to_string(),
                    _ => format!("BAD {}", bad.join("; ")),
                };
                format!(
                    "{status} | regions {} faces {}→{} edges {} flips {} (fine surface {}, inverted {}) resid {:.1e} angle {:.1}/{:.1} net {} not-edges {}",
                    r["regions"],
                    r["template_triangles"],
                    r["output_faces"],
                    r["segments_as_edges"],
                    r["flipped_faces"],
                    r["flipped_faces_against_fine_surface"],
                    r["faces_inverted_by_maps"],
                    r["curve_residual_max_relative"].as_f64().unwrap_or(f64::NAN),
                    r["min_angle_deg_before_smoothing"].as_f64().unwrap_or(f64::NAN),
                    r["min_angle_deg_after_smoothing"].as_f64().unwrap_or(f64::NAN),
                    serde_json::json!({
                        "welded": r["network"]["welded_points"], "tj": r["network"]["t_junctions"],
                        "ends": r["network"]["ends_merged"], "x": r["network"]["crossings_inserted"],
                        "dangling": r["network"]["dangling_ends"]
                    }),
                    r["segments_not_edges"]
                )
            }
        };
        println!("{:<48} {:>6.2}s  {line}", c.name, secs);
    }
}
