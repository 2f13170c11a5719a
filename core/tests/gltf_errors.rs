//! Broken glTF/GLB inputs: each gives the right error kind at the right place, never a panic,
//! and declared sizes are never trusted for allocation.

mod gltf_support;

use gltf_support::*;
use meshwork_core::error::{Error, Location};
use meshwork_core::io::gltf::{read, write_glb};
use meshwork_core::io::ReadOptions;
use serde_json::{json, Value};

fn err(bytes: &[u8]) -> Error {
    match read(bytes, &ReadOptions::default()) {
        Ok(l) => panic!("expected an error, read {} vertices", l.mesh.vertex_count()),
        Err(e) => e,
    }
}

fn at_path(e: &Error) -> String {
    match e {
        Error::Malformed { location: Location::Gltf(p), .. }
        | Error::InvalidMesh { location: Location::Gltf(p), .. }
        | Error::ExternalReference { location: Location::Gltf(p), .. } => p.clone(),
        other => panic!("expected a glTF path, got {other:?}"),
    }
}

fn at_byte(e: &Error) -> usize {
    match e {
        Error::Malformed { location: Location::Byte(b), .. } => *b,
        other => panic!("expected a byte offset, got {other:?}"),
    }
}

/// A valid one-triangle GLB (u16 indices) and its parts, to break one thing at a time.
fn triangle() -> (Bin, Value) {
    let mut bin = Bin::default();
    let pos = bin.view(&f32s(&FIVE_POINTS[..9]));
    let idx = bin.view(&u16s(&[0, 1, 2]));
    let d = doc(
        &bin,
        json!({
            "accessors": [vec3_accessor(pos, 3), { "bufferView": idx, "componentType": 5123, "count": 3, "type": "SCALAR" }],
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
            "nodes": [{ "mesh": 0 }],
            "scenes": [{ "nodes": [0] }],
            "scene": 0
        }),
    );
    (bin, d)
}

fn with(change: impl FnOnce(&mut Value, &mut Bin)) -> Vec<u8> {
    let (mut bin, mut d) = triangle();
    change(&mut d, &mut bin);
    glb(&d, &bin.bytes)
}

#[test]
fn the_base_file_is_valid() {
    let (bin, d) = triangle();
    let l = read(&glb(&d, &bin.bytes), &ReadOptions::default()).unwrap();
    assert_eq!(l.mesh.face_count(), 1);
}

#[test]
fn truncated_glb_names_the_end_offset() {
    let f = with(|_, _| {});
    for cut in [0, 5, 11, 12, 19, 30, f.len() - 1] {
        let e = err(&f[..cut]);
        assert_eq!(e.kind(), "malformed-input", "cut at {cut}: {e}");
        // A file shorter than its header's length is reported where it ends.
        if cut >= 12 {
            assert_eq!(at_byte(&e), cut, "{e}");
        }
    }
}

#[test]
fn bad_json_chunk() {
    let mut f = with(|_, _| {});
    f[20] = b'!';
    let e = err(&f);
    assert_eq!(at_byte(&e), 20, "{e}");
    assert!(e.to_string().contains("JSON"), "{e}");
}

#[test]
fn chunk_length_lying() {
    let f = with(|_, _| {});
    let json_len = u32::from_le_bytes(f[12..16].try_into().unwrap()) as usize;
    let bin_header = 20 + json_len;
    let mut lie = f.clone();
    lie[bin_header..bin_header + 4].copy_from_slice(&(1u32 << 30).to_le_bytes());
    assert_eq!(at_byte(&err(&lie)), bin_header);
    let mut lie = f;
    lie[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_eq!(at_byte(&err(&lie)), 12);
}

#[test]
fn buffer_longer_than_bin_chunk() {
    let e = err(&with(|d, _| d["buffers"][0]["byteLength"] = json!(1000)));
    assert_eq!(at_path(&e), "buffers[0].byteLength", "{e}");
}

#[test]
fn index_out_of_range() {
    let e = err(&with(|d, bin| {
        let v = bin.view(&u16s(&[0, 1, 7]));
        d["bufferViews"] = json!(bin.views);
        d["buffers"][0]["byteLength"] = json!(bin.bytes.len());
        d["accessors"][1]["bufferView"] = json!(v);
    }));
    assert_eq!(e.kind(), "invalid-mesh");
    assert_eq!(at_path(&e), "meshes[0].primitives[0].indices", "{e}");
    assert!(e.to_string().contains("is 7"), "{e}");
}

#[test]
fn references_out_of_range() {
    let e = err(&with(|d, _| d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(9)));
    assert_eq!(at_path(&e), "meshes[0].primitives[0].attributes.POSITION", "{e}");
    let e = err(&with(|d, _| d["accessors"][0]["bufferView"] = json!(5)));
    assert_eq!(at_path(&e), "accessors[0].bufferView", "{e}");
    let e = err(&with(|d, _| d["nodes"][0]["mesh"] = json!(3)));
    assert_eq!(at_path(&e), "nodes[0].mesh", "{e}");
    let e = err(&with(|d, _| d["scene"] = json!(1)));
    assert_eq!(at_path(&e), "scene", "{e}");
    let e = err(&with(|d, _| d["bufferViews"][1]["buffer"] = json!(1)));
    assert_eq!(at_path(&e), "bufferViews[1].buffer", "{e}");
}

#[test]
fn external_uri_is_refused_not_opened() {
    for uri in
        ["triangle.bin", "/etc/passwd", "https://example.com/a.bin", "file:///tmp/x.bin", "../../secret"]
    {
        let e = err(&with(|d, _| d["buffers"][0]["uri"] = json!(uri)));
        assert_eq!(e.kind(), "external-reference", "{uri}: {e}");
        assert_eq!(at_path(&e), "buffers[0].uri");
    }
    // The refusal does not depend on the file existing.
    let e = err(&with(|d, _| d["buffers"][0]["uri"] = json!("Cargo.toml")));
    assert_eq!(e.kind(), "external-reference");
}

#[test]
fn bad_data_uri() {
    let e = err(&with(|d, _| d["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,AAA*")));
    assert_eq!(at_path(&e), "buffers[0].uri");
    assert!(e.to_string().contains("character 3"), "{e}");
    let e = err(&with(|d, _| d["buffers"][0]["uri"] = json!("data:text/plain,hello")));
    assert_eq!(at_path(&e), "buffers[0].uri");
}

#[test]
fn accessor_past_its_buffer_view() {
    let e = err(&with(|d, _| d["accessors"][0]["count"] = json!(4)));
    assert_eq!(at_path(&e), "accessors[0]", "{e}");
    let e = err(&with(|d, _| d["accessors"][0]["byteOffset"] = json!(4)));
    assert_eq!(at_path(&e), "accessors[0]", "{e}");
    let e = err(&with(|d, _| d["bufferViews"][0]["byteLength"] = json!(10_000)));
    assert_eq!(at_path(&e), "bufferViews[0]", "{e}");
}

#[test]
fn huge_counts_are_refused_before_allocating() {
    // count × stride overflows u64: checked arithmetic, no allocation.
    let e = err(&with(|d, bin| {
        d["accessors"][0]["count"] = json!(u64::MAX / 4);
        bin.views[0]["byteStride"] = json!(252);
        d["bufferViews"] = json!(bin.views);
    }));
    assert_eq!(at_path(&e), "accessors[0]", "{e}");
    let e = err(&with(|d, _| d["accessors"][1]["count"] = json!(4_000_000_000u64)));
    assert_eq!(at_path(&e), "accessors[1]", "{e}");
    // No buffer view: nothing backs the count, the reader's limit applies.
    let e = err(&with(|d, _| {
        d["accessors"][0] = json!({ "componentType": 5126, "count": 1_000_000_000_000u64, "type": "VEC3" });
    }));
    assert_eq!(e.kind(), "too-large", "{e}");
    // Sparse count larger than the accessor.
    let e = err(&with(|d, _| {
        d["accessors"][0]["sparse"] = json!({ "count": 99, "indices": { "bufferView": 1, "componentType": 5123 }, "values": { "bufferView": 0 } });
    }));
    assert_eq!(at_path(&e), "accessors[0].sparse.count", "{e}");
}

#[test]
fn max_vertices_limit() {
    let (bin, d) = triangle();
    let opts = ReadOptions { max_vertices: 2, ..Default::default() };
    let e = read(&glb(&d, &bin.bytes), &opts).unwrap_err();
    assert_eq!(e.kind(), "too-large", "{e}");
}

#[test]
fn wrong_component_type_for_indices() {
    let e = err(&with(|d, bin| {
        let v = bin.view(&f32s(&[0., 1., 2.]));
        d["bufferViews"] = json!(bin.views);
        d["buffers"][0]["byteLength"] = json!(bin.bytes.len());
        d["accessors"][1]["bufferView"] = json!(v);
        d["accessors"][1]["componentType"] = json!(5126);
    }));
    assert_eq!(at_path(&e), "meshes[0].primitives[0].indices", "{e}");
    assert!(e.to_string().contains("FLOAT"), "{e}");
    let e = err(&with(|d, _| d["accessors"][1]["componentType"] = json!(5122)));
    assert_eq!(at_path(&e), "meshes[0].primitives[0].indices", "{e}");
    let e = err(&with(|d, _| d["accessors"][1]["componentType"] = json!(1234)));
    assert_eq!(at_path(&e), "accessors[1].componentType", "{e}");
}

#[test]
fn wrong_attribute_type() {
    let e = err(&with(|d, _| d["accessors"][0]["type"] = json!("VEC2")));
    assert_eq!(at_path(&e), "meshes[0].primitives[0].attributes.POSITION", "{e}");
}

#[test]
fn nan_and_infinite_positions() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let e = err(&with(|d, bin| {
            let v = bin.view(&f32s(&[0., 0., 0., 1., bad, 0., 0., 1., 0.]));
            d["bufferViews"] = json!(bin.views);
            d["buffers"][0]["byteLength"] = json!(bin.bytes.len());
            d["accessors"][0]["bufferView"] = json!(v);
        }));
        assert_eq!(e.kind(), "invalid-mesh", "{e}");
        assert_eq!(at_path(&e), "accessors[0]", "{e}");
        assert!(e.to_string().contains("element 1"), "{e}");
    }
}

#[test]
fn node_cycles_and_second_parents() {
    let e = err(&with(|d, _| {
        d["nodes"] = json!([{ "mesh": 0, "children": [1] }, { "children": [0] }]);
    }));
    assert!(at_path(&e).contains("children"), "{e}");
    let e = err(&with(|d, _| {
        d["nodes"] = json!([{ "children": [2] }, { "children": [2] }, { "mesh": 0 }]);
        d["scenes"] = json!([{ "nodes": [0, 1] }]);
    }));
    assert!(e.to_string().contains("reached twice"), "{e}");
    // Without a scene, a pure cycle has no root: nothing is read, and that is not a crash.
    let (bin, mut d) = triangle();
    d["nodes"] = json!([{ "mesh": 0, "children": [1] }, { "children": [0] }]);
    d.as_object_mut().unwrap().remove("scene");
    d.as_object_mut().unwrap().remove("scenes");
    let l = read(&glb(&d, &bin.bytes), &ReadOptions::default()).unwrap();
    assert_eq!(l.mesh.vertex_count(), 0);
}

#[test]
fn bad_transforms_and_modes() {
    let e = err(&with(|d, _| d["nodes"][0]["matrix"] = json!([1, 0, 0])));
    assert_eq!(at_path(&e), "nodes[0].matrix", "{e}");
    let e = err(&with(|d, _| d["nodes"][0]["rotation"] = json!([0, 0, 0, 0])));
    assert_eq!(at_path(&e), "nodes[0].rotation", "{e}");
    let e = err(&with(|d, _| d["meshes"][0]["primitives"][0]["mode"] = json!(9)));
    assert_eq!(at_path(&e), "meshes[0].primitives[0].mode", "{e}");
    let e = err(&with(|d, _| d["accessors"][0]["count"] = json!(-3)));
    assert_eq!(at_path(&e), "accessors[0].count", "{e}");
}

#[test]
fn unsupported_versions_and_compression() {
    let e = err(&with(|d, _| d["asset"]["version"] = json!("1.0")));
    assert_eq!(e.kind(), "unsupported-format", "{e}");
    let e = err(&with(|d, _| d["extensionsRequired"] = json!(["KHR_draco_mesh_compression"])));
    assert_eq!(e.kind(), "unsupported-format", "{e}");
    let e = err(&with(|d, _| {
        d.as_object_mut().unwrap().remove("asset");
    }));
    assert_eq!(at_path(&e), "asset", "{e}");
}

#[test]
fn gltf_json_syntax_error_names_the_line() {
    let e = err(b"{\n  \"asset\": {\"version\": \"2.0\"},\n  \"meshes\": [,]\n}");
    match e {
        Error::Malformed { location: Location::Line(3), .. } => {}
        other => panic!("expected line 3, got {other:?}"),
    }
}

/// Tiny deterministic generator (xorshift) for the fuzz loop.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
}

#[test]
fn truncations_and_bit_flips_never_panic() {
    let mut mesh = meshwork_core::shapes::icosphere(1, 1.0);
    mesh.curves = vec![vec![0, 1, 2]];
    let good = write_glb(&mesh).unwrap();
    let opts = ReadOptions::default();
    let mut outcomes = [0usize; 2];
    for cut in 0..good.len() {
        outcomes[read(&good[..cut], &opts).is_ok() as usize] += 1;
    }
    assert_eq!(outcomes[1], 0, "every truncation of a GLB must be refused");
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for _ in 0..3000 {
        let mut f = good.clone();
        for _ in 0..1 + rng.next() % 4 {
            let i = (rng.next() % f.len() as u64) as usize;
            f[i] ^= 1 << (rng.next() % 8);
        }
        // Any outcome but a panic is fine; a success must still be a consistent mesh.
        if let Ok(l) = read(&f, &opts) {
            l.mesh.check().unwrap();
        }
    }
}

/// Every number in a JSON tree, by pointer.
fn number_pointers(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Number(_) => out.push(at),
        Value::Array(a) => {
            a.iter().enumerate().for_each(|(i, x)| number_pointers(x, format!("{at}/{i}"), out))
        }
        Value::Object(o) => o.iter().for_each(|(k, x)| number_pointers(x, format!("{at}/{k}"), out)),
        _ => {}
    }
}

#[test]
fn mutated_json_numbers_never_panic() {
    // Structure-aware fuzzing: the JSON stays valid, its numbers (indices, counts, offsets,
    // strides, component types, modes) take hostile values.
    let (bin, mut d) = triangle();
    d["accessors"][0]["sparse"] = json!({ "count": 1, "indices": { "bufferView": 1, "componentType": 5123 }, "values": { "bufferView": 0 } });
    d["meshes"][0]["primitives"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "attributes": { "POSITION": 0 }, "indices": 1, "mode": 5 }));
    d["nodes"] = json!([{ "children": [1], "scale": [1, 2, 3] }, { "mesh": 0, "rotation": [0, 0, 0, 1] }]);
    let mut pointers = Vec::new();
    number_pointers(&d, String::new(), &mut pointers);
    let hostile = [
        json!(0),
        json!(1),
        json!(2),
        json!(3),
        json!(4),
        json!(7),
        json!(255),
        json!(5121),
        json!(5126),
        json!(65535),
        json!(1u64 << 31),
        json!((1u64 << 32) + 1),
        json!(u64::MAX),
        json!(-1),
        json!(1e300),
        json!(0.5),
    ];
    let opts = ReadOptions::default();
    let mut rng = Rng(0xDEAD_BEEF_CAFE_F00D);
    let mut refused = 0;
    for _ in 0..4000 {
        let mut m = d.clone();
        for _ in 0..1 + rng.next() % 2 {
            let p = &pointers[(rng.next() % pointers.len() as u64) as usize];
            *m.pointer_mut(p).unwrap() = hostile[(rng.next() % hostile.len() as u64) as usize].clone();
        }
        match read(&glb(&m, &bin.bytes), &opts) {
            Ok(l) => l.mesh.check().unwrap(),
            Err(e) => {
                assert_ne!(e.kind(), "internal", "{e}");
                refused += 1;
            }
        }
    }
    assert!(refused > 1000, "most mutations should be refused, only {refused} were");
}

#[test]
fn reused_accessors_are_bounded_by_the_limits() {
    // 200 LINE_STRIP primitives all reusing one 3-index accessor: 200 × 4 curve entries > a limit of 3 × 100.
    let (bin, mut d) = triangle();
    d["meshes"][0]["primitives"] =
        json!(vec![json!({ "attributes": { "POSITION": 0 }, "indices": 1, "mode": 3 }); 200]);
    let opts = ReadOptions { max_faces: 100, ..Default::default() };
    let e = read(&glb(&d, &bin.bytes), &opts).unwrap_err();
    assert_eq!(e.kind(), "too-large", "{e}");
    // The same with TRIANGLES: 200 faces > 100.
    d["meshes"][0]["primitives"] = json!(vec![json!({ "attributes": { "POSITION": 0 }, "indices": 1 }); 200]);
    let e = read(&glb(&d, &bin.bytes), &opts).unwrap_err();
    assert_eq!(e.kind(), "too-large", "{e}");
    // Within the limits, both read fine and share one vertex block.
    let l = read(&glb(&d, &bin.bytes), &ReadOptions::default()).unwrap();
    assert_eq!((l.mesh.vertex_count(), l.mesh.face_count()), (3, 200));
}

/// Found by the CLI fuzz campaign: a finite node matrix with entries near 1e300 (positions stay
/// within f64) gave NaN or infinite normals, because the normal matrix's cofactors overflowed;
/// `meshwork convert` then wrote an OBJ whose `vn` lines our own reader refuses. The matrix is
/// scaled before its cofactors and determinant: normals come out unit length, and a mirroring
/// matrix that large still flips the winding.
#[test]
fn huge_node_matrix_keeps_normals_finite_and_mirrors() {
    let read_with = |sx: f64| {
        let mut bin = Bin::default();
        let pos = bin.view(&f32s(&FIVE_POINTS[..9]));
        let nrm = bin.view(&f32s(&[0., 0., 1., 0., 0., 1., 0., 0., 1.]));
        let d = doc(
            &bin,
            json!({
                "accessors": [vec3_accessor(pos, 3), vec3_accessor(nrm, 3)],
                "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0, "NORMAL": 1 } }] }],
                "nodes": [{ "mesh": 0, "matrix": [sx, 0, 0, 0, 0, 1e300, 0, 0, 0, 0, 1e300, 0, 0, 0, 0, 1] }],
                "scenes": [{ "nodes": [0] }],
                "scene": 0
            }),
        );
        read(&glb(&d, &bin.bytes), &ReadOptions::default()).expect("a finite transform is read").mesh
    };
    let (plain, mirrored) = (read_with(1e300), read_with(-1e300));
    for m in [&plain, &mirrored] {
        assert_eq!(m.positions[1], [m.positions[1][0], 0.0, 0.0]);
        assert!(m.positions[1][0].abs() == 1e300, "{:?}", m.positions[1]);
        // A mirror in x maps the normal (0, 0, 1) of a plane z = const to itself.
        assert_eq!(m.normals.as_ref().expect("normals"), &vec![[0.0, 0.0, 1.0]; 3]);
    }
    let (a, b) = (plain.faces.get(0).to_vec(), mirrored.faces.get(0).to_vec());
    assert_eq!(a, vec![0, 1, 2]);
    assert_eq!(b, vec![0, 2, 1], "a mirroring transform flips the winding");
}
