//! OBJ reading and writing.

use super::{Loaded, ReadOptions};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Decodes OBJ bytes.
pub fn read(_bytes: &[u8], _opts: &ReadOptions) -> Result<Loaded> {
    Err(Error::UnsupportedFormat("reading OBJ not implemented yet".into()))
}

/// Encodes `mesh`.
pub fn write(_mesh: &Mesh) -> Result<Vec<u8>> {
    Err(Error::UnsupportedFormat("writing OBJ not implemented yet".into()))
}
