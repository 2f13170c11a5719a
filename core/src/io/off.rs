//! OFF reading and writing.

use super::{Loaded, ReadOptions};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// True when the first token (after `#` comments) is an OFF header keyword: `OFF`, `COFF`,
/// `NOFF`, `CNOFF`, `STOFF`, `4OFF`, … (a short alphanumeric word ending in `OFF`).
pub(crate) fn looks_like_off(text: &[u8]) -> bool {
    for line in text.split(|&b| b == b'\n').take(1000) {
        let line = line.split(|&b| b == b'#').next().unwrap_or(b"");
        if let Some(tok) = line.split(|b| b.is_ascii_whitespace()).find(|t| !t.is_empty()) {
            return tok.ends_with(b"OFF") && tok.len() <= 8 && tok.iter().all(|b| b.is_ascii_alphanumeric());
        }
    }
    false
}

/// Decodes OFF bytes.
pub fn read(_bytes: &[u8], _opts: &ReadOptions) -> Result<Loaded> {
    Err(Error::UnsupportedFormat("reading OFF not implemented yet".into()))
}

/// Encodes `mesh`.
pub fn write(_mesh: &Mesh) -> Result<Vec<u8>> {
    Err(Error::UnsupportedFormat("writing OFF not implemented yet".into()))
}
