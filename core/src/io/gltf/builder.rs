//! A small glTF 2.0 document builder: binary data goes into one buffer (4-byte aligned buffer
//! views), JSON objects are collected in their arrays, and [`GltfBuilder::finish_glb`] or
//! [`GltfBuilder::finish_gltf`] assemble the file.
//!
//! The mesh writer ([`super::write`]) is built on it, and other jobs reuse it for output the mesh
//! writer does not cover (the morph job adds morph targets and a weights animation):
//!
//! ```
//! use meshwork_core::io::gltf::builder::{GltfBuilder, add_mesh};
//! use serde_json::json;
//! let mesh = meshwork_core::shapes::icosphere(1, 1.0);
//! let mut b = GltfBuilder::new();
//! let added = add_mesh(&mut b, &mesh).unwrap();
//! // A morph target moving every vertex by +1 in z, on every primitive of the written meshes.
//! let deltas = vec![[0.0f32, 0.0, 1.0]; mesh.vertex_count()];
//! let target = b.accessor_vec3(&deltas).unwrap();
//! for &m in &added.meshes {
//!     let gm = b.mesh_mut(m).unwrap();
//!     for p in gm["primitives"].as_array_mut().unwrap() {
//!         p["targets"] = json!([{ "POSITION": target }]);
//!     }
//!     gm["weights"] = json!([0.0]);
//! }
//! let glb = b.finish_glb();
//! assert_eq!(&glb[..4], b"glTF");
//! ```
//!
//! Rules the builder keeps so that output passes the Khronos validator: every accessor has
//! count ≥ 1 and finite values, VEC3/SCALAR float accessors carry exact `min`/`max` (computed on
//! the f32 values actually stored), empty top-level arrays are omitted, chunks and buffer views are
//! 4-byte aligned, `asset.generator` is `"meshwork"`.

use serde_json::{json, Map, Value};

use super::base64;
use crate::error::{Error, Location, Result};
use crate::mesh::Mesh;

/// `bufferView.target` for vertex attributes.
pub const ARRAY_BUFFER: u32 = 34962;
/// `bufferView.target` for indices.
pub const ELEMENT_ARRAY_BUFFER: u32 = 34963;

pub const FLOAT: u32 = 5126;
pub const UNSIGNED_SHORT: u32 = 5123;
pub const UNSIGNED_INT: u32 = 5125;

/// Primitive modes.
pub const MODE_LINE_STRIP: u32 = 3;
pub const MODE_TRIANGLES: u32 = 4;

/// Collects the pieces of one glTF document with a single binary buffer.
#[derive(Debug, Default, Clone)]
pub struct GltfBuilder {
    bin: Vec<u8>,
    buffer_views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    nodes: Vec<Value>,
    animations: Vec<Value>,
    scene_nodes: Vec<usize>,
    extensions_used: Vec<String>,
    extensions_required: Vec<String>,
}

fn pad_to_4(bytes: &mut Vec<u8>, fill: u8) {
    while !bytes.len().is_multiple_of(4) {
        bytes.push(fill);
    }
}

/// Appends little-endian bytes straight into `out` (no intermediate copy: outputs can be 100 MB).
fn extend_f32(out: &mut Vec<u8>, values: &[f32]) {
    out.reserve(values.len() * 4);
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

fn check_finite(values: &[f32], width: usize) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::InvalidMesh {
            location: Location::Vertex(i / width),
            message: "value is NaN or infinite (or too large for f32)".into(),
        }),
    }
}

/// Component-wise min and max of `values` seen as `width`-vectors.
fn bounds(values: &[f32], width: usize) -> (Vec<f32>, Vec<f32>) {
    let mut lo = vec![f32::INFINITY; width];
    let mut hi = vec![f32::NEG_INFINITY; width];
    for v in values.chunks_exact(width) {
        for k in 0..width {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo, hi)
}

impl GltfBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends `bytes` as a new buffer view (starting on a 4-byte boundary); returns its index.
    pub fn buffer_view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        self.buffer_view_with(target, |bin| bin.extend_from_slice(bytes))
    }

    /// A new buffer view whose bytes `fill` appends to the binary buffer directly.
    pub fn buffer_view_with(&mut self, target: Option<u32>, fill: impl FnOnce(&mut Vec<u8>)) -> usize {
        pad_to_4(&mut self.bin, 0);
        let start = self.bin.len();
        fill(&mut self.bin);
        let mut view = json!({ "buffer": 0, "byteOffset": start, "byteLength": self.bin.len() - start });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.buffer_views.push(view);
        self.buffer_views.len() - 1
    }

    /// A float accessor of `type_name` (`"SCALAR"`, `"VEC2"`, `"VEC3"`, `"VEC4"`) over `values`
    /// (length a multiple of the type's width), in its own buffer view. `with_bounds` adds exact
    /// `min`/`max` (required for POSITION, morph target POSITION and animation input).
    pub fn accessor_f32(
        &mut self,
        values: &[f32],
        type_name: &str,
        with_bounds: bool,
        target: Option<u32>,
    ) -> Result<usize> {
        let width = match type_name {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            _ => {
                return Err(Error::Internal(format!(
                    "accessor type {type_name} not supported by the builder"
                )))
            }
        };
        if values.is_empty() || !values.len().is_multiple_of(width) {
            return Err(Error::Internal(format!(
                "accessor of {} floats cannot hold {type_name} elements (glTF needs count ≥ 1)",
                values.len()
            )));
        }
        check_finite(values, width)?;
        let view = self.buffer_view_with(target, |bin| extend_f32(bin, values));
        let mut acc = json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": values.len() / width,
            "type": type_name,
        });
        if with_bounds {
            let (lo, hi) = bounds(values, width);
            acc["min"] = json!(lo);
            acc["max"] = json!(hi);
        }
        self.accessors.push(acc);
        Ok(self.accessors.len() - 1)
    }

    /// VEC3 float vertex attribute with `min`/`max` (positions, morph target deltas).
    pub fn accessor_vec3(&mut self, values: &[[f32; 3]]) -> Result<usize> {
        self.accessor_f32(values.as_flattened(), "VEC3", true, Some(ARRAY_BUFFER))
    }

    /// VEC3 float vertex attribute without bounds (normals).
    pub fn accessor_vec3_unbounded(&mut self, values: &[[f32; 3]]) -> Result<usize> {
        self.accessor_f32(values.as_flattened(), "VEC3", false, Some(ARRAY_BUFFER))
    }

    /// VEC2 float vertex attribute (texture coordinates).
    pub fn accessor_vec2(&mut self, values: &[[f32; 2]]) -> Result<usize> {
        self.accessor_f32(values.as_flattened(), "VEC2", false, Some(ARRAY_BUFFER))
    }

    /// SCALAR float data with `min`/`max` and no target (animation sampler input/output).
    pub fn accessor_scalar(&mut self, values: &[f32]) -> Result<usize> {
        self.accessor_f32(values, "SCALAR", true, None)
    }

    /// Index accessor: u16 when every index fits below 65535 (the largest value of a type is
    /// reserved for primitive restart and forbidden in glTF), else u32.
    pub fn accessor_indices(&mut self, indices: &[u32]) -> Result<usize> {
        if indices.is_empty() {
            return Err(Error::Internal("index accessor needs at least one index".into()));
        }
        let max = indices.iter().copied().max().unwrap_or(0);
        if max == u32::MAX {
            return Err(Error::Internal("index 4294967295 is reserved in glTF".into()));
        }
        let small = max < u32::from(u16::MAX);
        let view = self.buffer_view_with(Some(ELEMENT_ARRAY_BUFFER), |bin| {
            bin.reserve(indices.len() * if small { 2 } else { 4 });
            for &i in indices {
                if small {
                    bin.extend_from_slice(&(i as u16).to_le_bytes());
                } else {
                    bin.extend_from_slice(&i.to_le_bytes());
                }
            }
        });
        let ctype = if small { UNSIGNED_SHORT } else { UNSIGNED_INT };
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": ctype,
            "count": indices.len(),
            "type": "SCALAR",
        }));
        Ok(self.accessors.len() - 1)
    }

    /// Adds a raw accessor object (for layouts the helpers above do not cover).
    pub fn accessor_raw(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Adds a glTF mesh object (`{"name"?, "primitives": [...], "weights"?}`); returns its index.
    pub fn mesh(&mut self, mesh: Value) -> usize {
        self.meshes.push(mesh);
        self.meshes.len() - 1
    }

    pub fn mesh_mut(&mut self, index: usize) -> Option<&mut Value> {
        self.meshes.get_mut(index)
    }

    /// Adds a node object; returns its index. Call [`GltfBuilder::add_root`] to put it in the scene.
    pub fn node(&mut self, node: Value) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    pub fn node_mut(&mut self, index: usize) -> Option<&mut Value> {
        self.nodes.get_mut(index)
    }

    /// Makes `node` a root of the (single) scene.
    pub fn add_root(&mut self, node: usize) {
        self.scene_nodes.push(node);
    }

    /// Adds an animation object (`{"channels": [...], "samplers": [...]}`); returns its index.
    pub fn animation(&mut self, animation: Value) -> usize {
        self.animations.push(animation);
        self.animations.len() - 1
    }

    /// Declares an extension in `extensionsUsed` (and `extensionsRequired` when `required`).
    pub fn use_extension(&mut self, name: &str, required: bool) {
        if !self.extensions_used.iter().any(|e| e == name) {
            self.extensions_used.push(name.to_owned());
        }
        if required && !self.extensions_required.iter().any(|e| e == name) {
            self.extensions_required.push(name.to_owned());
        }
    }

    /// Binary data so far (length before final padding).
    pub fn bin_len(&self) -> usize {
        self.bin.len()
    }

    /// The glTF JSON document; `buffer_uri` is the `uri` of buffer 0 (`None` for GLB).
    pub fn to_json(&self, buffer_uri: Option<String>) -> Value {
        let mut root = Map::new();
        root.insert("asset".into(), json!({ "version": "2.0", "generator": "meshwork" }));
        // glTF forbids empty arrays: only emit what is there.
        let mut put = |key: &str, items: &[Value]| {
            if !items.is_empty() {
                root.insert(key.into(), Value::Array(items.to_vec()));
            }
        };
        if !self.extensions_used.is_empty() {
            put("extensionsUsed", &self.extensions_used.iter().map(|e| json!(e)).collect::<Vec<_>>());
        }
        if !self.extensions_required.is_empty() {
            put("extensionsRequired", &self.extensions_required.iter().map(|e| json!(e)).collect::<Vec<_>>());
        }
        if !self.scene_nodes.is_empty() {
            put("scenes", &[json!({ "nodes": self.scene_nodes })]);
        }
        put("nodes", &self.nodes);
        put("meshes", &self.meshes);
        put("animations", &self.animations);
        put("accessors", &self.accessors);
        put("bufferViews", &self.buffer_views);
        if !self.bin.is_empty() {
            let mut buffer = json!({ "byteLength": self.bin.len() });
            if let Some(uri) = buffer_uri {
                buffer["uri"] = json!(uri);
            }
            put("buffers", &[buffer]);
        }
        if !self.scene_nodes.is_empty() {
            root.insert("scene".into(), json!(0));
        }
        Value::Object(root)
    }

    /// Assembles a GLB: 12-byte header, JSON chunk padded with spaces, BIN chunk padded with zeros.
    pub fn finish_glb(self) -> Vec<u8> {
        let mut json = serde_json::to_vec(&self.to_json(None)).unwrap_or_default();
        pad_to_4(&mut json, b' ');
        let mut bin = self.bin;
        pad_to_4(&mut bin, 0);
        let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len() };
        let total = 12 + 8 + json.len() + bin_chunk;
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        if !bin.is_empty() {
            out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            out.extend_from_slice(b"BIN\0");
            out.extend_from_slice(&bin);
        }
        out
    }

    /// Assembles glTF JSON with the buffer embedded as a base64 `data:` URI.
    pub fn finish_gltf(self) -> Vec<u8> {
        let uri = format!("data:application/octet-stream;base64,{}", base64::encode(&self.bin));
        serde_json::to_vec_pretty(&self.to_json(Some(uri))).unwrap_or_default()
    }
}

/// What [`add_mesh`] put into the builder.
#[derive(Debug, Clone, Default)]
pub struct AddedMesh {
    /// Shared vertex attribute accessors (every primitive uses these).
    pub position: Option<usize>,
    pub normal: Option<usize>,
    pub texcoord: Option<usize>,
    /// glTF meshes created: one per non-empty face group, then one for the curves if any.
    pub meshes: Vec<usize>,
    /// Nodes created (one per glTF mesh, each a scene root with the same name).
    pub nodes: Vec<usize>,
}

/// Adds `mesh` to the builder in meshwork's layout; see [`super::write`] for the layout and
/// what is lost (polygons are fan-triangulated, positions become f32).
pub fn add_mesh(b: &mut GltfBuilder, mesh: &Mesh) -> Result<AddedMesh> {
    super::write::add_mesh(b, mesh)
}
