//! glTF 2.0 / GLB reading and writing.

use super::{Loaded, ReadOptions};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Decodes glTF 2.0 / GLB bytes.
pub fn read(_bytes: &[u8], _opts: &ReadOptions) -> Result<Loaded> {
    Err(Error::UnsupportedFormat("reading glTF 2.0 / GLB not implemented yet".into()))
}

/// Encodes `mesh` as GLB.
pub fn write_glb(_mesh: &Mesh) -> Result<Vec<u8>> {
    Err(Error::UnsupportedFormat("writing glTF 2.0 / GLB not implemented yet".into()))
}

/// Encodes `mesh` as glTF JSON with an embedded data: buffer.
pub fn write_gltf(_mesh: &Mesh) -> Result<Vec<u8>> {
    Err(Error::UnsupportedFormat("writing glTF 2.0 / GLB not implemented yet".into()))
}
