//! Fit benchmark: a real template (homer.obj split 0–2 times: 6k, 24k, 96k vertices) fitted to
//! plane sections of a known bend of itself, with 12 user pairs. Prints the stage timings and
//! quality of each run, the growth with template size and with curve-vertex count, and a
//! same-run peer comparison of the RBF stage against SciPy's `RBFInterpolator` (same kernel φ = r,
//! degree-1 polynomial), when the peers venv is installed.
//!
//! Run from the repository root (reads `../shared/meshes/homer.obj`) with a private release target dir
//! (see docs/benchmarks.md → Fit: the shared one mixes worktrees' builds of this example):
//! `CARGO_TARGET_DIR=/tmp/fit-rel cargo run --release -p meshwork-core --example bench_fit`

use std::time::Instant;

use meshwork_core::fit::rbf::{Kernel, Rbf};
use meshwork_core::fit::testdata::{bend, crossing_pairs, plane_sections, thin_network};
use meshwork_core::fit::{run, FitParams};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::subdivide_midpoint;
use meshwork_core::Progress;

fn planes(extra: bool) -> Vec<(Point3, f64)> {
    let mut ys = vec![0.3013, 0.4517, 0.6021, 0.7519, 0.9011];
    if extra {
        ys.extend([0.3761, 0.5263, 0.6773, 0.8261]);
    }
    let mut p: Vec<(Point3, f64)> = ys.iter().map(|&y| ([0.0, 1.0, 0.0], y)).collect();
    p.push(([1.0, 0.0, 0.0], 0.4987));
    p.push(([0.0, 0.0, 1.0], 0.4919));
    p
}

struct Case {
    template: Mesh,
    curves: Mesh,
    params: FitParams,
}

/// Output faces whose normal opposes the truth (the bent template): a face whose corners are all
/// template vertices is compared with the same triangle on the bent template, any other with the
/// truth face closest to its centroid (among the faces around the nearest truth vertex's
/// neighbours). Independent of the job's own `flipped_faces` (which compares with its fine-stage
/// surface). Applied to the truth itself it counts 0 (`--inherent`).
fn truth_flips(c: &Case, out: &Mesh, report: &serde_json::Value) -> usize {
    use meshwork_core::fit::kdtree::KdTree;
    use meshwork_core::geometry::{dist, dot, triangle_cross};
    use meshwork_core::spatial::closest_on_triangle;
    let truth: Vec<Point3> = c.template.positions.iter().map(|&p| bend(p, 1.0)).collect();
    let tris = meshwork_core::shapes::fan_triangles(&c.template.faces);
    let mut vf: Vec<Vec<u32>> = vec![Vec::new(); truth.len()];
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            vf[v as usize].push(f as u32);
        }
    }
    let tree = KdTree::new(&truth);
    let corners = |f: u32| tris[f as usize].map(|v| truth[v as usize]);
    let debug = std::env::var("FIT_DEBUG").is_ok();
    // The output drops the vertices the clean-up removed and renumbers the rest in order: the
    // fit's own vertex id of each output vertex (template vertices are the first ones).
    let mut removed: Vec<u64> = report["cleanup"]["removed_vertices"]
        .as_array()
        .map(|a| a.iter().filter_map(|v| v.as_u64()).collect())
        .unwrap_or_default();
    removed.sort_unstable();
    let mut fit_id = Vec::with_capacity(out.positions.len());
    let (mut id, mut k) = (0u64, 0usize);
    while fit_id.len() < out.positions.len() {
        if k < removed.len() && removed[k] == id {
            k += 1;
        } else {
            fit_id.push(id as usize);
        }
        id += 1;
    }
    let template_vertex = |v: u32| Some(fit_id[v as usize]).filter(|&i| i < truth.len());
    out.faces
        .iter()
        .filter(|f| {
            let p = |i: usize| out.positions[f[i] as usize];
            let c = [0, 1, 2].map(|k| (p(0)[k] + p(1)[k] + p(2)[k]) / 3.0);
            let (v, _) = tree.nearest(c).unwrap();
            let mut best = (f64::INFINITY, 0u32);
            for &g in &vf[v as usize] {
                for &w in &tris[g as usize] {
                    for &h in &vf[w as usize] {
                        let d = dist(c, closest_on_triangle(c, &corners(h)));
                        if d < best.0 {
                            best = (d, h);
                        }
                    }
                }
            }
            let n = triangle_cross(p(0), p(1), p(2));
            // A face of template vertices has its own truth: the same corners on the bent
            // template (the closest truth face can be on the other side of a thin part).
            let tv: Vec<usize> = f.iter().filter_map(|&v| template_vertex(v)).collect();
            let tn = if tv.len() == 3 {
                triangle_cross(truth[tv[0]], truth[tv[1]], truth[tv[2]])
            } else {
                let q = corners(best.1);
                triangle_cross(q[0], q[1], q[2])
            };
            let bad = dot(n, tn) < 0.0;
            if bad && debug {
                eprintln!("truth flip {f:?} dist {:.1e}", best.0);
            }
            bad
        })
        .count()
}

fn case(homer: &Mesh, split: u32, thin: usize, extra_planes: bool, smooth: bool) -> Case {
    let sections = thin_network(&plane_sections(homer, &planes(extra_planes)), thin);
    let template = subdivide_midpoint(homer, split);
    let pairs = crossing_pairs(&sections, &template, 12, |p| bend(p, 1.0));
    let mut curves = sections;
    for p in curves.positions.iter_mut() {
        *p = bend(*p, 1.0);
    }
    // `--levels N` overrides the approach levels (to compare with the one-step fit: 0).
    let args: Vec<String> = std::env::args().collect();
    let approach_levels = args
        .iter()
        .position(|a| a == "--levels")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(FitParams::default().approach_levels);
    Case { template, curves, params: FitParams { pairs, smooth, approach_levels, ..Default::default() } }
}

/// Best of `reps` runs; returns the report of the best, with `truth_flipped_faces` added.
fn time_fit(c: &Case, reps: usize) -> (f64, serde_json::Value) {
    let mut best = (f64::INFINITY, serde_json::Value::Null);
    for _ in 0..reps {
        let t = Instant::now();
        let mut out =
            run(vec![c.template.clone(), c.curves.clone()], &c.params, &Progress::new()).expect("fit");
        let s = t.elapsed().as_secs_f64();
        if s < best.0 {
            out.report["truth_flipped_faces"] = truth_flips(c, &out.meshes[0], &out.report).into();
            best = (s, out.report);
        }
    }
    best
}

fn line(label: &str, s: f64, r: &serde_json::Value) {
    let st = &r["stages"];
    println!(
        "{label:<34} {:>7} tmpl V {:>5} curve V {:>7.3} s | curves {:>6.1} coarse {:>6.1} fine {:>6.1} retri {:>6.1} part {:>5.1} smooth {:>6.1} ms | edges {:.4} flipped {} (truth {}) regions {} minangle {:.1}→{:.1}",
        r["template_vertices"],
        r["curve_vertices"],
        s,
        st["curves"].as_f64().unwrap_or(0.0),
        st["coarse"].as_f64().unwrap_or(0.0),
        st["fine"].as_f64().unwrap_or(0.0),
        st["retriangulate"].as_f64().unwrap_or(0.0),
        st["partition"].as_f64().unwrap_or(0.0),
        st["smooth"].as_f64().unwrap_or(0.0),
        r["segments_as_edges"].as_f64().unwrap_or(0.0),
        r["flipped_faces"],
        r["truth_flipped_faces"],
        r["regions"],
        r["min_angle_deg_before_smoothing"].as_f64().unwrap_or(0.0),
        r["min_angle_deg_after_smoothing"].as_f64().unwrap_or(0.0),
    );
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    let bytes = std::fs::read("../shared/meshes/homer.obj").expect("run from the repository root");
    let homer = read(&bytes, &ReadOptions::default()).expect("homer").mesh;

    if std::env::args().any(|a| a == "--inherent") {
        // The truth measure applied to the truth itself: faces of the bent template that oppose
        // the summed normal at their nearest vertex (creases and pleats of the model).
        for split in [1, 2] {
            let c = case(&homer, split, 2, false, false);
            let mut exact = c.template.clone();
            for p in exact.positions.iter_mut() {
                *p = bend(*p, 1.0);
            }
            println!(
                "homer split {split}: {} of {} truth faces oppose the truth measure",
                truth_flips(&c, &exact, &serde_json::Value::Null),
                exact.face_count()
            );
        }
        return;
    }
    if std::env::args().any(|a| a == "--real") {
        // The case of tests/fit_real.rs (6k homer split once, every 2nd section point, 7 planes).
        println!("== fit_real case: 24k-vertex template, 7 planes, every 2nd point ==");
        for smooth in [false, true] {
            let c = case(&homer, 1, 2, false, smooth);
            let (s, r) = time_fit(&c, 1);
            line(if smooth { "fit_real, smoothing" } else { "fit_real, no smoothing" }, s, &r);
            if std::env::args().any(|a| a == "--report") {
                println!("{}", serde_json::to_string_pretty(&r).unwrap());
            }
        }
        return;
    }
    println!(
        "== headline: 96k-vertex template, full section network ({} regions expected, counted by \
         testdata::section_regions) ==",
        meshwork_core::fit::testdata::section_regions(&homer, &planes(true))
    );
    for smooth in [false, true] {
        let c = case(&homer, 2, 1, true, smooth);
        let (s, r) = time_fit(&c, 3);
        line(if smooth { "96k, all points, smoothing" } else { "96k, all points, no smoothing" }, s, &r);
        if std::env::args().any(|a| a == "--report") {
            println!("{}", serde_json::to_string_pretty(&r).unwrap());
        }
    }
    if std::env::args().any(|a| a == "--headline") {
        return;
    }

    println!("== growth with template size (curves: every 2nd section point) ==");
    for split in [0, 1, 2] {
        let c = case(&homer, split, 2, true, true);
        let (s, r) = time_fit(&c, 3);
        line(&format!("homer split {split}"), s, &r);
    }

    println!("== growth with curve vertices (96k template) ==");
    for (thin, extra) in [(4, false), (2, false), (1, false), (1, true)] {
        let c = case(&homer, 2, thin, extra, true);
        let (s, r) = time_fit(&c, 3);
        line(&format!("every {thin}, {} planes", if extra { 11 } else { 7 }), s, &r);
    }

    println!("== RBF stage vs SciPy RBFInterpolator (kernel linear, degree 1), same data ==");
    let c = case(&homer, 2, 1, true, false);
    rbf_peer(&c);
}

/// Times our RBF (solve + evaluate at every template vertex) and SciPy's on the same centres.
fn rbf_peer(c: &Case) {
    // The fine-level problem: centres = curve points, values = a smooth displacement.
    let centres: Vec<Point3> = {
        let net = meshwork_core::fit::curves::CurveNetwork::from_mesh(&c.curves, 1e-6).unwrap();
        net.points
    };
    let values: Vec<Point3> =
        centres.iter().map(|p| [0.1 * p[1].sin(), 0.05 * p[0] * p[2], -0.02 * p[1]]).collect();
    let points = &c.template.positions;
    let mut best = f64::INFINITY;
    let mut ours = Vec::new();
    for _ in 0..3 {
        let t = Instant::now();
        let f = Rbf::fit(&centres, &values, Kernel::Linear, "bench").unwrap();
        ours = f.eval_many(points, &Progress::new()).unwrap();
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!("meshwork rbf: {} centres, {} points: {:.3} s", centres.len(), points.len(), best);
    let py = std::path::Path::new(&std::env::var("HOME").unwrap_or_default())
        .join(".cache/meshwork-peers/bin/python");
    if !py.exists() {
        println!("scipy peer: venv not installed, skipped");
        return;
    }
    let dir = std::env::temp_dir().join(format!("bench_fit_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, v: &[Point3]| {
        let bytes: Vec<u8> = v.iter().flat_map(|p| p.iter().flat_map(|x| x.to_le_bytes())).collect();
        std::fs::write(dir.join(name), bytes).unwrap();
    };
    write("c.bin", &centres);
    write("v.bin", &values);
    write("p.bin", points);
    let script = r#"
import sys, time, numpy as np
from scipy.interpolate import RBFInterpolator
d = sys.argv[1]
c = np.fromfile(d + '/c.bin').reshape(-1, 3); v = np.fromfile(d + '/v.bin').reshape(-1, 3)
p = np.fromfile(d + '/p.bin').reshape(-1, 3)
best = 1e9
for _ in range(3):
    t = time.perf_counter()
    out = RBFInterpolator(c, v, kernel='linear', degree=1)(p)
    best = min(best, time.perf_counter() - t)
out.tofile(d + '/o.bin')
print(best)
"#;
    std::fs::write(dir.join("peer.py"), script).unwrap();
    let o = std::process::Command::new(py).arg(dir.join("peer.py")).arg(&dir).output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    match stdout.trim().parse::<f64>() {
        Ok(s) => {
            let theirs: Vec<f64> = std::fs::read(dir.join("o.bin"))
                .unwrap()
                .chunks(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
                .collect();
            let diff = ours
                .iter()
                .flat_map(|p| p.iter())
                .zip(&theirs)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            println!(
                "scipy rbf: {s:.3} s  (ratio scipy/meshwork {:.2}; max |difference| {diff:.2e})",
                s / best
            );
        }
        Err(_) => println!("scipy peer failed: {}", String::from_utf8_lossy(&o.stderr)),
    }
    let _ = std::fs::remove_dir_all(&dir);
}
