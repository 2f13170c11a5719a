use super::*;
use crate::geometry::triangle_cross;

/// The fine surface's normals where it is the plane z = 0 seen from above.
const UP: [Point3; 8] = [[0.0, 0.0, 1.0]; 8];

/// A regular hexagon (radius 1, plane z = 0, counter-clockwise) around centre vertex 6.
fn hexagon_fan(centre: Point3) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let mut pos: Vec<Point3> = (0..6)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 6.0;
            [a.cos(), a.sin(), 0.0]
        })
        .collect();
    pos.push(centre);
    (pos, (0..6).map(|k| [k, (k + 1) % 6, 6]).collect())
}

fn up_faces(mesh: &TriMesh) -> usize {
    mesh.alive_faces().filter(|&f| mesh.face_normal(f)[2] > 0.0).count()
}

/// The centre at (0.9, 0.5) is beyond ring edge 0→1 only (by hand: cross((−0.5, 0.866), (−0.1,
/// 0.5)) = −0.163 < 0, the other five edges positive), so exactly face (0, 1, 6) points down
/// against the reference +z. Flipping its two inner edges leaves a face down (by hand: (2, 6, 0)
/// and (1, 6, 5) have cross −0.66 and −0.69), so the fix is the centre's move: to the ring's mean,
/// the origin, where all six faces point up. The ring is the boundary and never moves.
#[test]
fn a_face_turned_by_a_free_corner_is_turned_back_by_moving_it() {
    let (pos, tris) = hexagon_fan([0.9, 0.5, 0.0]);
    let mut mesh = TriMesh::new(pos.clone(), tris).unwrap();
    assert_eq!(up_faces(&mesh), 5);
    let mut reference = vec![[0.0, 0.0, 1.0]; 7];
    let fixed = [true, true, true, true, true, true, false];
    let s = repair_counted(&mut mesh, &mut reference, &UP, &fixed, &EdgeSet::default(), &Progress::new())
        .unwrap();
    assert_eq!((s.counted_before, s.fixed, s.left, s.vertex_moves, s.edge_flips), (1, 1, 0, 1, 0), "{s:?}");
    assert_eq!(up_faces(&mesh), 6);
    assert_eq!(&mesh.pos[..6], &pos[..6]);
    assert!(mesh.pos[6][0].abs() < 1e-12 && mesh.pos[6][1].abs() < 1e-12, "{:?}", mesh.pos[6]);
    assert_eq!(s.uv_batches.len(), 1);
}

/// The same with the report's own count: a template hexagon under the identity maps (the count's
/// reference is each template face's normal, +z), the output's centre moved as above. The
/// count says 1 before the pass and 0 after.
#[test]
fn the_reports_count_is_what_the_pass_lowers() {
    let (template, tris) = hexagon_fan([0.0, 0.0, 0.0]);
    let mut orientation = Orientation::new(&template, &tris);
    let (pos, _) = hexagon_fan([0.9, 0.5, 0.0]);
    let mut mesh = TriMesh::new(pos, tris.clone()).unwrap();
    assert_eq!(orientation.faces_against(&mesh.pos, &tris), 1);
    let fixed = [true, true, true, true, true, true, false];
    let s = repair_counted(&mut mesh, &mut orientation, &UP, &fixed, &EdgeSet::default(), &Progress::new())
        .unwrap();
    assert_eq!((s.counted_before, s.left), (1, 0), "{s:?}");
    assert_eq!(orientation.faces_against(&mesh.pos, &mesh.live_triangles()), 0);
}

/// Faces (0, 1, 2) up and (0, 2, 3) down (vertex 3 = (1, −0.3) on vertex 1's side of 0→2), all
/// vertices fixed: flipping 0–2 into 1–3 gives (3, 0, 1) and (1, 2, 3), both up (by hand: cross
/// 0.7 and 0.7). With two more down faces glued to (0, 2, 3) on its other edges (both locked, as
/// curve edges), the two new faces would each be folded against one of them (180°) where only
/// one edge was folded before: the pass leaves the face and counts the refusal.
#[test]
fn a_flip_is_made_unless_it_folds_a_neighbour() {
    let quad = vec![[0.0, 0.0, 0.0], [1.0, -1.0, 0.0], [2.0, 0.0, 0.0], [1.0, -0.3, 0.0]];
    let mut up = vec![[0.0, 0.0, 1.0]; 6];
    let mut mesh = TriMesh::new(quad.clone(), vec![[0, 1, 2], [0, 2, 3]]).unwrap();
    let s =
        repair_counted(&mut mesh, &mut up, &UP, &[true; 4], &EdgeSet::default(), &Progress::new()).unwrap();
    assert_eq!((s.counted_before, s.edge_flips, s.left, s.refused_fold), (1, 1, 0, 0), "{s:?}");
    assert!(mesh.has_edge(1, 3) && !mesh.has_edge(0, 2));
    assert_eq!(up_faces(&mesh), 2);

    // (3, 2, 4) and (0, 3, 5) point down (by hand: cross −0.545 each), glued along 3–2 and 0–3.
    let mut pos = quad.clone();
    pos.push([1.65, -0.65, 0.0]);
    pos.push([0.35, -0.65, 0.0]);
    let tris = vec![[0, 1, 2], [0, 2, 3], [3, 2, 4], [0, 3, 5]];
    let mut mesh = TriMesh::new(pos, tris).unwrap();
    assert_eq!(up_faces(&mesh), 1);
    let mut locked = EdgeSet::default();
    locked.insert((2, 3));
    locked.insert((0, 3));
    let s = repair_counted(&mut mesh, &mut up, &UP, &[true; 6], &locked, &Progress::new()).unwrap();
    assert_eq!((s.counted_before, s.edge_flips, s.vertex_moves, s.left), (3, 0, 0, 3), "{s:?}");
    assert!(s.refused_fold >= 1, "{s:?}");
    // Why, by hand: (0, 2, 3)'s only flip folds (the fold above); (3, 2, 4) and (0, 3, 5) have one
    // locked edge and two boundary edges, and every corner fixed: no edit to try.
    let w = &s.left_why;
    assert_eq!((w.fold, w.no_edit, w.floor, w.no_gain, w.all_corners_fixed), (1, 2, 0, 0, 3), "{s:?}");
    assert!(mesh.has_edge(0, 2) && !mesh.has_edge(1, 3));
    let n = triangle_cross(mesh.pos[0], mesh.pos[2], mesh.pos[3]);
    assert!(n[2] < 0.0);
}

/// The template hexagon under a mirror map (z ↦ −z, det J = −1 at every vertex): the count's
/// reference at each face is −z (J⁻ᵀ·(+z) = −z), so the five faces pointing up are counted. The
/// maps turned space inside out there, so the reference is reversed against the surface and the
/// pass must not "fix" them: nothing tried, nothing moved, all five reported as skipped.
#[test]
fn faces_where_the_maps_invert_space_are_left_and_reported() {
    let (template, tris) = hexagon_fan([0.0, 0.0, 0.0]);
    let mut orientation = Orientation::new(&template, &tris);
    orientation.push(&template, |_, _| [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]);
    let (pos, _) = hexagon_fan([0.9, 0.5, 0.0]);
    let mut mesh = TriMesh::new(pos.clone(), tris.clone()).unwrap();
    assert_eq!(orientation.faces_against(&mesh.pos, &tris), 5);
    let fixed = [true, true, true, true, true, true, false];
    let s = repair_counted(&mut mesh, &mut orientation, &UP, &fixed, &EdgeSet::default(), &Progress::new())
        .unwrap();
    assert_eq!((s.counted_before, s.skipped_inverted_by_maps, s.tried, s.left), (5, 5, 0, 5), "{s:?}");
    assert_eq!(mesh.pos, pos);
    assert_eq!(mesh.live_triangles(), tris);
}

/// a = (0, 0), b = (1, 0), c = (0.2, −0.1), d = (1.2, −0.9), all fixed: (a, b, c) points down
/// (cross −0.1), (b, a, d) up (cross 0.9). Flipping a–b gives (c, a, d) and (d, b, c), both up,
/// but (c, a, d) has a 1.79° corner at d (by hand: 10.30° at a, 167.91° at c), below the 2°
/// floor and the 7.13° (at b) of the faces it replaces: refused, and no corner may move. A new
/// vertex on a–b moved inside the quad c, a, d, b makes four faces up whose smallest angle can be
/// above 3° (a grid search by hand: 3.22° near (0.50, −0.31)).
fn sliver_quad() -> (Vec<Point3>, Vec<[u32; 3]>) {
    let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.2, -0.1, 0.0], [1.2, -0.9, 0.0]];
    (pos, vec![[0, 1, 2], [1, 0, 3]])
}

fn min_angle_of(mesh: &TriMesh) -> f64 {
    mesh.alive_faces()
        .map(|f| {
            let t = mesh.tris[f as usize];
            min_angle_deg(mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize])
        })
        .fold(180.0, f64::min)
}

#[test]
fn a_face_whose_flip_makes_a_sliver_is_split_instead() {
    let (pos, tris) = sliver_quad();
    let mut mesh = TriMesh::new(pos.clone(), tris).unwrap();
    assert_eq!(up_faces(&mesh), 1);
    let mut up = vec![[0.0, 0.0, 1.0]; 4];
    let s =
        repair_counted(&mut mesh, &mut up, &UP, &[true; 4], &EdgeSet::default(), &Progress::new()).unwrap();
    assert_eq!(
        (s.counted_before, s.edge_flips, s.vertex_moves, s.edge_splits, s.left),
        (1, 0, 0, 1, 0),
        "{s:?}"
    );
    assert!(s.refused_floor >= 1, "{s:?}");
    assert_eq!((mesh.pos.len(), mesh.live_faces(), up_faces(&mesh)), (5, 4, 4));
    assert_eq!(&mesh.pos[..4], &pos[..]);
    // The quad's outline is kept, a–b is gone, the new vertex is joined to all four corners.
    for (x, y) in [(2, 0), (1, 2), (3, 1), (0, 3), (4, 0), (4, 1), (4, 2), (4, 3)] {
        assert!(mesh.face_with_edge(x, y).is_some(), "edge {x}→{y}");
    }
    assert!(!mesh.has_edge(0, 1));
    assert!(min_angle_of(&mesh) >= MIN_ANGLE_FLOOR_DEG, "{}", min_angle_of(&mesh));
    assert_eq!(s.added, vec![[(0, 0.5), (1, 0.5), (0, 0.0)]]);
    assert_eq!(up.len(), 5);
    assert_eq!(s.uv_batches.len(), 1);
    assert_eq!(s.uv_batches[0][0].vertex, 4);
}

/// The same under the report's own count: the template is the quad with c above a–b, (0.2, 0.1),
/// all faces up; identity maps. The output's c below a–b is counted (1), the split leaves 0, and
/// the count knows the new vertex (its maps blended from a and b).
#[test]
fn the_reports_count_follows_a_split() {
    let (pos, tris) = sliver_quad();
    let mut template = pos.clone();
    template[2] = [0.2, 0.1, 0.0];
    let mut orientation = Orientation::new(&template, &tris);
    let mut mesh = TriMesh::new(pos, tris.clone()).unwrap();
    assert_eq!(orientation.faces_against(&mesh.pos, &tris), 1);
    let s =
        repair_counted(&mut mesh, &mut orientation, &UP, &[true; 4], &EdgeSet::default(), &Progress::new())
            .unwrap();
    assert_eq!((s.counted_before, s.edge_splits, s.left), (1, 1, 0), "{s:?}");
    assert_eq!(orientation.len(), 5);
    assert_eq!(orientation.faces_against(&mesh.pos, &mesh.live_triangles()), 0);
}

/// The sliver quad again, but the fine surface says the quad is seen from below (normals −z):
/// the four faces of the split would all oppose it. The split is refused and the face left.
#[test]
fn a_split_that_turns_more_faces_against_the_fine_surface_is_refused() {
    let (pos, tris) = sliver_quad();
    let mut mesh = TriMesh::new(pos.clone(), tris.clone()).unwrap();
    let mut up = vec![[0.0, 0.0, 1.0]; 4];
    let down = [[0.0, 0.0, -1.0]; 4];
    let s =
        repair_counted(&mut mesh, &mut up, &down, &[true; 4], &EdgeSet::default(), &Progress::new()).unwrap();
    assert_eq!((s.counted_before, s.edge_splits, s.left), (1, 0, 1), "{s:?}");
    assert!(s.refused_surface >= 1, "{s:?}");
    assert_eq!((mesh.live_triangles(), mesh.pos, up.len()), (tris, pos, 4));
}

/// The sliver quad with every split refused (the fine surface points down, so the split's four
/// up faces oppose it) and no corner free: the flip's 1.79° corner is below the 2° floor, so the
/// face is left while the mesh has no thinner face (smallest 7.13°, above the floor: the last
/// passes do not run). With a thin triangle elsewhere (its base angles atan(0.005 / 0.5) = 0.573°
/// by hand), the last passes accept the flip: its faces are no thinner than the mesh already was,
/// and the mesh's smallest angle stays 0.573°.
#[test]
fn a_flip_below_the_floor_is_made_when_the_mesh_is_already_thinner() {
    let down = vec![[0.0, 0.0, -1.0]; 7];
    let (pos, tris) = sliver_quad();
    let mut mesh = TriMesh::new(pos.clone(), tris.clone()).unwrap();
    let mut up = vec![[0.0, 0.0, 1.0]; 4];
    let s =
        repair_counted(&mut mesh, &mut up, &down, &[true; 4], &EdgeSet::default(), &Progress::new()).unwrap();
    assert_eq!((s.counted_before, s.left, s.edge_flips, s.edge_splits), (1, 1, 0, 0), "{s:?}");
    assert_eq!((s.last_resort_floor_deg, s.fixed_at_last_resort), (None, 0), "{s:?}");
    assert!(s.refused_floor >= 1 && s.refused_surface >= 1, "{s:?}");
    assert_eq!(mesh.live_triangles(), tris);

    let mut pos = pos;
    pos.extend([[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.5, 0.005, 0.0]]);
    let mut tris = tris;
    tris.push([4, 5, 6]);
    let mut mesh = TriMesh::new(pos.clone(), tris).unwrap();
    let thin = min_angle_of(&mesh);
    assert!((thin - 0.005f64.atan2(0.5).to_degrees()).abs() < 1e-9, "{thin}");
    let mut up = vec![[0.0, 0.0, 1.0]; 7];
    let s =
        repair_counted(&mut mesh, &mut up, &down, &[true; 7], &EdgeSet::default(), &Progress::new()).unwrap();
    assert_eq!((s.counted_before, s.left, s.edge_flips, s.fixed_at_last_resort), (1, 0, 1, 1), "{s:?}");
    assert!((s.last_resort_floor_deg.unwrap() - thin).abs() < 1e-12, "{s:?}");
    assert_eq!(up_faces(&mesh), 3);
    assert!(mesh.has_edge(2, 3) && !mesh.has_edge(0, 1));
    assert!((min_angle_of(&mesh) - thin).abs() < 1e-9, "{}", min_angle_of(&mesh));
    assert_eq!(mesh.pos, pos);
}

/// The flip search's collinear case (`untangle::flip_search::tests::collinear_overlap`) under the count:
/// a = (0, 0), m = (1, 0), b = (2, 0) on one line, a–m and b–c3 curve edges, every vertex fixed;
/// face (a, m, c1) points down (doubled signed area −1.2, by hand) under (c1, b, a). Its one flip
/// (a–c1) gives the zero-area (m, a, b), its corners cannot move, and a split is refused (the fine
/// surface is given pointing down, so every split face opposes it): no single edit. Two flips
/// (a–c1, then the zero-area face's long edge a–b) end with every face up, and a triangulation of
/// the same hexagon (total area 8.8 by the shoelace formula); the curve edges stay.
#[test]
fn a_face_no_single_edit_fixes_is_fixed_by_a_flip_sequence() {
    let (pos, tris) = crate::fit::untangle::flip_search::tests::collinear_overlap();
    let (a, m, b, c3) = (0, 1, 2, 6);
    let mut mesh = TriMesh::new(pos.clone(), tris).unwrap();
    assert_eq!(up_faces(&mesh), 9);
    let mut locked = EdgeSet::default();
    locked.insert((a, m));
    locked.insert((b, c3));
    let mut up = vec![[0.0, 0.0, 1.0]; 9];
    let down = vec![[0.0, 0.0, -1.0]; 9];
    let s = repair_counted(&mut mesh, &mut up, &down, &[true; 9], &locked, &Progress::new()).unwrap();
    assert_eq!((s.counted_before, s.edge_flips, s.vertex_moves, s.edge_splits), (1, 0, 0, 0), "{s:?}");
    assert_eq!((s.flip_sequences, s.sequence_flips, s.left, s.fixed), (1, 2, 0, 1), "{s:?}");
    assert_eq!((mesh.live_faces(), up_faces(&mesh)), (10, 10));
    assert!(mesh.has_edge(a, m) && mesh.has_edge(b, c3), "a curve edge was flipped away");
    assert_eq!(mesh.pos, pos);
    let area: f64 = mesh
        .live_triangles()
        .iter()
        .map(|t| {
            triangle_cross(mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize])[2] / 2.0
        })
        .sum();
    assert!((area - 8.8).abs() < 1e-12, "{area}");
}

/// A face keeps its key under a rotation of its corners (a flip sequence re-writes a face it
/// leaves as it was with any first corner, under a new id); the reversed face is another face.
#[test]
fn a_face_key_is_its_oriented_triangle() {
    let k = FaceKey::of([7, 3, 5]);
    assert_eq!(k, FaceKey([3, 5, 7]));
    assert_eq!(FaceKey::of([3, 5, 7]), k);
    assert_eq!(FaceKey::of([5, 7, 3]), k);
    assert_ne!(FaceKey::of([7, 5, 3]), k);
    assert_eq!(FaceKey::of([7, 5, 3]), FaceKey([3, 7, 5]));
}
