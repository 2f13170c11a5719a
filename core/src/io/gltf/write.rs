//! Mesh → glTF layout (used by both GLB and glTF JSON output):
//!
//! - one set of vertex accessors shared by every primitive: POSITION (f32, exact min/max), NORMAL
//!   (normalised; a zero or non-finite normal is written as +Z because glTF requires unit
//!   normals), TEXCOORD_0 (v flipped: meshwork keeps the OBJ convention, origin bottom-left;
//!   glTF's origin is top-left). Vertex order is kept, so vertex `i` stays vertex `i`;
//! - one glTF mesh per non-empty face group, named after the group, with one TRIANGLES primitive,
//!   and one node of the same name per mesh. Polygons are fan-triangulated (glTF has no quads);
//!   a face with fewer than 3 vertices cannot be written: that is an error (`invalid-mesh` naming
//!   the face; repair drops such faces), not a silent drop. Faces come out grouped by group id;
//! - curves as LINE_STRIP primitives of one extra mesh named `curves` (a curve of fewer than 2
//!   vertices has no segment and is left out; its vertices are still written);
//! - a mesh with vertices but neither faces nor curves is written as one POINTS primitive.
//!
//! Positions are f32 in glTF: coordinates round to about 7 significant digits.

use serde_json::json;

use super::builder::{GltfBuilder, MODE_LINE_STRIP, MODE_TRIANGLES};
use crate::error::{Error, Location, Result};
use crate::mesh::Mesh;

pub use super::builder::AddedMesh;

const MODE_POINTS: u32 = 0;

fn unit_f32(n: [f64; 3]) -> [f32; 3] {
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len.is_finite() && len > 1e-30 {
        let v = [(n[0] / len) as f32, (n[1] / len) as f32, (n[2] / len) as f32];
        // Re-normalise in f32 so the validator's unit-length check (tolerance 5e-4) is met.
        let l32 = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / l32, v[1] / l32, v[2] / l32]
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// Fan-triangulated faces per group id.
fn triangles_by_group(mesh: &Mesh) -> Result<Vec<Vec<u32>>> {
    let group_count = mesh.faces.groups().iter().map(|&g| g as usize + 1).max().unwrap_or(0);
    let mut by_group = vec![Vec::new(); group_count.max(mesh.groups.len())];
    let apex = mesh.faces.fan_apexes();
    for (fi, face) in mesh.faces.iter().enumerate() {
        if face.len() < 3 {
            return Err(Error::InvalidMesh {
                location: Location::Face(fi),
                message: format!("a face with {} vertices cannot be written to glTF", face.len()),
            });
        }
        let tris = &mut by_group[mesh.faces.group(fi) as usize];
        crate::mesh::fan_of(face, apex[fi] as usize, |t| tris.extend_from_slice(&t));
    }
    Ok(by_group)
}

pub(super) fn add_mesh(b: &mut GltfBuilder, mesh: &Mesh) -> Result<AddedMesh> {
    mesh.check()?;
    let mut added = AddedMesh::default();
    if mesh.positions.is_empty() {
        return Ok(added);
    }
    let positions: Vec<[f32; 3]> =
        mesh.positions.iter().map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]).collect();
    let position = b.accessor_vec3(&positions)?;
    added.position = Some(position);
    let mut attributes = json!({ "POSITION": position });
    if let Some(normals) = &mesh.normals {
        let n: Vec<[f32; 3]> = normals.iter().map(|&n| unit_f32(n)).collect();
        let acc = b.accessor_vec3_unbounded(&n)?;
        attributes["NORMAL"] = json!(acc);
        added.normal = Some(acc);
    }
    if let Some(uvs) = &mesh.uvs {
        let t: Vec<[f32; 2]> = uvs.iter().map(|uv| [uv[0] as f32, (1.0 - uv[1]) as f32]).collect();
        let acc = b.accessor_vec2(&t)?;
        attributes["TEXCOORD_0"] = json!(acc);
        added.texcoord = Some(acc);
    }

    let mut push_mesh = |b: &mut GltfBuilder, name: &str, primitives: Vec<serde_json::Value>| {
        let mut m = json!({ "primitives": primitives });
        let mut node = json!({});
        if !name.is_empty() {
            m["name"] = json!(name);
            node["name"] = json!(name);
        }
        let mi = b.mesh(m);
        node["mesh"] = json!(mi);
        let ni = b.node(node);
        b.add_root(ni);
        added.meshes.push(mi);
        added.nodes.push(ni);
    };

    let by_group = triangles_by_group(mesh)?;
    for (g, tris) in by_group.iter().enumerate() {
        if tris.is_empty() {
            continue;
        }
        let indices = b.accessor_indices(tris)?;
        let prim = json!({ "attributes": attributes, "indices": indices, "mode": MODE_TRIANGLES });
        push_mesh(b, mesh.group_name(g as u32), vec![prim]);
    }

    let mut curve_prims = Vec::new();
    for curve in mesh.curves.iter().filter(|c| c.len() >= 2) {
        let indices = b.accessor_indices(curve)?;
        curve_prims.push(json!({ "attributes": attributes, "indices": indices, "mode": MODE_LINE_STRIP }));
    }
    let curve_prims_written = curve_prims.len();
    if !curve_prims.is_empty() {
        push_mesh(b, "curves", curve_prims);
    }

    if by_group.iter().all(|t| t.is_empty()) && curve_prims_written == 0 {
        push_mesh(b, "points", vec![json!({ "attributes": attributes, "mode": MODE_POINTS })]);
    }
    Ok(added)
}

/// Encodes `mesh` as GLB (see the module docs for the layout).
pub fn write_glb(mesh: &Mesh) -> Result<Vec<u8>> {
    let mut b = GltfBuilder::new();
    add_mesh(&mut b, mesh)?;
    Ok(b.finish_glb())
}

/// Encodes `mesh` as glTF JSON with the buffer embedded as a base64 `data:` URI.
pub fn write_gltf(mesh: &Mesh) -> Result<Vec<u8>> {
    let mut b = GltfBuilder::new();
    add_mesh(&mut b, mesh)?;
    Ok(b.finish_gltf())
}
