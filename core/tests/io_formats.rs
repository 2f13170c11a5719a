//! PLY, STL, OFF: round trips, hand-written files in every variant, and content detection.

use meshwork_core::io::{self, detect, Format, ReadOptions};
use meshwork_core::mesh::{Faces, Mesh};
use meshwork_core::shapes;

fn read(bytes: &[u8]) -> io::Loaded {
    io::read(bytes, &ReadOptions::default()).expect("readable")
}

/// A mixed quad/triangle/pentagon mesh with awkward coordinates, normals and UVs.
fn mixed_mesh() -> Mesh {
    let mut m = shapes::torus(9, 5, 1.0, 0.25, true);
    m.positions[0] = [0.1 + 0.2, -1e-300, 1.0 / 3.0];
    m.positions[1] = [-0.0, 123456789.12345679, 5e-324];
    let mut faces = Faces::new();
    for f in m.faces.iter() {
        faces.push(f, 0);
    }
    faces.push(&[0, 1, 2], 0);
    faces.push(&[3, 4, 5, 6, 7], 0);
    m.faces = faces;
    m.normals = Some(m.positions.iter().map(|p| [p[0], -p[1], 0.5]).collect());
    m.uvs = Some((0..m.positions.len()).map(|i| [i as f64 / 3.0, 1.0 - i as f64 / 7.0]).collect());
    m
}

fn bits(m: &Mesh) -> Vec<[u64; 3]> {
    m.positions.iter().map(|p| p.map(f64::to_bits)).collect()
}

#[test]
fn ply_round_trip_is_exact() {
    let m = mixed_mesh();
    let b = io::write(&m, Format::Ply).unwrap();
    assert_eq!(detect(&b, None).unwrap(), Format::Ply);
    let back = read(&b).mesh;
    assert_eq!(bits(&back), bits(&m));
    assert_eq!(back.faces, m.faces);
    assert_eq!(back.normals, m.normals);
    assert_eq!(back.uvs, m.uvs);
}

#[test]
fn ply_wide_faces_use_uint_counts() {
    // A 300-gon cannot have a uchar count.
    let n = 300;
    let pos: Vec<[f64; 3]> = (0..n).map(|i| [(i as f64).cos(), (i as f64).sin(), 0.0]).collect();
    let mut f = Faces::new();
    f.push(&(0..n as u32).collect::<Vec<_>>(), 0);
    let m = Mesh::new(pos, f);
    let b = io::write(&m, Format::Ply).unwrap();
    assert!(String::from_utf8_lossy(&b[..200]).contains("property list uint uint vertex_indices"));
    assert_eq!(read(&b).mesh.faces, m.faces);
}

#[test]
fn off_round_trip_is_exact() {
    let mut m = mixed_mesh();
    m.uvs = None; // OFF keeps normals (NOFF), not UVs
    let b = io::write(&m, Format::Off).unwrap();
    assert!(b.starts_with(b"NOFF\n"));
    assert_eq!(detect(&b, None).unwrap(), Format::Off);
    let back = read(&b).mesh;
    assert_eq!(bits(&back), bits(&m));
    assert_eq!(back.faces, m.faces);
    assert_eq!(back.normals, m.normals);
}

#[test]
fn off_variants_and_comments() {
    // Hand-written: COFF with colours, counts on the header line, comments and blank lines.
    let src =
        "# a comment\nCOFF 4 2 0\n\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255 # trailing\n1 1 0 0 0 255 255\n\
               0 1 0 1 1 1 1\n3 0 1 2 0.5 0.5 0.5\n4 0 1 2 3\n";
    let l = read(src.as_bytes());
    assert_eq!(l.format, Format::Off);
    assert_eq!(l.mesh.positions, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(l.mesh.faces.get(0), &[0, 1, 2]);
    assert_eq!(l.mesh.faces.get(1), &[0, 1, 2, 3]);
}

#[test]
fn stl_binary_round_trip_welds_back_to_the_same_mesh() {
    // An icosphere (triangles) through STL: f32 positions, corners re-welded by exact position.
    let m = shapes::icosphere(2, 1.0);
    let b = io::write(&m, Format::Stl).unwrap();
    assert_eq!(b.len(), 84 + 50 * m.face_count());
    assert_eq!(detect(&b, None).unwrap(), Format::Stl);
    let l = read(&b);
    assert_eq!(l.mesh.vertex_count(), m.vertex_count());
    assert_eq!(l.mesh.faces.len(), m.faces.len());
    // Weld order is first use, so compare each triangle's corner positions (as f32).
    for (fa, fb) in m.faces.iter().zip(l.mesh.faces.iter()) {
        for (&a, &b) in fa.iter().zip(fb) {
            let pa = m.positions[a as usize].map(|c| c as f32 as f64);
            assert_eq!(pa, l.mesh.positions[b as usize]);
        }
    }
    let w = &l.warnings[0];
    assert!(
        w.contains(&format!(
            "welded {} facet corners into {} vertices",
            3 * m.face_count(),
            m.vertex_count()
        )),
        "{w}"
    );
}

#[test]
fn stl_fan_triangulates_polygons() {
    let m = shapes::grid(2, 2, 1.0, true); // 4 quads → 8 triangles
    let b = io::write(&m, Format::Stl).unwrap();
    let back = read(&b).mesh;
    assert_eq!(back.face_count(), 8);
    assert_eq!(back.vertex_count(), 9);
    // Normals written per triangle: +z for this counter-clockwise grid.
    let n: Vec<f32> =
        (0..3).map(|k| f32::from_le_bytes(b[84 + 4 * k..88 + 4 * k].try_into().unwrap())).collect();
    assert_eq!(n, vec![0.0, 0.0, 1.0]);
}

#[test]
fn stl_binary_starting_with_solid_is_binary() {
    let m = shapes::icosphere(0, 1.0);
    let mut b = io::write(&m, Format::Stl).unwrap();
    b[..5].copy_from_slice(b"solid");
    assert_eq!(detect(&b, None).unwrap(), Format::Stl);
    assert_eq!(read(&b).mesh.face_count(), 20);
}

#[test]
fn stl_ascii_hand_written() {
    let src = "solid tet\n facet normal 0 0 -1\n  outer loop\n   vertex 0 0 0\n   vertex 0 1 0\n   vertex 1 0 0\n\
               endloop\n endfacet\n facet normal 0 -1 0\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 0 1\n\
               endloop\n endfacet\nendsolid tet\n";
    for src in [src.to_string(), src.to_uppercase().replace("\n", "\r\n")] {
        let l = read(src.as_bytes());
        assert_eq!(l.format, Format::Stl);
        assert_eq!(
            l.mesh.positions,
            vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
        );
        assert_eq!(l.mesh.faces, Faces::from_triangles(&[[0, 1, 2], [0, 2, 3]]));
    }
}

#[test]
fn detection_by_content_then_name() {
    assert_eq!(detect(b"glTF\x02\0\0\0", None).unwrap(), Format::Glb);
    assert_eq!(detect(b"  {\"asset\": {\"version\": \"2.0\"}}", None).unwrap(), Format::Gltf);
    assert_eq!(detect(b"ply\r\nformat ascii 1.0\r\n", None).unwrap(), Format::Ply);
    assert_eq!(detect(b"# c\nv 1 2 3\n", None).unwrap(), Format::Obj);
    assert_eq!(detect(b"mtllib a.mtl\n", Some("x.ply")).unwrap(), Format::Obj);
    assert_eq!(detect(b"OFF\n0 0 0\n", None).unwrap(), Format::Off);
    assert_eq!(detect(b"solid x\nendsolid x\n", None).unwrap(), Format::Stl);
    // Content that matches nothing: the name decides, or it is unsupported.
    assert_eq!(detect(b"\x00\x01garbage", Some("mesh.stl")).unwrap(), Format::Stl);
    assert_eq!(detect(b"\x00\x01garbage", None).unwrap_err().kind(), "unsupported-format");
    assert_eq!(detect(b"", None).unwrap_err().kind(), "malformed-input");
}

#[test]
fn gltf_json_is_detected_and_read_through_io_read() {
    // The glTF writer's JSON output must come back through content detection (`{` + "asset").
    let m = shapes::icosphere(1, 1.0);
    let b = io::write(&m, Format::Gltf).unwrap();
    assert_eq!(detect(&b, None).unwrap(), Format::Gltf);
    let l = read(&b);
    assert_eq!(l.format, Format::Gltf);
    assert_eq!(l.mesh.vertex_count(), m.vertex_count());
    assert_eq!(l.mesh.faces, m.faces);
}
