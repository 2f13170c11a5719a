//! Curve files written the way other programs write them: glTF LINES / LINE_STRIP / LINE_LOOP
//! (one primitive, or one node with a transform per polyline), OBJ `l` with negative indices; and
//! templates as scanners and CAD tools write them (binary PLY of f32, an ASCII STL soup).

use crate::io::gltf::base64::encode as base64;
use crate::mesh::{Mesh, Point3};

/// A glTF (JSON with an embedded base64 buffer) holding `points` and one primitive of `mode` with
/// `indices`.
pub fn gltf_lines(points: &[Point3], indices: &[u32], mode: u32) -> Vec<u8> {
    let mut buf = Vec::new();
    for p in points {
        for &x in p {
            buf.extend_from_slice(&(x as f32).to_le_bytes());
        }
    }
    let pos_len = buf.len();
    for &i in indices {
        buf.extend_from_slice(&i.to_le_bytes());
    }
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] as f32);
            hi[k] = hi[k].max(p[k] as f32);
        }
    }
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": buf.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&buf))}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": pos_len},
            {"buffer": 0, "byteOffset": pos_len, "byteLength": buf.len() - pos_len}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": points.len(), "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": mode}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    serde_json::to_vec(&doc).unwrap_or_default()
}

/// glTF with one mesh per polyline (LINE_STRIP, no indices), each under its own node with a
/// translation, a 90° rotation about z and a scale, all children of a node scaling by 2: the stored
/// points are the world points `lines` mapped back by hand (f32), so a reader that applies the
/// node transforms gets `lines` back to f32 rounding.
pub fn gltf_strips_with_nodes(lines: &[Vec<Point3>]) -> Vec<u8> {
    use serde_json::json;
    let mut buf: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut meshes, mut nodes) = (vec![], vec![], vec![], vec![]);
    let mut children = vec![];
    for (k, line) in lines.iter().enumerate() {
        // Node k: translation t_k, rotation 90° about z (x→y, y→-x), scale s; parent scale 2.
        // world = 2 · (t + s · Rz(p_local)) ⇒ p_local = Rz⁻¹((world / 2 − t) / s).
        let t = [0.3 * k as f64, -0.2, 0.1 * k as f64];
        let s = 0.5 + 0.25 * k as f64;
        let local: Vec<[f32; 3]> = line
            .iter()
            .map(|w| {
                let q = [(w[0] / 2.0 - t[0]) / s, (w[1] / 2.0 - t[1]) / s, (w[2] / 2.0 - t[2]) / s];
                // Rz⁻¹ (x, y) = (y, -x)
                [q[1] as f32, -q[0] as f32, q[2] as f32]
            })
            .collect();
        let off = buf.len();
        for p in &local {
            for x in p {
                buf.extend_from_slice(&x.to_le_bytes());
            }
        }
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in &local {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        views.push(json!({"buffer": 0, "byteOffset": off, "byteLength": buf.len() - off}));
        accessors.push(json!({"bufferView": k, "componentType": 5126, "count": local.len(), "type": "VEC3", "min": lo, "max": hi}));
        meshes.push(json!({"primitives": [{"attributes": {"POSITION": k}, "mode": 3}]}));
        let h = std::f64::consts::FRAC_1_SQRT_2;
        nodes.push(json!({"mesh": k, "translation": t, "rotation": [0.0, 0.0, h, h], "scale": [s, s, s]}));
        children.push(k);
    }
    nodes.push(json!({"children": children, "scale": [2.0, 2.0, 2.0]}));
    let root = nodes.len() - 1;
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": buf.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&buf))}],
        "bufferViews": views, "accessors": accessors, "meshes": meshes, "nodes": nodes,
        "scenes": [{"nodes": [root]}], "scene": 0
    });
    serde_json::to_vec(&doc).unwrap_or_default()
}

/// `curves` (e.g. the ellipsoid sections) as OBJ text with negative (relative) indices.
pub fn obj_negative_indices(curves: &Mesh) -> Vec<u8> {
    let mut s = String::new();
    for c in &curves.curves {
        for &v in c {
            let p = curves.positions[v as usize];
            s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        s += "l";
        for k in 0..c.len() {
            s += &format!(" {}", k as i64 - c.len() as i64);
        }
        s += "\n";
    }
    s.into_bytes()
}

/// A triangle mesh as a hand-written binary little-endian PLY (float vertices, uchar/int lists),
/// as scanners write it.
pub fn binary_ply(m: &Mesh) -> Vec<u8> {
    let tris = m.faces.triangles();
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\ncomment made by meshwork testdata\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        m.positions.len(),
        tris.len()
    )
    .into_bytes();
    for p in &m.positions {
        for c in p {
            b.extend_from_slice(&(*c as f32).to_le_bytes());
        }
    }
    for t in &tris {
        b.push(3);
        for v in t {
            b.extend_from_slice(&(*v as i32).to_le_bytes());
        }
    }
    b
}

/// A triangle mesh as hand-written ASCII STL: a soup (every facet its own corners), normals zero.
pub fn ascii_stl(m: &Mesh) -> Vec<u8> {
    let mut s = String::from("solid mesh\n");
    for t in m.faces.triangles() {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for v in t {
            let p = m.positions[v as usize];
            s += &format!("      vertex {:e} {:e} {:e}\n", p[0], p[1], p[2]);
        }
        s += "    endloop\n  endfacet\n";
    }
    s += "endsolid mesh\n";
    s.into_bytes()
}
