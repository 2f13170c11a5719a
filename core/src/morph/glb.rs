//! The morph's animated GLB, written through the project's one glTF writer
//! ([`crate::io::gltf::builder::GltfBuilder`]): one mesh whose base geometry is the first shape,
//! one glTF morph target per further shape (position deltas), and an animation whose weights go
//! through the shapes in turn, so any glTF viewer plays the morph.
//! (glTF 2.0 §3.7.2.2 morph targets, §3.11 animations; positions are f32 by the spec.)
//!
//! Also the per-frame GLB of the `frames_zip` output ([`write_static`]): one plain mesh.

use serde_json::json;

use crate::error::{Error, Result};
use crate::io::gltf::builder::{GltfBuilder, MODE_TRIANGLES};
use crate::mesh::Point3;

fn to_f32(p: &[Point3]) -> Vec<[f32; 3]> {
    p.iter().map(|q| q.map(|c| c as f32)).collect()
}

fn indices(tris: &[[u32; 3]]) -> Vec<u32> {
    tris.iter().flatten().copied().collect()
}

/// `shapes[0]` is the base; `keys` are (time in s, weights per target) keyframes.
pub fn write(tris: &[[u32; 3]], shapes: &[Vec<Point3>], keys: &[(f32, Vec<f32>)]) -> Result<Vec<u8>> {
    let base_shape = shapes.first().ok_or_else(|| Error::Internal("morph GLB without shapes".into()))?;
    if tris.is_empty() || base_shape.is_empty() {
        return Err(Error::Internal("morph GLB of an empty mesh".into()));
    }
    let targets = shapes.len() - 1;
    let mut b = GltfBuilder::new();
    let base = to_f32(base_shape);
    let pos = b.accessor_vec3(&base)?;
    let mut target_accs = Vec::with_capacity(targets);
    for s in &shapes[1..] {
        // Deltas taken on the f32 values, so base + delta is the stored target exactly.
        let d: Vec<[f32; 3]> = s
            .iter()
            .zip(&base)
            .map(|(p, q)| [p[0] as f32 - q[0], p[1] as f32 - q[1], p[2] as f32 - q[2]])
            .collect();
        target_accs.push(b.accessor_vec3(&d)?);
    }
    let idx = b.accessor_indices(&indices(tris))?;
    let mut primitive = json!({"attributes": {"POSITION": pos}, "indices": idx, "mode": MODE_TRIANGLES});
    let mut mesh = json!({"name": "morph"});
    if targets > 0 {
        primitive["targets"] = json!(target_accs.iter().map(|&a| json!({"POSITION": a})).collect::<Vec<_>>());
        mesh["weights"] = json!(vec![0.0; targets]);
        mesh["extras"] =
            json!({"targetNames": (1..=targets).map(|k| format!("input{k}")).collect::<Vec<_>>()});
    }
    mesh["primitives"] = json!([primitive]);
    let m = b.mesh(mesh);
    let node = b.node(json!({"mesh": m, "name": "morph"}));
    b.add_root(node);
    if targets > 0 && keys.len() >= 2 {
        let times: Vec<f32> = keys.iter().map(|k| k.0).collect();
        let weights: Vec<f32> = keys
            .iter()
            .flat_map(|(_, w)| (0..targets).map(move |k| w.get(k).copied().unwrap_or(0.0)))
            .collect();
        let t_acc = b.accessor_scalar(&times)?;
        let w_acc = b.accessor_scalar(&weights)?;
        b.animation(json!({
            "name": "morph",
            "samplers": [{"input": t_acc, "output": w_acc, "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": node, "path": "weights"}}],
        }));
    }
    Ok(b.finish_glb())
}

/// A GLB of one triangle mesh (one frame of the `frames_zip` output).
pub fn write_static(tris: &[[u32; 3]], pos: &[Point3], name: &str) -> Result<Vec<u8>> {
    if tris.is_empty() || pos.is_empty() {
        return Err(Error::Internal("frame GLB of an empty mesh".into()));
    }
    let mut b = GltfBuilder::new();
    let p = b.accessor_vec3(&to_f32(pos))?;
    let idx = b.accessor_indices(&indices(tris))?;
    let m = b.mesh(json!({
        "name": name,
        "primitives": [{"attributes": {"POSITION": p}, "indices": idx, "mode": MODE_TRIANGLES}],
    }));
    let node = b.node(json!({"mesh": m, "name": name}));
    b.add_root(node);
    Ok(b.finish_glb())
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
