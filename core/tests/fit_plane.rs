//! A plane grid cut by curves: the curves must become mesh edges and split the grid into the
//! expected regions; the plane must stay a plane (hand truth: z = 0 everywhere).

use meshwork_core::fit::{run, Alignment, CoplanarCentres, FitParams};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::grid;
use meshwork_core::{Error, Progress};

/// A wavy line from the left edge to the right edge (y ≈ 0.2) and a circle (centre (0.55, 0.6),
/// radius 0.22): 3 regions on the unit square.
fn curves() -> Mesh {
    let mut positions: Vec<Point3> = Vec::new();
    let mut line = Vec::new();
    for k in 0..=12 {
        let x = k as f64 / 12.0;
        positions.push([x, 0.2 + 0.04 * (6.0 * x).sin(), 0.0]);
        line.push((positions.len() - 1) as u32);
    }
    let mut circle = Vec::new();
    let n = 24;
    for k in 0..n {
        let t = std::f64::consts::TAU * k as f64 / n as f64;
        positions.push([0.55 + 0.22 * t.cos(), 0.6 + 0.22 * t.sin(), 0.0]);
        circle.push((positions.len() - 1) as u32);
    }
    circle.push(circle[0]);
    Mesh { positions, curves: vec![line, circle], ..Default::default() }
}

fn params() -> FitParams {
    FitParams { alignment: Alignment::None, coplanar_centres: CoplanarCentres::Augment, ..Default::default() }
}

#[test]
fn curves_become_edges_and_cut_three_regions() {
    let out = run(vec![grid(24, 24, 1.0 / 24.0, false), curves()], &params(), &Progress::new()).unwrap();
    let r = &out.report;
    eprintln!("{}", serde_json::to_string_pretty(r).unwrap());
    let m = &out.meshes[0];
    assert_eq!(r["regions"], 3);
    assert_eq!(m.groups.len(), 3);
    assert_eq!(r["segments_as_edges"], 1.0);
    assert_eq!(r["flipped_faces"], 0);
    assert!(r["curve_residual_max"].as_f64().unwrap() < 1e-12);
    // The plane stays the plane z = 0 (all displacements in the RBF data have z = 0).
    assert!(m.positions.iter().all(|p| p[2].abs() < 1e-12));
    // Faces grow only by the curve vertices inserted into the grid (no flips → no subdivision):
    // still a disc, so Euler's formula F = 2V − B − 2 (B = boundary edges), and at most one new
    // vertex per curve vertex (13 + 24).
    let mut uses = std::collections::HashMap::new();
    for f in m.faces.iter() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let boundary = uses.values().filter(|&&c| c == 1).count();
    assert!(boundary >= 96);
    assert_eq!(m.face_count(), 2 * m.vertex_count() - boundary - 2);
    assert!(m.vertex_count() <= 25 * 25 + 13 + 24);
    // Each output curve is a chain of mesh edges whose vertices lie on the input curve's segments.
    let input = curves();
    for (ci, chain) in m.curves.iter().enumerate() {
        assert!(chain.len() >= input.curves[ci].len());
        for w in chain.windows(2) {
            let has = m.faces.iter().any(|f| f.contains(&w[0]) && f.contains(&w[1]));
            assert!(has, "curve {ci}: {:?} is not a mesh edge", w);
        }
        for &v in chain {
            let p = m.positions[v as usize];
            let d = input.curves[ci]
                .windows(2)
                .map(|s| seg_dist(p, input.positions[s[0] as usize], input.positions[s[1] as usize]))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-9, "chain vertex {v} is {d} off curve {ci}");
        }
    }
    // The circle's region: the faces inside the circle, by their centroids, share one group.
    let inside: Vec<u32> = m
        .faces
        .iter()
        .enumerate()
        .filter(|(_, f)| {
            let c = centroid(m, f);
            ((c[0] - 0.55).powi(2) + (c[1] - 0.6).powi(2)).sqrt() < 0.18
        })
        .map(|(i, _)| m.faces.group(i))
        .collect();
    assert!(inside.len() > 20 && inside.iter().all(|&g| g == inside[0]));
}

#[test]
fn coplanar_centres_are_rejected_by_default() {
    let p = FitParams { alignment: Alignment::None, ..Default::default() };
    let e = run(vec![grid(8, 8, 0.125, false), curves()], &p, &Progress::new()).unwrap_err();
    match e {
        Error::InvalidParams { field, message } => {
            assert_eq!(field, "curves");
            assert!(message.contains("one plane"), "{message}");
        }
        other => panic!("{other}"),
    }
}

fn centroid(m: &Mesh, f: &[u32]) -> Point3 {
    let mut c = [0.0; 3];
    for &v in f {
        for k in 0..3 {
            c[k] += m.positions[v as usize][k] / f.len() as f64;
        }
    }
    c
}

fn seg_dist(p: Point3, a: Point3, b: Point3) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let l2 = ab.iter().map(|x| x * x).sum::<f64>();
    let t = (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2]) / l2).clamp(0.0, 1.0);
    ((0..3).map(|k| (a[k] + t * ab[k] - p[k]).powi(2)).sum::<f64>()).sqrt()
}
