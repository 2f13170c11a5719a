//! glTF 2.0: `.glb` and `.gltf` with embedded `data:` buffers, read and written by hand on top of
//! `serde_json` (no glTF crate: fewer dependencies, and errors that name the JSON path of the
//! problem, e.g. `meshes[0].primitives[1].indices`).
//!
//! - [`read`]: every mesh instance of the scene flattened into one [`Mesh`] with node transforms
//!   applied; one face group per triangle primitive; lines as curves. See [`read`] module docs.
//! - [`write_glb`] / [`write_gltf`]: see [`write`] for the layout; polygons are fan-triangulated
//!   and positions become f32.
//! - [`builder`]: the document builder the writer uses, for jobs that add more (morph targets,
//!   animations).
//!
//! Security: a buffer `uri` that is a file path or URL is refused with
//! [`crate::Error::ExternalReference`] and never opened.

mod accessor;
pub(crate) mod base64;
pub mod builder;
mod glb;
mod json;
mod read;
mod transform;
pub mod write;

pub use read::read;
pub use write::{write_glb, write_gltf};
