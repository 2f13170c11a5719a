//! Tests of the orientation count (moved out of `orientation.rs`).

use super::*;
use crate::geometry::{cross, norm};

fn sphere() -> (Vec<Point3>, Vec<[u32; 3]>) {
    let m = crate::shapes::icosphere(3, 1.0);
    let tris = m.faces.triangles();
    (m.positions, tris)
}

/// Rotation by `angle` about the unit `axis` (Rodrigues).
fn rotation(axis: Point3, angle: f64) -> Jacobian {
    let (s, c) = angle.sin_cos();
    let [x, y, z] = axis;
    [
        [c + x * x * (1.0 - c), x * y * (1.0 - c) - z * s, x * z * (1.0 - c) + y * s],
        [y * x * (1.0 - c) + z * s, c + y * y * (1.0 - c), y * z * (1.0 - c) - x * s],
        [z * x * (1.0 - c) - y * s, z * y * (1.0 - c) + x * s, c + z * z * (1.0 - c)],
    ]
}

fn apply(j: &Jacobian, p: Point3) -> Point3 {
    [dot(j[0], p), dot(j[1], p), dot(j[2], p)]
}

/// A rotation turns no face over, however far it turns: 0 counted, while the template's own
/// normals would flag most faces of a sphere turned by 150°.
#[test]
fn a_rotation_by_150_degrees_turns_no_face() {
    let (pos, tris) = sphere();
    let r = rotation(normalize([1.0, 1.0, 0.3]), 150f64.to_radians());
    let turned: Vec<Point3> = pos.iter().map(|&p| apply(&r, p)).collect();
    let mut o = Orientation::new(&pos, &tris);
    // Against the raw template normals (no map pushed), most faces of the turned sphere oppose.
    let raw_count = o.faces_against(&turned, &tris);
    assert!(raw_count > tris.len() / 2, "{raw_count} of {}", tris.len());
    assert_eq!(o.push(&pos, |_, _| r), 0);
    assert_eq!(o.faces_against(&turned, &tris), 0);
    assert_eq!(o.faces_inverted(&tris), 0);
}

/// A smooth map that turns space inside out beyond a plane, (x, y, z) ↦ (x, y, z·g(x)) with
/// g = 1 for x ≤ 0 falling to −1 for x ≥ 0.4 (det J = g, 0 at x = 0.2): the faces beyond
/// the plane come out inside out and are counted, those before it are not. The surface-based
/// measure (the mesh's own vertex normals) sees none of them.
#[test]
fn a_map_that_turns_a_region_inside_out_counts_its_faces() {
    let (pos, tris) = sphere();
    let g = |x: f64| (std::f64::consts::PI * (x / 0.4).clamp(0.0, 1.0)).cos();
    let dg = |x: f64| {
        if (0.0..=0.4).contains(&x) {
            -std::f64::consts::PI / 0.4 * (std::f64::consts::PI * x / 0.4).sin()
        } else {
            0.0
        }
    };
    let image: Vec<Point3> = pos.iter().map(|p| [p[0], p[1], p[2] * g(p[0])]).collect();
    let mut o = Orientation::new(&pos, &tris);
    let inverted_vertices =
        o.push(&pos, |_, p| [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [p[2] * dg(p[0]), 0.0, g(p[0])]]);
    assert_eq!(inverted_vertices, pos.iter().filter(|p| p[0] >= 0.2).count());
    // The truth by position: faces wholly beyond x = 0.2 are inside out, faces wholly before
    // it are not; faces across it may go either way.
    let beyond = tris.iter().filter(|t| t.iter().all(|&v| pos[v as usize][0] > 0.2)).count();
    let touching = tris.iter().filter(|t| t.iter().any(|&v| pos[v as usize][0] > 0.2)).count();
    let counted = o.faces_against(&image, &tris);
    assert!(beyond > 100, "the case: {beyond} faces beyond the plane");
    assert!((beyond..=touching).contains(&counted), "{counted} not in {beyond}..={touching}");
    let inverted = o.faces_inverted(&tris);
    assert!((beyond..=touching).contains(&inverted), "{inverted} not in {beyond}..={touching}");
    // The faces before the plane: none counted.
    let before: Vec<[u32; 3]> =
        tris.iter().copied().filter(|t| t.iter().all(|&v| pos[v as usize][0] < 0.2)).collect();
    assert_eq!(o.faces_against(&image, &before), 0);
    // Against the deformed surface's own normals (the report's measure before): blind to it.
    let own = Orientation::new(&image, &tris);
    let old = own.faces_against(&image, &tris);
    assert!(old * 10 < beyond, "old measure {old}, inside-out faces {beyond}");
}

/// Added vertices take their parents' Jacobians and places: a vertex inside a template face
/// refers to that face's normal, whatever its corners' vertex normals; a rolled-back addition
/// is dropped.
#[test]
fn added_vertices_take_their_parents_maps_and_places() {
    // A thin fin: two faces folded back to 20° from each other on the edge 0-1, their
    // corners' vertex normals nearly along the edge's bisector.
    let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, 0.94, 0.34]];
    let tris = vec![[0, 1, 2], [1, 0, 3]];
    let mut o = Orientation::new(&pos, &tris);
    o.push(&pos, |v, _| if v == 1 { [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] } else { IDENTITY });
    let parents = vec![[(0, 0.25), (1, 0.25), (2, 0.5)], [(0, 0.5), (1, 0.5), (0, 0.0)]];
    o.sync(&parents);
    assert_eq!(o.len(), 6);
    assert_eq!(o.places[4], Place::Face(0));
    assert_eq!(o.places[5], Place::Edge(0, 1));
    assert!((o.jacobians[4][0][0] - 1.25).abs() < 1e-12 && (o.jacobians[5][0][0] - 1.5).abs() < 1e-12);
    // Face 0 split at vertex 4: each piece is in face 0 and compared with its normal.
    let mut at = pos.clone();
    at.push([0.5, 0.5, 0.0]);
    at.push([0.5, 0.0, 0.0]);
    let split = [[0, 1, 4], [1, 2, 4], [2, 0, 4]];
    assert_eq!(o.faces_against(&at, &split), 0);
    // The same pieces turned over are all counted.
    let turned: Vec<[u32; 3]> = split.iter().map(|t| [t[0], t[2], t[1]]).collect();
    assert_eq!(o.faces_against(&at, &turned), 3);
    o.sync(&parents[..1]);
    assert_eq!(o.len(), 5);
}

/// A face with normal `n` at `at` (edge length 1e-3).
fn face_with_normal(at: Point3, n: Point3) -> [Point3; 3] {
    let n = normalize(n);
    let helper = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let a = normalize(cross(helper, n));
    let b = cross(n, a);
    [at, add(at, scale(a, 1e-3)), add(at, scale(b, 1e-3))]
}

/// A field map pushed in single precision ([`Orientation::push_field`]) counts exactly what
/// the same map pushed in f64 counts, also for faces whose normal is within 1e-10 of
/// perpendicular to their reference (the bounds leave those open and the count replays them
/// exactly), and for faces on vertices added between two maps (replayed through their
/// parents) and after the last (blended).
#[test]
fn a_single_precision_field_counts_as_the_exact_one() {
    let (pos, tris) = sphere();
    let centres: Vec<Point3> = pos.iter().step_by(7).copied().collect();
    let values: Vec<Point3> =
        centres.iter().map(|p| [0.3 * p[1] * p[2], 0.2 * (3.0 * p[0]).sin(), -0.25 * p[0] * p[1]]).collect();
    let f = Arc::new(Rbf::fit(&centres, &values, crate::fit::rbf::Kernel::Linear, "test").unwrap());
    let progress = Progress::new();
    let (mut exact, mut approx) = (Orientation::new(&pos, &tris), Orientation::new(&pos, &tris));
    exact.push(&pos, |_, p| field_step(&f.gradient(p), 0.5));
    approx.push_field(&pos, f.clone(), 0.5, &progress).unwrap();
    // Midpoints of some edges, added between the two maps, then more after the last.
    let mut parents: Vec<[(u32, f64); 3]> =
        tris.iter().take(40).map(|t| [(t[0], 0.5), (t[1], 0.5), (t[2], 0.0)]).collect();
    exact.sync(&parents);
    approx.sync(&parents);
    let mut at = pos.clone();
    for p in &parents {
        at.push(scale(add(at[p[0].0 as usize], at[p[1].0 as usize]), 0.5));
    }
    exact.push(&at, |_, p| field_step(&f.gradient(p), 1.0));
    approx.push_field(&at, f.clone(), 1.0, &progress).unwrap();
    let nv = at.len() as u32;
    parents.extend((0..10u32).map(|i| [(nv - 1 - i, 0.25), (i, 0.75), (0, 0.0)]));
    exact.sync(&parents);
    approx.sync(&parents);
    let n = exact.len() as u32;
    // Faces on template vertices, on vertices added between the maps, and after them.
    let faces: Vec<[u32; 3]> =
        tris.iter().take(30).copied().chain((0..20).map(|i| [i, nv - 1 - i, n - 1 - i % 10])).collect();
    let (mut open, mut counted) = (0, 0);
    for t in &faces {
        // The exact reference, from the f64 push.
        let normals = exact.corner_normals(t);
        let mut r = [0.0; 3];
        for k in 0..3 {
            r = add(r, push_normal(&exact.jacobians[t[k] as usize], normals[k]));
        }
        let r = normalize(r);
        let side = normalize(cross(r, [0.3, -0.5, 0.8]));
        for sign in [-1.0, 1.0] {
            let mut out = vec![[0.0; 3]; n as usize];
            let corners = face_with_normal([0.1, 0.2, 0.3], add(side, scale(r, sign * 1e-10)));
            for k in 0..3 {
                out[t[k] as usize] = corners[k];
            }
            let truth = (sign < 0.0) as usize;
            assert_eq!(exact.faces_against(&out, &[*t]), truth, "f64 push, face {t:?}");
            assert_eq!(approx.faces_against(&out, &[*t]), truth, "f32 push, face {t:?}");
            let stored = |v: u32| (approx.jacobians[v as usize], approx.errors[v as usize]);
            open += (approx.decide(&out, t, stored) == Decision::Open) as usize;
            counted += truth;
        }
    }
    assert_eq!(open, 2 * faces.len(), "every such face is open under the single-precision bounds");
    assert_eq!(counted, faces.len());
    // Faces far from perpendicular: decided from the bounds, the same count.
    assert_eq!(approx.faces_against(&pos, &tris), exact.faces_against(&pos, &tris));
    assert_eq!(approx.faces_inverted(&tris), exact.faces_inverted(&tris));
}

/// cof(J)·n is the normal of the image of a face with normal n, and det J its volume factor.
#[test]
fn the_cofactor_maps_face_normals() {
    let j = [[1.2, -0.3, 0.5], [0.1, 0.9, -0.4], [0.7, 0.2, 1.1]];
    let (a, b) = ([1.0, 0.2, -0.1], [0.3, -0.8, 0.5]);
    let (c, det) = cofactor_times(&j, cross(a, b));
    let image = cross(apply(&j, a), apply(&j, b));
    assert!(norm(crate::geometry::sub(c, image)) < 1e-12);
    let by_hand =
        1.2 * (0.9 * 1.1 + 0.4 * 0.2) + 0.3 * (0.1 * 1.1 + 0.4 * 0.7) + 0.5 * (0.1 * 0.2 - 0.9 * 0.7);
    assert!((det - by_hand).abs() < 1e-12);
}
