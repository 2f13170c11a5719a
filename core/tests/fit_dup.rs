//! Coincident RBF centres made by the fit itself (fit-dup): several curve vertices whose closest
//! points on the approached template are one convex vertex used to be inserted 1e-12 apart, and
//! the fine stage then refused the curves as "duplicate RBF centres".

use meshwork_core::fit::insert;
use meshwork_core::fit::testdata::{plane_sections, sweep_planes, to_unit_box};
use meshwork_core::geometry::{dist, Aabb};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::job::{self, JobKind};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::repair::{self, RepairParams};
use meshwork_core::shapes::icosphere;
use meshwork_core::spatial::closest_on_triangle;
use meshwork_core::Progress;

fn shared(name: &str) -> Mesh {
    let path = format!("{}/../../shared/meshes/{name}.obj", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let opts = ReadOptions { name_hint: Some("x.obj".into()), ..Default::default() };
    read(&bytes, &opts).unwrap().mesh
}

/// The sweep's plane sections of a repaired shared mesh in the unit box.
fn sections_of(name: &str) -> Mesh {
    let params = RepairParams { fill_holes: false, ..Default::default() };
    let mut m = repair::run(shared(name), &params, &Progress::new()).unwrap().meshes.remove(0);
    to_unit_box(&mut m);
    let planes = sweep_planes(&m);
    plane_sections(&m, &planes)
}

/// `sweep_unseen`'s "icosphere vs sections of homer (auto)": it failed with "curve 545 point 571
/// (template vertex 217) and curve 580 point 617 (template vertex 4619) are at the same position".
/// The truth checked is the job's contract, independent of its report: a fit, every curve vertex
/// on an output vertex, no zero-area face.
#[test]
fn icosphere_onto_homers_sections_fits_without_coincident_centres() {
    let curves = sections_of("homer");
    let points: Vec<Point3> = curves.positions.clone();
    let mut t = icosphere(3, 0.5);
    for p in &mut t.positions {
        *p = [p[0] + 0.5, p[1] + 0.5, p[2] + 0.5];
    }
    let out = job::run(JobKind::Fit, vec![t, curves], serde_json::json!({}), &Progress::new())
        .unwrap_or_else(|e| panic!("the fit failed: {e}"));
    let m = &out.meshes[0];
    let diag = Aabb::of(&m.positions).unwrap().diagonal();
    let tree = meshwork_core::fit::kdtree::KdTree::new(&m.positions);
    let far = points.iter().map(|&p| tree.nearest(p).unwrap().1.sqrt()).fold(0.0, f64::max);
    assert!(far <= 1e-9 * diag, "a curve vertex is {far:.3e} from the output");
    for (i, f) in m.faces.iter().enumerate() {
        let p: Vec<Point3> = f.iter().map(|&v| m.positions[v as usize]).collect();
        let area = meshwork_core::geometry::triangle_area(p[0], p[1], p[2]);
        assert!(area > 0.0, "face {i} has zero area");
    }
    // The case (from the report): the insertion met feet piled at one place and spread them.
    let ins = &out.report["fine"]["insertion"];
    assert!(ins["spread_feet"].as_u64().unwrap() > 0, "{ins}");
    assert_eq!(out.report["fine"]["coincident_centres"], 0);
}

/// A square pyramid, apex (0, 0, 1) over (±1, ±1, 0), its four sides.
fn pyramid() -> (Vec<Point3>, Vec<[u32; 3]>) {
    let pos = vec![[0.0, 0.0, 1.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [-1.0, -1.0, 0.0], [1.0, -1.0, 0.0]];
    (pos, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])
}

/// A curve across the pyramid's apex, high above it: the closest point of its 11 middle vertices
/// is the apex (inside its normal cone). Every curve vertex must get a template vertex of its own,
/// none within 1e-3 of another (the curve's spacing is 0.05; the insertion used to nudge each
/// later one 20 % into ever smaller faces around the apex).
#[test]
fn feet_piled_at_an_apex_get_separate_template_vertices() {
    let (mut pos, mut tris) = pyramid();
    let pts: Vec<Point3> = (0..=12).map(|k| [0.05 * k as f64 - 0.3, 0.02, 1.6]).collect();
    let curves =
        Mesh { positions: pts.clone(), curves: vec![(0..pts.len() as u32).collect()], ..Default::default() };
    let net = meshwork_core::fit::curves::CurveNetwork::from_mesh(&curves, 1e-9).unwrap();
    let closest = |p: Point3| {
        tris.iter()
            .map(|t| closest_on_triangle(p, &t.map(|v| pos[v as usize])))
            .min_by(|a, b| dist(*a, p).total_cmp(&dist(*b, p)))
            .unwrap()
    };
    let at_apex = pts.iter().filter(|&&p| dist(closest(p), pos[0]) < 1e-12).count();
    assert!(at_apex >= 5, "the case: {at_apex} feet at the apex");
    let ins =
        insert::insert_curve_points(&mut pos, &mut tris, &net, &[], 0.0, None, &Progress::new()).unwrap();
    let vop = &ins.vertex_of_point;
    for a in 0..vop.len() {
        for b in a + 1..vop.len() {
            let d = dist(pos[vop[a] as usize], pos[vop[b] as usize]);
            assert!(d >= 1e-3, "points {a} and {b}: template vertices {d:.3e} apart");
        }
    }
    // The curve runs along +x: its template vertices must too (the nudges scattered them around
    // the apex in the order the queue met them).
    let xs: Vec<f64> = vop.iter().map(|&v| pos[v as usize][0]).collect();
    assert!(xs.windows(2).all(|w| w[1] > w[0]), "template vertices out of the curve's order: {xs:?}");
    assert!(ins.stats.spread_feet >= at_apex - 1, "{:?}", ins.stats);
}
