//! Reader features, each on a small GLB built by hand with expected values worked out by hand.

mod gltf_support;

use gltf_support::*;
use meshwork_core::io::gltf::read;
use meshwork_core::io::{Format, Loaded, ReadOptions};
use serde_json::json;

fn load(bytes: &[u8]) -> Loaded {
    read(bytes, &ReadOptions::default()).unwrap_or_else(|e| panic!("read failed: {e}"))
}

fn tris(l: &Loaded) -> Vec<Vec<u32>> {
    l.mesh.faces.iter().map(|f| f.to_vec()).collect()
}

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
}

#[test]
fn triangle_strip_with_u8_indices_skips_degenerates() {
    let mut bin = Bin::default();
    let pos = bin.view(&f32s(&[FIVE_POINTS.as_slice(), &[3., 0., 0.]].concat()));
    // Strip v = [0 1 2 2 3 4]: triangles k = 0..3 are
    //   k0 (v0 v1 v2) = (0 1 2); k1 odd (v1 v3 v2) = (1 2 2) degenerate;
    //   k2 (v2 v3 v4) = (2 2 3) degenerate; k3 odd (v3 v5 v4) = (2 4 3).
    let idx = bin.view(&[0u8, 1, 2, 2, 3, 4]);
    let f = single_mesh(
        &bin,
        json!([vec3_accessor(pos, 6), { "bufferView": idx, "componentType": 5121, "count": 6, "type": "SCALAR" }]),
        json!([{ "attributes": { "POSITION": 0 }, "indices": 1, "mode": 5 }]),
    );
    let l = load(&f);
    assert_eq!(l.format, Format::Glb);
    assert_eq!(tris(&l), vec![vec![0, 1, 2], vec![2, 4, 3]]);
    assert!(l.warnings.iter().any(|w| w.contains("2 degenerate")), "{:?}", l.warnings);
}

#[test]
fn triangle_fan_without_indices() {
    let mut bin = Bin::default();
    let pos = bin.view(&f32s(&FIVE_POINTS));
    let f = single_mesh(
        &bin,
        json!([vec3_accessor(pos, 5)]),
        json!([{ "attributes": { "POSITION": 0 }, "mode": 6 }]),
    );
    // Fan triangle k is (v_{k+1}, v_{k+2}, v_0).
    assert_eq!(tris(&load(&f)), vec![vec![1, 2, 0], vec![2, 3, 0], vec![3, 4, 0]]);
}

#[test]
fn u16_and_u32_indices_and_two_primitives_become_two_groups() {
    let mut bin = Bin::default();
    let pos_a = bin.view(&f32s(&FIVE_POINTS[..9]));
    let pos_b = bin.view(&f32s(&FIVE_POINTS));
    let ia = bin.view(&u16s(&[0, 1, 2]));
    let ib = bin.view(&u32s(&[1, 3, 2, 1, 4, 3]));
    let f = single_mesh(
        &bin,
        json!([
            vec3_accessor(pos_a, 3), vec3_accessor(pos_b, 5),
            { "bufferView": ia, "componentType": 5123, "count": 3, "type": "SCALAR" },
            { "bufferView": ib, "componentType": 5125, "count": 6, "type": "SCALAR" }
        ]),
        json!([
            { "attributes": { "POSITION": 0 }, "indices": 2 },
            { "attributes": { "POSITION": 1 }, "indices": 3 }
        ]),
    );
    let l = load(&f);
    // Primitive 1's vertices follow primitive 0's 3: its indices are offset by 3.
    assert_eq!(l.mesh.vertex_count(), 8);
    assert_eq!(tris(&l), vec![vec![0, 1, 2], vec![4, 6, 5], vec![4, 7, 6]]);
    assert_eq!(l.mesh.groups, ["m/0", "m/1"]);
    assert_eq!(l.mesh.faces.groups(), &[0, 1, 1]);
}

#[test]
fn quantized_positions_normalized_and_not() {
    let mut bin = Bin::default();
    // Normalized SHORT: c / 32767, clamped at -1 (so -32768 → -1 too).
    let q = bin.view(&i16s(&[32767, 0, -32768, 16384, -32767, 0, 0, 0, 0]));
    // Unnormalized UNSIGNED_SHORT (padded to 4-byte elements with byteStride 8), scaled by the node.
    let u = bin.view(&u16s(&[10, 20, 30, 0, 1000, 0, 2, 0, 0, 0, 4, 0]));
    let f = glb(
        &doc(
            &bin,
            json!({
                "extensionsUsed": ["KHR_mesh_quantization"],
                "extensionsRequired": ["KHR_mesh_quantization"],
                "accessors": [
                    { "bufferView": q, "componentType": 5122, "normalized": true, "count": 3, "type": "VEC3" },
                    { "bufferView": u, "byteOffset": 0, "componentType": 5123, "count": 3, "type": "VEC3" }
                ],
                "meshes": [
                    { "name": "q", "primitives": [{ "attributes": { "POSITION": 0 } }] },
                    { "name": "u", "primitives": [{ "attributes": { "POSITION": 1 } }] }
                ],
                "nodes": [{ "mesh": 0 }, { "mesh": 1, "scale": [0.5, 0.5, 0.5] }],
                "scenes": [{ "nodes": [0, 1] }],
                "scene": 0
            }),
        ),
        &bin.bytes,
    );
    // The u16 view needs a stride: set it on view `u`.
    let mut d: serde_json::Value = {
        let json_len = u32::from_le_bytes(f[12..16].try_into().unwrap()) as usize;
        serde_json::from_slice(&f[20..20 + json_len]).unwrap()
    };
    d["bufferViews"][u]["byteStride"] = json!(8);
    let l = load(&glb(&d, &bin.bytes));
    let p = &l.mesh.positions;
    assert_eq!(p[0], [1.0, 0.0, -1.0]);
    assert!(close(p[1], [16384.0 / 32767.0, -1.0, 0.0]), "{:?}", p[1]);
    assert_eq!(p[2], [0.0, 0.0, 0.0]);
    // (10, 20, 30) · 0.5, then elements at byte 8 and 16.
    assert_eq!(p[3], [5.0, 10.0, 15.0]);
    assert_eq!(p[4], [500.0, 0.0, 1.0]);
    assert_eq!(p[5], [0.0, 0.0, 2.0]);
    assert_eq!(l.mesh.groups, ["q", "u"]);
}

#[test]
fn sparse_accessor_overrides_listed_elements() {
    let mut bin = Bin::default();
    let pos = bin.view(&f32s(&FIVE_POINTS));
    let sidx = bin.view(&u16s(&[1, 4]));
    let svals = bin.view(&f32s(&[7., 8., 9., -1., -2., -3.]));
    let sparse = json!({ "count": 2, "indices": { "bufferView": sidx, "componentType": 5123 }, "values": { "bufferView": svals } });
    // Second accessor: no buffer view at all (zeros) plus the same sparse substitutions.
    let f = single_mesh(
        &bin,
        json!([
            { "bufferView": pos, "componentType": 5126, "count": 5, "type": "VEC3", "sparse": sparse },
            { "componentType": 5126, "count": 5, "type": "VEC3", "sparse": sparse }
        ]),
        json!([{ "attributes": { "POSITION": 0 }, "mode": 3 }, { "attributes": { "POSITION": 1 }, "mode": 3 }]),
    );
    let l = load(&f);
    let p = &l.mesh.positions;
    assert_eq!(p[..5], [[0., 0., 0.], [7., 8., 9.], [0., 1., 0.], [1., 1., 0.], [-1., -2., -3.]]);
    assert_eq!(p[5..], [[0.; 3], [7., 8., 9.], [0.; 3], [0.; 3], [-1., -2., -3.]]);
    // Two LINE_STRIPs, the second offset by 5.
    assert_eq!(l.mesh.curves, vec![vec![0, 1, 2, 3, 4], vec![5, 6, 7, 8, 9]]);
}

#[test]
fn node_hierarchy_composes_trs_and_matrix() {
    let mut bin = Bin::default();
    let pos = bin.view(&f32s(&[1., 0., 0., 0., 1., 0., 0., 0., 1.]));
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let f = glb(
        &doc(
            &bin,
            json!({
                "accessors": [vec3_accessor(pos, 3)],
                "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 } }] }],
                "nodes": [
                    // parent: T(1,2,3) · S(2)
                    { "name": "parent", "translation": [1, 2, 3], "scale": [2, 2, 2], "children": [1, 2] },
                    // child: 90° about +z
                    { "name": "child", "rotation": [0, 0, h, h], "mesh": 0 },
                    // matrix child: translation (0, 0, 10) column-major
                    { "name": "moved", "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,10,1], "mesh": 0 }
                ],
                "scenes": [{ "nodes": [0] }],
                "scene": 0
            }),
        ),
        &bin.bytes,
    );
    let l = load(&f);
    let p = &l.mesh.positions;
    // By hand: R_z90 (x,y,z) = (-y, x, z); then ·2; then +(1,2,3).
    // (1,0,0) → (0,1,0) → (0,2,0) → (1,4,3); (0,1,0) → (-1,0,0) → (-2,0,0) → (-1,2,3);
    // (0,0,1) → (0,0,1) → (0,0,2) → (1,2,5).
    assert!(close(p[0], [1., 4., 3.]) && close(p[1], [-1., 2., 3.]) && close(p[2], [1., 2., 5.]), "{p:?}");
    // Matrix child: (x, y, z + 10), then ·2, then +(1,2,3).
    assert!(close(p[3], [3., 2., 23.]) && close(p[4], [1., 4., 23.]) && close(p[5], [1., 2., 25.]), "{p:?}");
    // Unnamed mesh: the groups take the node names.
    assert_eq!(l.mesh.groups, ["child", "moved"]);
}

#[test]
fn mirroring_transform_flips_winding_and_normals() {
    let mut bin = Bin::default();
    let pos = bin.view(&f32s(&[0., 0., 0., 1., 0., 0., 0., 1., 0.]));
    let nrm = bin.view(&f32s(&[0., 0., 1., 0., 0., 1., 0., 0., 1.]));
    let f = glb(
        &doc(
            &bin,
            json!({
                "accessors": [vec3_accessor(pos, 3), vec3_accessor(nrm, 3)],
                "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0, "NORMAL": 1 } }] }],
                "nodes": [{ "mesh": 0, "scale": [1, 1, -1] }],
                "scenes": [{ "nodes": [0] }]
            }),
        ),
        &bin.bytes,
    );
    let l = load(&f);
    // z-mirror: the triangle lies in z = 0, its +z normal becomes -z, and winding flips so the
    // geometric normal (right-hand rule) agrees with it.
    assert_eq!(tris(&l), vec![vec![0, 2, 1]]);
    assert_eq!(l.mesh.normals.as_deref(), Some(&[[0., 0., -1.]; 3][..]));
}

#[test]
fn lines_and_line_loops_become_curves_and_points_are_skipped() {
    let mut bin = Bin::default();
    let pos = bin.view(&f32s(&FIVE_POINTS));
    // LINES (0-1)(1-2)(3-4): the first two chain into one polyline.
    let lines = bin.view(&[0u8, 1, 1, 2, 3, 4]);
    let f = single_mesh(
        &bin,
        json!([vec3_accessor(pos, 5), { "bufferView": lines, "componentType": 5121, "count": 6, "type": "SCALAR" }]),
        json!([
            { "attributes": { "POSITION": 0 }, "indices": 1, "mode": 1 },
            { "attributes": { "POSITION": 0 }, "mode": 2 },
            { "attributes": { "POSITION": 0 }, "mode": 0 }
        ]),
    );
    let l = load(&f);
    // Both line primitives share POSITION accessor 0 under one transform: one vertex block.
    assert_eq!(l.mesh.vertex_count(), 5);
    assert_eq!(l.mesh.curves, vec![vec![0, 1, 2], vec![3, 4], vec![0, 1, 2, 3, 4, 0]]);
    assert_eq!(l.mesh.face_count(), 0);
    assert!(
        l.warnings.iter().any(|w| w.contains("primitives[2]") && w.contains("POINTS")),
        "{:?}",
        l.warnings
    );
}

#[test]
fn interleaved_attributes_with_byte_stride() {
    // position, normal interleaved: 24-byte elements.
    let mut data = Vec::new();
    for (p, n) in [([0., 0., 0.], [0., 0., 1.]), ([1., 0., 0.], [0., 1., 0.]), ([0., 1., 0.], [1., 0., 0.])] {
        data.extend(f32s(&p));
        data.extend(f32s(&n));
    }
    let mut bin = Bin::default();
    let v = bin.view(&data);
    bin.views[v]["byteStride"] = json!(24);
    let f = single_mesh(
        &bin,
        json!([vec3_accessor(v, 3), { "bufferView": v, "byteOffset": 12, "componentType": 5126, "count": 3, "type": "VEC3" }]),
        json!([{ "attributes": { "POSITION": 0, "NORMAL": 1 } }]),
    );
    let l = load(&f);
    assert_eq!(l.mesh.positions, vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]);
    assert_eq!(l.mesh.normals.unwrap(), vec![[0., 0., 1.], [0., 1., 0.], [1., 0., 0.]]);
}

#[test]
fn normals_dropped_when_a_primitive_lacks_them_and_min_max_not_trusted() {
    let mut bin = Bin::default();
    let pos = bin.view(&f32s(&FIVE_POINTS[..9]));
    let nrm = bin.view(&f32s(&[0., 0., 1., 0., 0., 1., 0., 0., 1.]));
    let mut lying = vec3_accessor(pos, 3);
    lying["min"] = json!([5, 5, 5]);
    lying["max"] = json!([6, 6, 6]);
    let f = single_mesh(
        &bin,
        json!([lying, vec3_accessor(nrm, 3)]),
        json!([{ "attributes": { "POSITION": 0, "NORMAL": 1 } }, { "attributes": { "POSITION": 0 } }]),
    );
    let l = load(&f);
    assert!(l.mesh.normals.is_none());
    assert!(
        l.warnings.iter().any(|w| w.contains("NORMAL dropped") && w.contains("primitives[1]")),
        "{:?}",
        l.warnings
    );
    assert_eq!(l.mesh.positions[1], [1., 0., 0.], "data wins over the declared min/max");
}

#[test]
fn gltf_json_with_data_uri_and_scene_selection() {
    let bytes = f32s(&FIVE_POINTS[..9]);
    let b64 = {
        // Independent encoder for the test: 9 floats = 36 bytes, a multiple of 3, no padding.
        const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        bytes
            .chunks(3)
            .flat_map(|c| {
                let n = (c[0] as u32) << 16 | (c[1] as u32) << 8 | c[2] as u32;
                [18, 12, 6, 0].map(|s| A[(n >> s & 63) as usize] as char)
            })
            .collect::<String>()
    };
    let doc = json!({
        "asset": { "version": "2.0" },
        "buffers": [{ "byteLength": 36, "uri": format!("data:application/gltf-buffer;base64,{b64}") }],
        "bufferViews": [{ "buffer": 0, "byteLength": 36 }],
        "accessors": [vec3_accessor(0, 3)],
        "meshes": [{ "name": "a", "primitives": [{ "attributes": { "POSITION": 0 } }] },
                   { "name": "b", "primitives": [{ "attributes": { "POSITION": 0 } }] }],
        "nodes": [{ "mesh": 0 }, { "mesh": 1, "translation": [0, 0, 1] }],
        "scenes": [{ "nodes": [0] }, { "nodes": [1] }],
        "scene": 1
    });
    let l = load(&serde_json::to_vec(&doc).unwrap());
    assert_eq!(l.format, Format::Gltf);
    // Only the default scene (1): mesh "b" moved up by 1; mesh "a" reported as not read.
    assert_eq!(l.mesh.positions, vec![[0., 0., 1.], [1., 0., 1.], [0., 1., 1.]]);
    assert_eq!(l.mesh.groups, ["b"]);
    assert!(l.warnings.iter().any(|w| w.contains("meshes[0]")), "{:?}", l.warnings);

    // Without a default scene: every root node; without nodes: every mesh.
    let mut no_default = doc.clone();
    no_default.as_object_mut().unwrap().remove("scene");
    assert_eq!(load(&serde_json::to_vec(&no_default).unwrap()).mesh.vertex_count(), 6);
    let mut no_nodes = doc;
    for k in ["scene", "scenes", "nodes"] {
        no_nodes.as_object_mut().unwrap().remove(k);
    }
    let l = load(&serde_json::to_vec(&no_nodes).unwrap());
    assert_eq!(l.mesh.groups, ["a", "b"]);
    // Same accessor, same (identity) transform: the two meshes share the vertex block.
    assert_eq!(l.mesh.vertex_count(), 3);
    assert_eq!(l.mesh.face_count(), 2);
}

#[test]
fn quantized_byte_positions_and_normals() {
    let mut bin = Bin::default();
    // BYTE normalized, 3-byte elements padded to 4 (byteStride 4, as KHR_mesh_quantization asks).
    let i8v = bin.view(&[127u8, 128, 0, 0, 64, 0, 129, 0, 0, 0, 0, 0]); // 128 = -128, 129 = -127
    bin.views[i8v]["byteStride"] = json!(4);
    // UNSIGNED_BYTE normalized, same layout.
    let u8v = bin.view(&[255u8, 0, 51, 0, 0, 255, 0, 0, 0, 0, 0, 0]);
    bin.views[u8v]["byteStride"] = json!(4);
    // BYTE normalized normals (the same view as the positions: (1, -1, 0) etc. before normalising).
    let f = single_mesh(
        &bin,
        json!([
            { "bufferView": i8v, "componentType": 5120, "normalized": true, "count": 3, "type": "VEC3" },
            { "bufferView": u8v, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC3" },
            { "bufferView": u8v, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC2" }
        ]),
        json!([{ "attributes": { "POSITION": 0, "NORMAL": 0, "TEXCOORD_0": 2 } }, { "attributes": { "POSITION": 1, "NORMAL": 0, "TEXCOORD_0": 2 } }]),
    );
    let l = load(&f);
    let p = &l.mesh.positions;
    // c / 127 clamped to -1; c / 255.
    assert_eq!(p[0], [1.0, -1.0, 0.0]);
    assert!(close(p[1], [64.0 / 127.0, 0.0, -1.0]), "{:?}", p[1]);
    assert_eq!(p[3], [1.0, 0.0, 0.2]);
    assert_eq!(p[4], [0.0, 1.0, 0.0]);
    let n = l.mesh.normals.as_ref().unwrap();
    let s = 1.0 / 2f64.sqrt();
    assert!(close(n[0], [s, -s, 0.0]), "normals are re-normalised after the transform: {:?}", n[0]);
    // TEXCOORD_0 (1, 0) in glTF's top-left convention is (1, 1) in meshwork's bottom-left one.
    assert_eq!(l.mesh.uvs.as_ref().unwrap()[0], [1.0, 1.0]);
}
