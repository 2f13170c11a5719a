//! write → read round trips through GLB and glTF JSON: positions equal to the input rounded to
//! f32, the same triangles (polygons come back fan-triangulated), the same face groups by name,
//! the same curves, normals and uvs.

use meshwork_core::io::gltf::{read, write_glb, write_gltf};
use meshwork_core::io::{Format, ReadOptions};
use meshwork_core::mesh::{Faces, Mesh};
use meshwork_core::shapes;

fn f32_round(p: [f64; 3]) -> [f64; 3] {
    p.map(|c| c as f32 as f64)
}

/// Both encodings, read back.
fn round_trips(mesh: &Mesh) -> Vec<(Format, Mesh, Vec<String>)> {
    let opts = ReadOptions::default();
    let glb = read(&write_glb(mesh).unwrap(), &opts).unwrap();
    let gltf = read(&write_gltf(mesh).unwrap(), &opts).unwrap();
    assert_eq!(glb.format, Format::Glb);
    assert_eq!(gltf.format, Format::Gltf);
    vec![(glb.format, glb.mesh, glb.warnings), (gltf.format, gltf.mesh, gltf.warnings)]
}

/// (group name, triangle) for every face, sorted: the partition independent of face order.
fn named_faces(m: &Mesh) -> Vec<(String, Vec<u32>)> {
    let mut v: Vec<_> = (0..m.face_count())
        .map(|i| (m.group_name(m.faces.group(i)).to_owned(), m.faces.get(i).to_vec()))
        .collect();
    v.sort();
    v
}

#[test]
fn triangle_mesh_is_identical_up_to_f32() {
    // Radius 1/3: coordinates that are not exact in f32, so the rounding is visible.
    let mesh = shapes::icosphere(2, 1.0 / 3.0);
    for (format, back, warnings) in round_trips(&mesh) {
        assert!(warnings.is_empty(), "{format:?}: {warnings:?}");
        let expected: Vec<_> = mesh.positions.iter().map(|&p| f32_round(p)).collect();
        assert_eq!(back.positions, expected, "{format:?}");
        assert_ne!(back.positions, mesh.positions, "coordinates should have been rounded to f32");
        assert_eq!(back.faces, mesh.faces, "{format:?}");
        assert!(back.groups.is_empty(), "{format:?}: an unnamed mesh stays unnamed, got {:?}", back.groups);
        assert!(back.normals.is_none() && back.uvs.is_none() && back.curves.is_empty());
    }
}

#[test]
fn quads_come_back_fan_triangulated() {
    let mesh = shapes::torus(12, 8, 2.0, 0.5, true);
    assert!(!mesh.faces.all_triangles());
    let fans = shapes::fan_triangles(&mesh.faces);
    for (format, back, _) in round_trips(&mesh) {
        assert_eq!(
            back.faces.as_triangles().unwrap().chunks(3).map(|t| [t[0], t[1], t[2]]).collect::<Vec<_>>(),
            fans,
            "{format:?}"
        );
        assert_eq!(back.positions.len(), mesh.positions.len());
    }
}

fn two_groups_and_curves() -> Mesh {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mut faces = Faces::new();
    // Interleaved groups: the writer emits one primitive per group.
    faces.push(&[0, 1, 2], 0);
    faces.push(&[1, 4, 5, 3], 1);
    faces.push(&[1, 3, 2], 0);
    let mut m = Mesh::new(positions, faces);
    m.groups = vec!["left".into(), "right side".into()];
    m.curves = vec![vec![0, 6, 2], vec![4, 5]];
    m.normals = Some(vec![[0.0, 0.0, 2.0]; 7]);
    m.uvs = Some((0..7).map(|i| [i as f64 / 7.0, 0.25]).collect());
    m
}

#[test]
fn groups_curves_normals_and_uvs_survive() {
    let mesh = two_groups_and_curves();
    let expected_faces = vec![
        ("left".to_owned(), vec![0, 1, 2]),
        ("left".to_owned(), vec![1, 3, 2]),
        // the quad (1, 4, 5, 3) as a fan from its first vertex
        ("right side".to_owned(), vec![1, 4, 5]),
        ("right side".to_owned(), vec![1, 5, 3]),
    ];
    for (format, back, warnings) in round_trips(&mesh) {
        assert!(warnings.is_empty(), "{format:?}: {warnings:?}");
        assert_eq!(back.positions, mesh.positions, "{format:?}: small integers are exact in f32");
        assert_eq!(named_faces(&back), expected_faces, "{format:?}");
        let mut names = back.groups.clone();
        names.sort();
        assert_eq!(names, ["left", "right side"]);
        assert_eq!(back.curves, mesh.curves, "{format:?}");
        // Normals are written normalised (glTF requires unit normals).
        assert_eq!(back.normals.as_deref(), Some(&[[0.0, 0.0, 1.0]; 7][..]), "{format:?}");
        let uvs = back.uvs.as_ref().unwrap();
        for (a, b) in uvs.iter().zip(mesh.uvs.as_ref().unwrap()) {
            assert!((a[0] - b[0]).abs() < 1e-7 && (a[1] - b[1]).abs() < 1e-7, "{format:?}: {a:?} vs {b:?}");
        }
    }
}

#[test]
fn curves_only_and_points_only() {
    let mut curves = Mesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]], Faces::new());
    curves.curves = vec![vec![0, 1, 2, 0]];
    for (format, back, _) in round_trips(&curves) {
        assert_eq!(back.curves, curves.curves, "{format:?}");
        assert_eq!(back.positions, curves.positions);
        assert_eq!(back.face_count(), 0);
    }
    // A point cloud is written as POINTS, which the reader skips and says so.
    let points = Mesh::new(vec![[0.0; 3], [1.0, 2.0, 3.0]], Faces::new());
    for (format, back, warnings) in round_trips(&points) {
        assert_eq!(back.vertex_count(), 0, "{format:?}");
        assert!(warnings.iter().any(|w| w.contains("POINTS")), "{format:?}: {warnings:?}");
    }
}

#[test]
fn empty_mesh_round_trips_to_empty() {
    for (_, back, _) in round_trips(&Mesh::default()) {
        assert_eq!(back, Mesh::default());
    }
}

#[test]
fn big_mesh_uses_u32_indices_and_round_trips() {
    // > 65535 vertices forces 32-bit indices.
    let mesh = shapes::triangle_grid(300, 240, 0.01);
    assert!(mesh.vertex_count() > 65_535);
    for (format, back, _) in round_trips(&mesh) {
        assert_eq!(back.faces, mesh.faces, "{format:?}");
        assert_eq!(back.vertex_count(), mesh.vertex_count());
    }
}

#[test]
fn out_of_f32_range_coordinates_are_refused_by_the_writer() {
    let mesh = Mesh::from_triangles(vec![[0.0; 3], [1e300, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]]);
    let err = write_glb(&mesh).unwrap_err();
    assert_eq!(err.kind(), "invalid-mesh", "{err}");
    assert!(err.to_string().contains("vertex 1"), "{err}");
}

#[test]
fn generic_io_detects_both_encodings() {
    use meshwork_core::io;
    let mesh = shapes::icosphere(1, 1.0);
    for format in [Format::Glb, Format::Gltf] {
        let bytes = io::write(&mesh, format).unwrap();
        let loaded = io::read(&bytes, &ReadOptions::default()).unwrap();
        assert_eq!(loaded.format, format);
        assert_eq!(loaded.mesh.faces, mesh.faces);
    }
}

#[test]
fn faces_gltf_cannot_hold_are_an_error_not_a_silent_drop() {
    let mut faces = Faces::new();
    faces.push(&[0, 1, 2], 0);
    faces.push(&[1, 2], 0);
    let mesh = Mesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], faces);
    let err = write_glb(&mesh).unwrap_err();
    assert!(
        matches!(
            &err,
            meshwork_core::Error::InvalidMesh { location: meshwork_core::error::Location::Face(1), .. }
        ),
        "{err}"
    );
}
