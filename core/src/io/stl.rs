//! STL reading and writing.

use super::{Loaded, ReadOptions};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Decodes STL bytes.
pub fn read(_bytes: &[u8], _opts: &ReadOptions) -> Result<Loaded> {
    Err(Error::UnsupportedFormat("reading STL not implemented yet".into()))
}

/// Encodes `mesh` (binary; polygons fan-triangulated).
pub fn write(_mesh: &Mesh) -> Result<Vec<u8>> {
    Err(Error::UnsupportedFormat("writing STL not implemented yet".into()))
}
