//! Fit sweep over every shared mesh a template can be made of: each mesh (repaired, scaled into
//! the unit box) is cut by plane sections, the sections are moved by a known bend
//! (`testdata::bend`), and the mesh split once is fitted to them, with 12 user pairs and with the
//! automatic alignment. Prints per case: flips, segments as edges, regions found vs the regions
//! the planes cut the surface into (counted independently on a finer copy), `euler`: the regions
//! the thinned network itself can make on a closed genus-0 template (Euler's formula, see
//! [`euler_regions`]), the max distance of the output to the bent surface and the time. A check of the general case, not a benchmark.
//!
//! Run from the repository root:
//! `CARGO_TARGET_DIR=/work/target-release cargo run --release -p meshwork-core --example sweep_fit [NAME…]`
//! (`SWEEP_FAILED=1` also prints the report's list of segments that could not be made edge chains;
//! `SWEEP_APPROACH=1` the fine stage's approach levels and curve distances.)

use std::collections::HashMap;
use std::time::Instant;

use meshwork_core::fit::curves::{CurveNetwork, NetworkOptions};
use meshwork_core::fit::testdata::{
    bend, boundary_vertices, crossing_pairs, plane_sections, section_regions, sweep_planes, thin_network,
    to_unit_box,
};
use meshwork_core::fit::{run, CoplanarCentres, FitParams};
use meshwork_core::geometry::Aabb;
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::mesh::Mesh;
use meshwork_core::repair::{self, RepairParams};
use meshwork_core::shapes::subdivide_midpoint;
use meshwork_core::spatial::Bvh;
use meshwork_core::Progress;

const MESHES: [&str; 7] = ["homer", "fandisk", "spot", "stanford-bunny", "rocker-arm", "alligator", "woody"];

/// Reads, repairs (weld, orient, manifold) and scales `name` so its longest side is 1, min corner at 0.
fn load(name: &str) -> Option<Mesh> {
    let bytes = std::fs::read(format!("../shared/meshes/{name}.obj")).ok()?;
    let raw = read(&bytes, &ReadOptions::default()).ok()?.mesh;
    let params = RepairParams { fill_holes: false, ..Default::default() };
    let mut m = repair::run(raw, &params, &Progress::new()).ok()?.meshes.remove(0);
    Aabb::of(&m.positions)?;
    to_unit_box(&mut m);
    Some(m)
}

/// Max distance of `out`'s vertices to the bent truth surface (exact closest points, BVH),
/// relative to the truth's bbox diagonal.
fn max_deviation(out: &Mesh, truth: &Mesh) -> f64 {
    let bvh = Bvh::new(&truth.positions, &truth.faces);
    let diag = Aabb::of(&truth.positions).map_or(1.0, |b| b.diagonal());
    bvh.max_distance(&out.positions) / diag
}

/// Curve ends (curve-graph degree 1) of the output that are not on the mesh boundary: each one
/// is a cut that stops short, so the regions on both sides stay joined. (0 on closed templates.)
fn ends_inside(out: &Mesh) -> (usize, usize) {
    let mut deg: HashMap<u32, usize> = HashMap::new();
    for c in &out.curves {
        for w in c.windows(2) {
            if w[0] != w[1] {
                *deg.entry(w[0]).or_default() += 1;
                *deg.entry(w[1]).or_default() += 1;
            }
        }
    }
    let on_boundary = boundary_vertices(out);
    let ends: Vec<u32> = deg.iter().filter(|(_, &d)| d == 1).map(|(&v, _)| v).collect();
    (ends.iter().filter(|&&v| !on_boundary[v as usize]).count(), ends.len())
}

/// Regions the curve network can make on `template` if every segment becomes an edge chain and
/// nothing else changes: for a closed, connected genus-0 template Euler's formula for an embedded
/// graph gives F = E − V + C + 1 (C = connected components of the network); on genus g it is
/// between that minus 2g and that (each handle the network cuts through adds up to 2 to χ).
/// Computed from the input network alone, so it tells a network that cannot show a region (a
/// section loop thinned to two points, two sections welded into one) from a fit that lost one.
/// `None` when the template is open or has several components.
fn euler_regions(template: &Mesh, curves: &Mesh, params: &FitParams) -> Option<String> {
    /// Union-find root with path halving.
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
    for f in template.faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let closed = edges.values().all(|&n| n == 2);
    let mut tparent: Vec<usize> = (0..template.positions.len()).collect();
    for &(a, b) in edges.keys() {
        let (ra, rb) = (root(&mut tparent, a as usize), root(&mut tparent, b as usize));
        tparent[ra] = rb;
    }
    let roots: std::collections::HashSet<usize> =
        edges.keys().map(|&(a, _)| root(&mut tparent, a as usize)).collect();
    if roots.len() != 1 {
        return None;
    }
    let chi = template.positions.len() as i64 - edges.len() as i64 + template.faces.len() as i64;
    if !closed || chi > 2 || chi % 2 != 0 {
        return None;
    }
    let genus = ((2 - chi) / 2) as usize;
    let options = NetworkOptions {
        join_tolerance: params.join_tolerance,
        merge_tolerance: params.merge_tolerance,
        junction_tolerance: params.junction_tolerance,
    };
    let net = CurveNetwork::build(curves, &options).ok()?;
    // Union-find over the network's points for its connected components.
    let mut parent: Vec<usize> = (0..net.points.len()).collect();
    let mut segs: Vec<(u32, u32)> = net.segments.iter().map(|s| (s[0].min(s[1]), s[0].max(s[1]))).collect();
    segs.sort_unstable();
    segs.dedup();
    for &(a, b) in &segs {
        let (ra, rb) = (root(&mut parent, a as usize), root(&mut parent, b as usize));
        parent[ra] = rb;
    }
    let used: std::collections::HashSet<u32> = segs.iter().flat_map(|&(a, b)| [a, b]).collect();
    let comps: std::collections::HashSet<usize> =
        used.iter().map(|&v| root(&mut parent, v as usize)).collect();
    let planar = segs.len() + comps.len() + 1 - used.len();
    Some(if genus == 0 {
        planar.to_string()
    } else {
        format!("{}-{planar}", planar.saturating_sub(2 * genus))
    })
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    let only: Vec<String> = std::env::args().skip(1).collect();
    println!(
        "{:<16} {:<6} {:>6} {:>6} {:>7} {:>6} {:>6} {:>8} {:>9} {:>6} {:>9} {:>9} {:>8}",
        "mesh",
        "align",
        "tmplV",
        "curveV",
        "time s",
        "flips",
        "folds",
        "edges %",
        "regions",
        "euler",
        "max dev",
        "minang",
        "ends in"
    );
    for name in MESHES.iter().filter(|n| only.is_empty() || only.iter().any(|o| o == *n)) {
        let Some(m) = load(name) else {
            println!("{name:<16} SKIP (not readable or not repairable)");
            continue;
        };
        let planes = sweep_planes(&m);
        let expected = section_regions(&m, &planes);
        let sections = thin_network(&plane_sections(&m, &planes), 2);
        let template = subdivide_midpoint(&m, 1);
        let mut truth = template.clone();
        for p in &mut truth.positions {
            *p = bend(*p, 1.0);
        }
        let pairs = crossing_pairs(&sections, &template, 12, |p| bend(p, 1.0));
        let mut curves = sections;
        for p in &mut curves.positions {
            *p = bend(*p, 1.0);
        }
        for (label, pairs) in [("pairs", pairs), ("auto", Vec::new())] {
            // Flat meshes (woody, alligator) give coplanar curves: the seed's normal augmentation.
            let flat = Aabb::of(&m.positions).is_some_and(|b| (0..3).any(|k| b.max[k] - b.min[k] < 0.05));
            let coplanar_centres = if flat { CoplanarCentres::Augment } else { CoplanarCentres::Reject };
            let params = FitParams { pairs, coplanar_centres, ..Default::default() };
            let euler = euler_regions(&template, &curves, &params);
            let t = Instant::now();
            let got = run(vec![template.clone(), curves.clone()], &params, &Progress::new());
            let secs = t.elapsed().as_secs_f64();
            match got {
                Err(e) => println!("{name:<16} {label:<6} ERROR {e}"),
                Ok(out) => {
                    let r = &out.report;
                    let inside = ends_inside(&out.meshes[0]);
                    if std::env::var("SWEEP_FAILED").is_ok() {
                        eprintln!("{name} {label}: {}", r["retriangulation"]["failed"]);
                    }
                    if std::env::var("SWEEP_APPROACH").is_ok() {
                        eprintln!(
                            "{name} {label}: approach {} fine distance max {} mean {} insertion {}",
                            r["fine"]["approach"],
                            r["fine"]["correspondence_distance_max"],
                            r["fine"]["correspondence_distance_mean"],
                            r["fine"]["insertion"]
                        );
                    }
                    if std::env::var("SWEEP_UNTANGLE").is_ok() {
                        eprintln!(
                            "{name} {label}: untangle {} cleanup {}",
                            r["untangle"], r["cleanup"]["bad_faces_after"]
                        );
                    }
                    println!(
                        "{name:<16} {label:<6} {:>6} {:>6} {:>7.2} {:>9} {:>6} {:>8.2} {:>4}/{:<4} {:>6} {:>9.2e} {:>4.1}/{:<4.1} {:>3}/{:<3}",
                        template.positions.len(),
                        curves.positions.len(),
                        secs,
                        // before smoothing / final (the final count against the fine surface, the measure before session 13)
                        format!(
                            "{}/{}({})",
                            r["flipped_faces_before_smoothing"],
                            r["flipped_faces"],
                            r["flipped_faces_against_fine_surface"]
                        ),
                        // Reference-free folded edges (output; the template's own in brackets).
                        format!("{}({})", r["folded_edges"], r["folds"]["template"]["folded_edges"]),
                        100.0 * r["segments_as_edges"].as_f64().unwrap_or(f64::NAN),
                        r["regions"],
                        expected,
                        euler.unwrap_or_else(|| "–".to_string()),
                        max_deviation(&out.meshes[0], &truth),
                        r["min_angle_deg_before_smoothing"].as_f64().unwrap_or(f64::NAN),
                        r["min_angle_deg_after_smoothing"].as_f64().unwrap_or(f64::NAN),
                        inside.0,
                        inside.1,
                    );
                }
            }
        }
    }
}
