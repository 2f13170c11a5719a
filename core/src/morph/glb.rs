//! A self-contained writer for the morph's animated GLB: one mesh whose base geometry is the first
//! shape, one glTF morph target per further shape (position deltas), and an animation whose
//! weights go through the shapes in turn, so any glTF viewer plays the morph.
//! (glTF 2.0 §3.7.2.2 morph targets, §3.11 animations; positions are f32 by the spec.)

use crate::mesh::Point3;

/// `shapes[0]` is the base; `keys` are (time in s, weights per target) keyframes.
pub fn write(tris: &[[u32; 3]], shapes: &[Vec<Point3>], keys: &[(f32, Vec<f32>)]) -> Vec<u8> {
    let n = shapes[0].len();
    let targets = shapes.len() - 1;
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    // Base positions.
    let base: Vec<[f32; 3]> = shapes[0].iter().map(|p| p.map(|c| c as f32)).collect();
    let push_vec3 = |bin: &mut Vec<u8>,
                     data: &[[f32; 3]],
                     views: &mut Vec<serde_json::Value>,
                     accessors: &mut Vec<serde_json::Value>| {
        let off = bin.len();
        let mut mn = [f32::INFINITY; 3];
        let mut mx = [f32::NEG_INFINITY; 3];
        for p in data {
            for k in 0..3 {
                mn[k] = mn[k].min(p[k]);
                mx[k] = mx[k].max(p[k]);
                bin.extend_from_slice(&p[k].to_le_bytes());
            }
        }
        if data.is_empty() {
            mn = [0.0; 3];
            mx = [0.0; 3];
        }
        views.push(serde_json::json!({"buffer": 0, "byteOffset": off, "byteLength": data.len() * 12, "target": 34962}));
        accessors.push(serde_json::json!({
            "bufferView": views.len() - 1, "componentType": 5126, "count": data.len(), "type": "VEC3",
            "min": mn, "max": mx,
        }));
        accessors.len() - 1
    };
    let pos_acc = push_vec3(&mut bin, &base, &mut views, &mut accessors);
    let mut target_accs = Vec::new();
    for s in &shapes[1..] {
        let d: Vec<[f32; 3]> = s
            .iter()
            .zip(&base)
            .map(|(p, b)| [p[0] as f32 - b[0], p[1] as f32 - b[1], p[2] as f32 - b[2]])
            .collect();
        target_accs.push(push_vec3(&mut bin, &d, &mut views, &mut accessors));
    }
    // Indices.
    let off = bin.len();
    for t in tris {
        for &v in t {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    views.push(
        serde_json::json!({"buffer": 0, "byteOffset": off, "byteLength": tris.len() * 12, "target": 34963}),
    );
    accessors.push(serde_json::json!({
        "bufferView": views.len() - 1, "componentType": 5125, "count": tris.len() * 3, "type": "SCALAR",
        "max": [n.saturating_sub(1)], "min": [0],
    }));
    let idx_acc = accessors.len() - 1;
    // Animation: times and weights.
    let mut anim = serde_json::Value::Null;
    if targets > 0 && keys.len() >= 2 {
        let off = bin.len();
        for (t, _) in keys {
            bin.extend_from_slice(&t.to_le_bytes());
        }
        views.push(serde_json::json!({"buffer": 0, "byteOffset": off, "byteLength": keys.len() * 4}));
        let t0 = keys.first().map(|k| k.0).unwrap_or(0.0);
        let t1 = keys.last().map(|k| k.0).unwrap_or(0.0);
        accessors.push(serde_json::json!({
            "bufferView": views.len() - 1, "componentType": 5126, "count": keys.len(), "type": "SCALAR",
            "min": [t0], "max": [t1],
        }));
        let time_acc = accessors.len() - 1;
        let off = bin.len();
        for (_, w) in keys {
            for k in 0..targets {
                bin.extend_from_slice(&w.get(k).copied().unwrap_or(0.0).to_le_bytes());
            }
        }
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": off, "byteLength": keys.len() * targets * 4}),
        );
        accessors.push(serde_json::json!({
            "bufferView": views.len() - 1, "componentType": 5126, "count": keys.len() * targets, "type": "SCALAR",
        }));
        let w_acc = accessors.len() - 1;
        anim = serde_json::json!([{
            "name": "morph",
            "samplers": [{"input": time_acc, "output": w_acc, "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}],
        }]);
    }
    let mut primitive =
        serde_json::json!({"attributes": {"POSITION": pos_acc}, "indices": idx_acc, "mode": 4});
    if targets > 0 {
        primitive["targets"] = serde_json::Value::Array(
            target_accs.iter().map(|&a| serde_json::json!({"POSITION": a})).collect(),
        );
    }
    let mut mesh = serde_json::json!({"name": "morph", "primitives": [primitive]});
    if targets > 0 {
        mesh["weights"] = serde_json::json!(vec![0.0; targets]);
        mesh["extras"] = serde_json::json!({"targetNames": (1..=targets).map(|k| format!("input{k}")).collect::<Vec<_>>()});
    }
    let mut doc = serde_json::json!({
        "asset": {"version": "2.0", "generator": "meshwork morph"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "morph"}],
        "meshes": [mesh],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    if !anim.is_null() {
        doc["animations"] = anim;
    }
    let mut json = serde_json::to_vec(&doc).unwrap_or_default();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// Keyframes for a sequence through the shapes: at time k·`seconds_per_leg` the weights select
/// shape k alone (all zero for the base); linear in between.
pub fn sequence_keys(shapes: usize, seconds_per_leg: f32) -> Vec<(f32, Vec<f32>)> {
    let targets = shapes.saturating_sub(1);
    (0..shapes)
        .map(|k| {
            let mut w = vec![0.0; targets];
            if k > 0 {
                w[k - 1] = 1.0;
            }
            (k as f32 * seconds_per_leg, w)
        })
        .collect()
}
