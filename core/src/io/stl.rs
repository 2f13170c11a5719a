//! STL reading and writing.

use super::{Loaded, ReadOptions};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// True when the length is exactly that of a binary STL with the triangle count in its header.
pub(crate) fn is_binary_size(bytes: &[u8]) -> bool {
    if bytes.len() < 84 {
        return false;
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    84 + 50 * n == bytes.len() as u64
}

/// True for text that starts with `solid` and has a `facet` or `endsolid` in its first kilobyte,
/// all of it printable ASCII (a binary header may start with "solid" too; its triangles will not be text).
pub(crate) fn looks_ascii(bytes: &[u8]) -> bool {
    let t = &bytes[bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len())..];
    let head = &t[..t.len().min(1024)];
    head.len() >= 5
        && head[..5].eq_ignore_ascii_case(b"solid")
        && head.iter().all(|&b| b.is_ascii_graphic() || b.is_ascii_whitespace())
        && (memchr::memmem::find(head, b"facet").is_some()
            || memchr::memmem::find(head, b"endsolid").is_some())
}

/// Decodes STL bytes.
pub fn read(_bytes: &[u8], _opts: &ReadOptions) -> Result<Loaded> {
    Err(Error::UnsupportedFormat("reading STL not implemented yet".into()))
}

/// Encodes `mesh` (binary; polygons fan-triangulated).
pub fn write(_mesh: &Mesh) -> Result<Vec<u8>> {
    Err(Error::UnsupportedFormat("writing STL not implemented yet".into()))
}
