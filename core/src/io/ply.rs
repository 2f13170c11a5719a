//! PLY reading and writing.

use super::{Loaded, ReadOptions};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Decodes PLY bytes.
pub fn read(_bytes: &[u8], _opts: &ReadOptions) -> Result<Loaded> {
    Err(Error::UnsupportedFormat("reading PLY not implemented yet".into()))
}

/// Encodes `mesh` (binary little-endian).
pub fn write(_mesh: &Mesh) -> Result<Vec<u8>> {
    Err(Error::UnsupportedFormat("writing PLY not implemented yet".into()))
}
