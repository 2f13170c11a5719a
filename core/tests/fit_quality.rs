//! Mesh quality after re-triangulation: the sliver clean-up, the guarded smoothing and the UVs
//! of snapped vertices. Every case has an independent truth: a plane (normal +z, UVs an affine
//! function of position, regions counted by hand) or the unit sphere (outward normal = position).
//!
//! Invariants checked directly on the output mesh, not on the job's own measures:
//! no face with area ≤ 1e-6 × the mean area, no face against the analytic normal, every input
//! curve point an output vertex bit for bit, every output curve an edge chain on its input
//! polyline, the region count, and the face count within a few % of the run without clean-up.

use std::collections::HashSet;

use meshwork_core::fit::testdata::ellipsoid_sections;
use meshwork_core::fit::testdata::faces_against;
use meshwork_core::fit::{run, Alignment, CoplanarCentres, FitParams};
use meshwork_core::geometry::{corner_angle, dot, norm, sub, triangle_cross};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::{grid, icosphere};
use meshwork_core::{Output, Progress};

/// Curves on the unit square drawn to make slivers on a 16×16 grid (h = 1/16): a horizontal line
/// 0.3% of h above a grid line and a vertical one 2% of h right of one, sampled every 0.43 h and
/// 0.55 h (their crossings with the grid edges fall next to grid vertices, which the walk snaps
/// next to curve points: needles), crossing at a shared point, and a circle whose points are
/// placed within 1% of h of grid vertices. No two curve points are closer than 0.13 h. Regions
/// by hand: the two lines cut the square into 4, the circle (inside one quarter) adds 1: 5.
fn sliver_curves() -> Mesh {
    let h = 1.0 / 16.0;
    let (y0, x0) = (8.0 * h + 0.003 * h, 4.0 * h + 0.02 * h);
    let mut positions: Vec<Point3> = Vec::new();
    let push = |p: Point3, positions: &mut Vec<Point3>| {
        positions.push(p);
        (positions.len() - 1) as u32
    };
    let cross = push([x0, y0, 0.0], &mut positions);
    let mut horizontal = Vec::new();
    for k in 0..=37 {
        let x = k as f64 / 37.0;
        if k == 10 {
            horizontal.push(cross); // 9/37 < x0 < 10/37
        }
        horizontal.push(push([x, y0, 0.0], &mut positions));
    }
    let mut vertical = Vec::new();
    for k in 0..=29 {
        let y = k as f64 / 29.0;
        if k == 15 {
            vertical.push(cross); // 14/29 < y0 < 15/29
        }
        vertical.push(push([x0, y, 0.0], &mut positions));
    }
    let mut circle = Vec::new();
    let n = 20;
    for k in 0..n {
        let t = std::f64::consts::TAU * k as f64 / n as f64;
        let p = [0.72 + 0.14 * t.cos(), 0.26 + 0.14 * t.sin()];
        // Pull each point to 1% of h from its nearest grid vertex when it is within h/4 of one.
        let g = [(p[0] / h).round() * h, (p[1] / h).round() * h];
        let d = ((p[0] - g[0]).powi(2) + (p[1] - g[1]).powi(2)).sqrt();
        let q = if d < 0.25 * h && d > 0.0 {
            [g[0] + 0.01 * h * (p[0] - g[0]) / d, g[1] + 0.01 * h * (p[1] - g[1]) / d]
        } else {
            p
        };
        circle.push(push([q[0], q[1], 0.0], &mut positions));
    }
    circle.push(circle[0]);
    Mesh { positions, curves: vec![horizontal, vertical, circle], ..Default::default() }
}

fn plane_params() -> FitParams {
    FitParams { alignment: Alignment::None, coplanar_centres: CoplanarCentres::Augment, ..Default::default() }
}

fn fit(template: Mesh, curves: Mesh, params: &FitParams) -> Output {
    run(vec![template, curves], params, &Progress::new()).expect("fit")
}

fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Smallest corner angle (degrees) of the output, computed here.
fn min_angle(m: &Mesh) -> f64 {
    m.faces
        .iter()
        .flat_map(|f| {
            let p = |k: usize| m.positions[f[k % 3] as usize];
            (0..3).map(move |k| corner_angle(p(k), p(k + 1), p(k + 2)).to_degrees())
        })
        .fold(180.0, f64::min)
}

/// The invariants shared by all cases. `normal(p)` is the analytic outward normal at p.
fn check_invariants(out: &Output, curves: &Mesh, regions: usize, normal: impl Fn(Point3) -> Point3) {
    let m = &out.meshes[0];
    let r = &out.report;
    // No degenerate face (area ≤ 1e-6 × mean) and none against the analytic normal.
    let areas: Vec<f64> = m
        .faces
        .iter()
        .map(|f| {
            0.5 * norm(triangle_cross(
                m.positions[f[0] as usize],
                m.positions[f[1] as usize],
                m.positions[f[2] as usize],
            ))
        })
        .collect();
    let mean = areas.iter().sum::<f64>() / areas.len() as f64;
    for (i, f) in m.faces.iter().enumerate() {
        assert!(areas[i] > 1e-6 * mean, "face {i} {f:?} has area {} (mean {mean})", areas[i]);
    }
    let against = faces_against(m, normal);
    assert!(against.is_empty(), "faces against the analytic normal: {against:?}");
    // Every curve point is an output vertex, bit for bit.
    let verts: HashSet<[u64; 3]> = m.positions.iter().map(|p| p.map(f64::to_bits)).collect();
    for (i, p) in curves.positions.iter().enumerate() {
        assert!(verts.contains(&p.map(f64::to_bits)), "curve point {i} {p:?} is not an output vertex");
    }
    // Every output curve is a chain of mesh edges on its input polyline.
    let mut edges: HashSet<(u32, u32)> = HashSet::new();
    for f in m.faces.iter() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    assert_eq!(m.curves.len(), curves.curves.len());
    for (ci, chain) in m.curves.iter().enumerate() {
        assert!(chain.len() >= 2);
        for w in chain.windows(2) {
            assert!(edges.contains(&(w[0].min(w[1]), w[0].max(w[1]))), "curve {ci}: {w:?} is not an edge");
        }
        let line = &curves.curves[ci];
        for &v in chain {
            let p = m.positions[v as usize];
            let d = line
                .windows(2)
                .map(|s| seg_dist(p, curves.positions[s[0] as usize], curves.positions[s[1] as usize]))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-9, "chain vertex {v} is {d} off curve {ci}");
        }
    }
    assert_eq!(r["regions"], regions as u64);
    assert_eq!(m.groups.len(), regions);
    assert_eq!(r["segments_as_edges"], 1.0);
}

fn seg_dist(p: Point3, a: Point3, b: Point3) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 { (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    norm(sub(p, [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]]))
}

#[test]
fn plane_slivers_are_cleaned_and_smoothing_never_lowers_the_min_angle() {
    let template = grid(16, 16, 1.0 / 16.0, false);
    let curves = sliver_curves();
    let raw =
        fit(template.clone(), curves.clone(), &FitParams { cleanup: false, smooth: false, ..plane_params() });
    let out = fit(template, curves.clone(), &plane_params());
    let r = &out.report;
    eprintln!("{}", serde_json::to_string_pretty(&r["cleanup"]).unwrap());
    // The case does make slivers (else the test proves nothing).
    let raw_min = min_angle(&raw.meshes[0]);
    assert!(raw_min < 3.0, "re-triangulation alone gives {raw_min}°: the curves no longer make slivers");
    assert!(num(&r["min_angle_deg_after_retriangulation"]) < 3.0);
    check_invariants(&out, &curves, 5, |_| [0.0, 0.0, 1.0]);
    assert!(out.meshes[0].positions.iter().all(|p| p[2] == 0.0), "the plane stays z = 0");
    // Clean-up: flips done, and no face left below the threshold (15°): on this network no two
    // curve points are closer than 0.13 h and the curves meet at 90°, so no small angle is forced
    // by the input (a needle along a curve has a snapped vertex, which may be removed).
    assert!(num(&r["cleanup"]["flips"]) > 0.0);
    assert_eq!(r["cleanup"]["bad_faces_after"], 0, "{}", r["cleanup"]);
    let before = num(&r["min_angle_deg_before_smoothing"]);
    let after = num(&r["min_angle_deg_after_smoothing"]);
    assert!(before >= 15.0, "after clean-up {before}°");
    assert!(after >= before, "smoothing lowered the min angle {before}° → {after}°");
    assert!((min_angle(&out.meshes[0]) - after).abs() < 1e-9);
    // Faces: within 5% of the run without clean-up (collapses remove 2 faces each).
    let (f0, f1) = (raw.meshes[0].face_count() as f64, out.meshes[0].face_count() as f64);
    assert!((f1 - f0).abs() <= 0.05 * f0, "faces {f0} → {f1}");
    assert_eq!(raw.report["regions"], 5);
}

#[test]
fn sphere_through_great_circles_keeps_angles_above_the_threshold() {
    // Three orthogonal great circles (12 points per quarter) on a level-3 icosphere: 8 octants.
    // The network's own angles are 90° at the 6 crossings and 180° elsewhere, and no two of its
    // points are closer than the sampling step (7.5°) — about half the template's edge — so
    // nothing forces a small angle: after clean-up every face must be at or above the clean-up
    // threshold (15°) and smoothing must keep it there.
    let curves = ellipsoid_sections([1.0; 3], 12);
    let template = icosphere(3, 1.0);
    let params = FitParams { alignment: Alignment::None, ..Default::default() };
    let raw =
        fit(template.clone(), curves.clone(), &FitParams { cleanup: false, smooth: false, ..params.clone() });
    let out = fit(template, curves.clone(), &params);
    let r = &out.report;
    eprintln!("{}", serde_json::to_string_pretty(&r["cleanup"]).unwrap());
    check_invariants(&out, &curves, 8, |p| p);
    let before = num(&r["min_angle_deg_before_smoothing"]);
    let after = num(&r["min_angle_deg_after_smoothing"]);
    assert!(before >= 15.0, "after clean-up {before}°");
    assert!(after >= before, "smoothing lowered the min angle {before}° → {after}°");
    assert!(min_angle(&out.meshes[0]) >= 15.0);
    // On the sphere: the vertices stay within the sagitta of a level-3 icosphere of radius 1.
    for p in &out.meshes[0].positions {
        assert!((norm(*p) - 1.0).abs() < 0.01, "vertex at radius {}", norm(*p));
    }
    let (f0, f1) = (raw.meshes[0].face_count() as f64, out.meshes[0].face_count() as f64);
    assert!((f1 - f0).abs() <= 0.05 * f0, "faces {f0} → {f1}");
    assert_eq!(raw.report["regions"], 8);
}

/// On a plane whose fit moves nothing, UVs that are an affine function of position must stay that
/// function at *every* output vertex: vertices snapped along a curve included (their UV is
/// interpolated in the face they land in, which reproduces an affine map exactly). Keeping the
/// old UV of a snapped vertex breaks this by its snap distance. The fit moves nothing because
/// every curve point is a grid vertex (zero RBF data); the zigzag's segments, of slopes ±1/5
/// and 1/6 in grid units, cross grid edges within 0.2 of a vertex, where the walk snaps.
#[test]
fn snapped_vertices_get_the_uv_of_where_they_land() {
    let uv_of = |p: Point3| [0.3 + 2.0 * p[0] - 0.5 * p[1], 1.0 + 0.25 * p[0] - p[1]];
    let h = 1.0 / 16.0;
    let mut template = grid(16, 16, h, false);
    template.uvs = Some(template.positions.iter().map(|&p| uv_of(p)).collect());
    let zigzag: Vec<Point3> = [(0.0, 8.0), (5.0, 9.0), (10.0, 8.0), (16.0, 9.0)]
        .iter()
        .map(|&(i, j)| [i * h, j * h, 0.0])
        .collect();
    let curves = Mesh { positions: zigzag, curves: vec![vec![0, 1, 2, 3]], ..Default::default() };
    let params = FitParams { smooth: false, ..plane_params() };
    let out = fit(template.clone(), curves.clone(), &params);
    check_invariants(&out, &curves, 2, |_| [0.0, 0.0, 1.0]);
    let m = &out.meshes[0];
    let moved = out.report["moved_vertices"].as_array().unwrap().len();
    assert!(moved > 0, "the case snaps no vertex: it tests nothing");
    let uvs = m.uvs.as_ref().unwrap();
    assert_eq!(uvs.len(), m.vertex_count());
    for (v, (p, uv)) in m.positions.iter().zip(uvs).enumerate() {
        let want = uv_of(*p);
        let err = (uv[0] - want[0]).abs().max((uv[1] - want[1]).abs());
        assert!(err < 1e-12, "vertex {v} at {p:?}: uv {uv:?}, affine truth {want:?}");
    }
}

/// The smoothing guard on its own: a grid whose free vertices are scattered by up to 45% of the
/// spacing (some faces nearly degenerate), smoothed with a quarter of the vertices fixed. Truth:
/// the plane's normal +z; the smallest angle may not drop, no face may turn over.
#[test]
fn guarded_smoothing_of_a_scrambled_grid() {
    use meshwork_core::fit::smooth::{smooth, SmoothSettings};
    let g = grid(20, 20, 0.05, false);
    let tris: Vec<[u32; 3]> = g.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    let n = 21;
    let fixed: Vec<bool> = (0..g.positions.len())
        .map(|i| {
            let (x, y) = (i % n, i / n);
            x == 0 || y == 0 || x == n - 1 || y == n - 1 || (x * 7 + y * 3) % 4 == 0
        })
        .collect();
    let mut pos = g.positions.clone();
    for (i, p) in pos.iter_mut().enumerate() {
        if !fixed[i] {
            let k = i as f64;
            p[0] += 0.45 * 0.05 * (k * 1.37).sin();
            p[1] += 0.45 * 0.05 * (k * 2.11).cos();
        }
    }
    let orient = |pos: &[Point3], t: &[u32; 3]| {
        triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize])[2]
    };
    let start_flipped: Vec<bool> = tris.iter().map(|t| orient(&pos, t) <= 0.0).collect();
    let angles = |pos: &[Point3]| {
        tris.iter()
            .flat_map(|t| {
                (0..3).map(move |k| {
                    corner_angle(
                        pos[t[k] as usize],
                        pos[t[(k + 1) % 3] as usize],
                        pos[t[(k + 2) % 3] as usize],
                    )
                    .to_degrees()
                })
            })
            .fold(180.0, f64::min)
    };
    let before = angles(&pos);
    let fixed_pos = pos.clone();
    let s = SmoothSettings {
        mcf_iterations: 10,
        mcf_step: 0.5,
        laplacian_iterations: 20,
        min_angle_floor_deg: 15.0,
    };
    let stats = smooth(&mut pos, &tris, &fixed, &s, &Progress::new()).unwrap();
    let after = angles(&pos);
    assert!(after >= before, "{before}° → {after}°");
    for (i, t) in tris.iter().enumerate() {
        if !start_flipped[i] {
            assert!(orient(&pos, t) > 0.0, "face {i} turned over");
        }
    }
    for (i, p) in pos.iter().enumerate() {
        assert_eq!(p[2], 0.0);
        if fixed[i] {
            assert_eq!(*p, fixed_pos[i]);
        }
    }
    assert!(stats.moves > 0);
}
