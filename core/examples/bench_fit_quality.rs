//! Mesh quality after re-triangulation on the fit headline case (homer split twice, 96k vertices,
//! 11 section planes of a known bend, 12 pairs; the same case as `bench_fit --headline`): the
//! sliver clean-up and the guarded smoothing each on and off, best of N runs (default 3). Prints
//! the time, the clean-up and smoothing stage times, the face count, flipped faces by the job's
//! measure and against the truth (the bent template, as `bench_fit`), and the smallest angle
//! after re-triangulation / before smoothing (after the clean-up) / after smoothing.
//!
//! `CARGO_TARGET_DIR=/tmp/fitq-rel cargo run --release -p meshwork-core --example bench_fit_quality -- 3`
use std::time::Instant;

use meshwork_core::fit::testdata::{bend, crossing_pairs, plane_sections, thin_network};
use meshwork_core::fit::{run, FitParams};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::subdivide_midpoint;
use meshwork_core::Progress;

fn planes() -> Vec<(Point3, f64)> {
    let ys = vec![0.3013, 0.4517, 0.6021, 0.7519, 0.9011, 0.3761, 0.5263, 0.6773, 0.8261];
    let mut p: Vec<(Point3, f64)> = ys.iter().map(|&y| ([0.0, 1.0, 0.0], y)).collect();
    p.push(([1.0, 0.0, 0.0], 0.4987));
    p.push(([0.0, 0.0, 1.0], 0.4919));
    p
}

/// Output faces whose normal opposes the truth's normal at the nearest truth vertex.
fn truth_flips(template: &Mesh, out: &Mesh) -> usize {
    use meshwork_core::fit::kdtree::KdTree;
    use meshwork_core::geometry::{dot, triangle_cross};
    let truth: Vec<Point3> = template.positions.iter().map(|&p| bend(p, 1.0)).collect();
    let tris = meshwork_core::shapes::fan_triangles(&template.faces);
    let mut vn = vec![[0.0; 3]; truth.len()];
    for t in &tris {
        let n = triangle_cross(truth[t[0] as usize], truth[t[1] as usize], truth[t[2] as usize]);
        for &v in t {
            for k in 0..3 {
                vn[v as usize][k] += n[k];
            }
        }
    }
    let tree = KdTree::new(&truth);
    out.faces
        .iter()
        .filter(|f| {
            let p = |i: usize| out.positions[f[i] as usize];
            let c = [0, 1, 2].map(|k| (p(0)[k] + p(1)[k] + p(2)[k]) / 3.0);
            let (v, _) = tree.nearest(c).unwrap();
            dot(triangle_cross(p(0), p(1), p(2)), vn[v as usize]) < 0.0
        })
        .count()
}

fn main() {
    let bytes = std::fs::read("../shared/meshes/homer.obj").unwrap();
    let homer = read(&bytes, &ReadOptions::default()).unwrap().mesh;
    let sections = thin_network(&plane_sections(&homer, &planes()), 1);
    let template = subdivide_midpoint(&homer, 2);
    let pairs = crossing_pairs(&sections, &template, 12, |p| bend(p, 1.0));
    let mut curves = sections;
    for p in curves.positions.iter_mut() {
        *p = bend(*p, 1.0);
    }
    let reps: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(3);
    for (cleanup, smooth) in [(false, true), (true, true), (false, false), (true, false)] {
        let params = FitParams { pairs: pairs.clone(), cleanup, smooth, ..Default::default() };
        let mut best = (f64::INFINITY, serde_json::Value::Null, 0);
        for _ in 0..reps {
            let t = Instant::now();
            let out = run(vec![template.clone(), curves.clone()], &params, &Progress::new()).unwrap();
            let s = t.elapsed().as_secs_f64();
            if s < best.0 {
                best = (s, out.report.clone(), truth_flips(&template, &out.meshes[0]));
            }
        }
        let r = &best.1;
        let st = &r["stages"];
        println!(
            "cleanup {cleanup:5} smooth {smooth:5}: {:.3} s | cleanup {:>6.1} smooth {:>6.1} ms | faces {} truth flips {} flipped {} | min angle retri {:.4} before {:.4} after {:.4} | mean {:.2} {:.2} {:.2} | <10°: {} {} {} | flips {} collapses {} bad {}→{} | halved {} rejected {}",
            best.0,
            st["cleanup"].as_f64().unwrap_or(0.0),
            st["smooth"].as_f64().unwrap_or(0.0),
            r["output_faces"],
            best.2,
            r["flipped_faces"],
            r["min_angle_deg_after_retriangulation"].as_f64().unwrap(),
            r["min_angle_deg_before_smoothing"].as_f64().unwrap(),
            r["min_angle_deg_after_smoothing"].as_f64().unwrap(),
            r["mean_min_angle_deg_after_retriangulation"].as_f64().unwrap(),
            r["mean_min_angle_deg_before_smoothing"].as_f64().unwrap(),
            r["mean_min_angle_deg_after_smoothing"].as_f64().unwrap(),
            r["faces_below_10deg_after_retriangulation"],
            r["faces_below_10deg_before_smoothing"],
            r["faces_below_10deg_after_smoothing"],
            r["cleanup"]["flips"],
            r["cleanup"]["collapses"],
            r["cleanup"]["bad_faces_before"],
            r["cleanup"]["bad_faces_after"],
            r["smoothing"]["moves_halved"],
            r["smoothing"]["moves_rejected"],
        );
    }
}
