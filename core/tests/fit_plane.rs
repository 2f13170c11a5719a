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

/// The template's UVs follow the fit: old vertices keep theirs, every vertex the fit adds gets the
/// barycentric interpolation of its template face's UVs where it was made. With the UVs an affine
/// function of the template position (hand-chosen, invertible), mapping each output vertex's UV
/// back gives where it sits in the template; the output faces drawn there must tile the unit
/// square exactly once (all positively oriented, total area 1): no gap, no fold, no overlap.
#[test]
fn uvs_are_carried_to_new_vertices() {
    let (a, b, c, d) = (2.0, -0.5, 0.25, -1.0); // uv = (0.3 + a x + b y, 1 + c x + d y)
    let uv_of = |p: Point3| [0.3 + a * p[0] + b * p[1], 1.0 + c * p[0] + d * p[1]];
    let det = a * d - b * c;
    let back = |uv: [f64; 2]| {
        let (u, v) = (uv[0] - 0.3, uv[1] - 1.0);
        [(d * u - b * v) / det, (a * v - c * u) / det]
    };
    let mut template = grid(24, 24, 1.0 / 24.0, false);
    template.uvs = Some(template.positions.iter().map(|&p| uv_of(p)).collect());
    let out = run(vec![template.clone(), curves()], &params(), &Progress::new()).unwrap();
    let m = &out.meshes[0];
    assert!(m.vertex_count() > template.vertex_count(), "the fit added vertices");
    let uvs = m.uvs.as_ref().expect("output keeps the UVs");
    assert_eq!(uvs.len(), m.vertex_count());
    // Template vertices keep their UVs, except those the fit moved over the surface (snapped onto
    // a curve: re-interpolated where they landed, checked by the tiling below) or removed (sliver
    // clean-up). The report lists both in the numbering before the clean-up, which only drops
    // the removed vertices and keeps the order.
    let ids = |v: &serde_json::Value| -> Vec<usize> {
        v.as_array().unwrap().iter().map(|x| x.as_u64().unwrap() as usize).collect()
    };
    let (moved, removed) =
        (ids(&out.report["moved_vertices"]), ids(&out.report["cleanup"]["removed_vertices"]));
    let template_uvs = template.uvs.as_ref().unwrap();
    let mut kept = 0;
    for (i, uv) in template_uvs.iter().enumerate() {
        if removed.contains(&i) {
            continue;
        }
        if !moved.contains(&i) {
            assert_eq!(uvs[kept], *uv, "template vertex {i} (output {kept})");
        }
        kept += 1;
    }
    let q: Vec<[f64; 2]> = uvs.iter().map(|&uv| back(uv)).collect();
    let mut total = 0.0;
    for f in m.faces.iter() {
        let (p0, p1, p2) = (q[f[0] as usize], q[f[1] as usize], q[f[2] as usize]);
        let area = 0.5 * ((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]));
        assert!(area > 0.0, "face {f:?} is folded in UV space");
        total += area;
    }
    assert!((total - 1.0).abs() < 1e-9, "UV-space area {total}");
    // And they reach the file: OBJ written with `vt` and read back.
    let bytes = meshwork_core::io::write(m, meshwork_core::io::Format::Obj).unwrap();
    let read = meshwork_core::io::read(&bytes, &Default::default()).unwrap().mesh;
    assert_eq!(read.uvs.as_ref().map(|u| u.len()), Some(m.vertex_count()));
}

/// The template's face groups survive as region × group: the grid's left half is group "left",
/// the right half "right"; the line and the circle (which straddles x = 1/2) make 3 regions, each
/// on both halves: 6 output groups, and every output face lying in one half carries that half's
/// name (hand truth from its corner positions; no smoothing, so nothing moves afterwards).
#[test]
fn template_groups_are_intersected_with_regions() {
    let g = grid(24, 24, 1.0 / 24.0, false);
    let tris: Vec<[u32; 3]> = g.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    let mut faces = meshwork_core::mesh::Faces::new();
    for t in &tris {
        let cx = t.iter().map(|&v| g.positions[v as usize][0]).sum::<f64>() / 3.0;
        faces.push(t, (cx > 0.5) as u32);
    }
    let mut template = Mesh::new(g.positions.clone(), faces);
    template.groups = vec!["left".into(), "right".into()];
    let params = FitParams { smooth: false, ..params() };
    let out = run(vec![template, curves()], &params, &Progress::new()).unwrap();
    assert_eq!(out.report["regions"], 3);
    let m = &out.meshes[0];
    assert_eq!(m.groups.len(), 6, "{:?}", m.groups);
    for (i, f) in m.faces.iter().enumerate() {
        let xs: Vec<f64> = f.iter().map(|&v| m.positions[v as usize][0]).collect();
        let name = m.group_name(m.faces.group(i));
        if xs.iter().all(|&x| x <= 0.5) && xs.iter().any(|&x| x < 0.5) {
            assert!(name.ends_with("/left"), "face {i} at x {xs:?} is in {name}");
        }
        if xs.iter().all(|&x| x >= 0.5) && xs.iter().any(|&x| x > 0.5) {
            assert!(name.ends_with("/right"), "face {i} at x {xs:?} is in {name}");
        }
    }
}
