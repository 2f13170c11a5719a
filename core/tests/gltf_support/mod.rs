//! Hand-built glTF test files, assembled byte by byte here (not with meshwork's writer), so the
//! reader is tested against files whose content we wrote down ourselves.
#![allow(dead_code)]

use serde_json::{json, Value};

/// Little-endian bytes of a slice of numbers.
pub fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
pub fn u16s(v: &[u16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
pub fn i16s(v: &[i16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
pub fn u32s(v: &[u32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// A binary buffer that hands out 4-byte aligned buffer views.
#[derive(Default)]
pub struct Bin {
    pub bytes: Vec<u8>,
    pub views: Vec<Value>,
}

impl Bin {
    /// Appends `data` as buffer view; returns its index.
    pub fn view(&mut self, data: &[u8]) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(json!({ "buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len() }));
        self.bytes.extend_from_slice(data);
        self.views.len() - 1
    }
}

/// A GLB file: header, JSON chunk (space padded), BIN chunk (zero padded) when `bin` is non-empty.
pub fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend(j);
    if !b.is_empty() {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend(b);
    }
    out
}

/// A document skeleton around `bin`: asset, the buffer, its views, plus `rest` merged in.
pub fn doc(bin: &Bin, rest: Value) -> Value {
    let mut d = json!({
        "asset": { "version": "2.0" },
        "buffers": [{ "byteLength": bin.bytes.len() }],
        "bufferViews": bin.views,
    });
    for (k, v) in rest.as_object().unwrap() {
        d[k] = v.clone();
    }
    d
}

/// One mesh with the given primitives, one node, one scene.
pub fn single_mesh(bin: &Bin, accessors: Value, primitives: Value) -> Vec<u8> {
    glb(
        &doc(
            bin,
            json!({
                "accessors": accessors,
                "meshes": [{ "name": "m", "primitives": primitives }],
                "nodes": [{ "mesh": 0 }],
                "scenes": [{ "nodes": [0] }],
                "scene": 0,
            }),
        ),
        &bin.bytes,
    )
}

/// Positions of a unit right triangle plus two more points, f32 VEC3.
pub const FIVE_POINTS: [f32; 15] = [0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0., 2., 0., 0.];

pub fn vec3_accessor(view: usize, count: usize) -> Value {
    json!({ "bufferView": view, "componentType": 5126, "count": count, "type": "VEC3" })
}
