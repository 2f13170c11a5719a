//! Mesh file formats. Reading detects the format from the content (the name is only a hint), and
//! every malformed input becomes an [`Error`] saying what and where, never a panic. Declared counts
//! in headers are never trusted for allocation: readers grow as data actually arrives.

use crate::error::{Error, Location, Result};
use crate::mesh::Mesh;

pub mod gltf;
mod lex;
pub mod obj;
pub mod off;
pub mod ply;
pub mod stl;
pub mod zip;

/// Formats we read and write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    Obj,
    /// glTF 2.0 JSON with embedded (`data:`) buffers.
    Gltf,
    /// Binary glTF.
    Glb,
    Ply,
    Stl,
    Off,
}

impl Format {
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Gltf => "gltf",
            Format::Glb => "glb",
            Format::Ply => "ply",
            Format::Stl => "stl",
            Format::Off => "off",
        }
    }

    pub fn mime(self) -> &'static str {
        match self {
            Format::Obj => "model/obj",
            Format::Gltf => "model/gltf+json",
            Format::Glb => "model/gltf-binary",
            Format::Ply => "application/x-ply",
            Format::Stl => "model/stl",
            Format::Off => "application/x-off",
        }
    }

    /// From a file extension or short name (`"glb"`, `"OBJ"`, `"mesh.ply"`).
    pub fn from_name(name: &str) -> Option<Format> {
        let ext = name.rsplit('.').next().unwrap_or(name).to_ascii_lowercase();
        Some(match ext.as_str() {
            "obj" => Format::Obj,
            "gltf" => Format::Gltf,
            "glb" => Format::Glb,
            "ply" => Format::Ply,
            "stl" => Format::Stl,
            "off" => Format::Off,
            _ => return None,
        })
    }

    /// From a MIME type (parameters after `;` ignored).
    pub fn from_mime(mime: &str) -> Option<Format> {
        let m = mime.split(';').next().unwrap_or("").trim().to_ascii_lowercase();
        Some(match m.as_str() {
            "model/obj" | "text/plain+obj" | "application/x-tgif" => Format::Obj,
            "model/gltf+json" => Format::Gltf,
            "model/gltf-binary" => Format::Glb,
            "application/x-ply" | "application/ply" | "model/x-ply" => Format::Ply,
            "model/stl" | "application/sla" | "model/x.stl-binary" | "model/x.stl-ascii" => Format::Stl,
            "application/x-off" | "model/off" => Format::Off,
            _ => return None,
        })
    }
}

/// Limits enforced while reading, before anything big is allocated.
#[derive(Debug, Clone)]
pub struct ReadOptions {
    /// File name or extension, used only when the content is ambiguous.
    pub name_hint: Option<String>,
    pub max_vertices: usize,
    pub max_faces: usize,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions { name_hint: None, max_vertices: 50_000_000, max_faces: 100_000_000 }
    }
}

/// A mesh as read, with the detected format and anything the reader had to say about it
/// (attributes it could not keep, primitives it skipped and why).
#[derive(Debug, Clone)]
pub struct Loaded {
    pub mesh: Mesh,
    pub format: Format,
    pub warnings: Vec<String>,
}

/// Reads a mesh from bytes, detecting the format from the content.
pub fn read(bytes: &[u8], opts: &ReadOptions) -> Result<Loaded> {
    let format = detect(bytes, opts.name_hint.as_deref())?;
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(Error::malformed(format_name(format), Location::Byte(0), "empty file"));
    }
    match format {
        Format::Obj => obj::read(bytes, opts),
        Format::Gltf | Format::Glb => gltf::read(bytes, opts),
        Format::Ply => ply::read(bytes, opts),
        Format::Stl => stl::read(bytes, opts),
        Format::Off => off::read(bytes, opts),
    }
}

/// The name used in [`Error::Malformed`] for a format.
pub(crate) fn format_name(f: Format) -> &'static str {
    // The name is the file extension.
    f.extension()
}

/// The format of `bytes`, from magic numbers and content; `name_hint` only decides when the
/// content matches no format (e.g. an empty or truncated file).
///
/// Order matters: GLB magic; binary STL by its exact size (84 + 50·n bytes; binary files often
/// start with "solid" too, so that prefix proves nothing); PLY magic; JSON with an `"asset"` key
/// (glTF); an OFF header; ASCII STL (`solid` then `facet`/`endsolid`); OBJ statements.
pub fn detect(bytes: &[u8], name_hint: Option<&str>) -> Result<Format> {
    if let Some(f) = detect_content(bytes) {
        return Ok(f);
    }
    if let Some(f) = name_hint.and_then(Format::from_name) {
        return Ok(f);
    }
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(Error::malformed("mesh", Location::Byte(0), "empty file"));
    }
    Err(Error::UnsupportedFormat(
        "content matches none of OBJ, glTF/GLB, PLY, STL, OFF (no magic number or known statements)".into(),
    ))
}

fn detect_content(bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(b"glTF") {
        return Some(Format::Glb);
    }
    if stl::is_binary_size(bytes) && !stl::looks_ascii(bytes) {
        return Some(Format::Stl);
    }
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = &text[text.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(text.len())..];
    if text.starts_with(b"ply\n") || text.starts_with(b"ply\r\n") {
        return Some(Format::Ply);
    }
    if text.starts_with(b"{") && memchr::memmem::find(text, b"\"asset\"").is_some() {
        return Some(Format::Gltf);
    }
    if off::looks_like_off(text) {
        return Some(Format::Off);
    }
    if stl::looks_ascii(text) {
        return Some(Format::Stl);
    }
    if obj::looks_like_obj(text) {
        return Some(Format::Obj);
    }
    None
}

/// The smallest extent (longest side of the bounding box) written in f32 (glTF, binary STL) when
/// it is not 0: below it the coordinates, and details a ten-millionth of the mesh, leave f32's
/// normal range (≈1.2e-38) and are written as a few bits or 0 (fuzzing, session 20: `convert` of
/// a mesh at 1e-300 wrote a GLB of zeros, exit 0).
pub const F32_MIN_EXTENT: f64 = 1e-30;

/// Writes a mesh in the given format.
pub fn write(mesh: &Mesh, format: Format) -> Result<Vec<u8>> {
    if matches!(format, Format::Glb | Format::Gltf | Format::Stl) {
        let (side, v) = mesh.longest_side();
        if side > 0.0 && side < F32_MIN_EXTENT {
            return Err(Error::InvalidMesh {
                location: Location::Vertex(v),
                message: format!(
                    "the mesh spans only {side:e} (the longest side of its bounding box, up to this vertex), \
                     below {F32_MIN_EXTENT:e}: {} stores f32 coordinates, which would flush it to 0; write OBJ, \
                     PLY or OFF to keep it, or rescale the mesh",
                    format.extension().to_uppercase()
                ),
            });
        }
    }
    match format {
        Format::Obj => obj::write(mesh),
        Format::Glb => gltf::write_glb(mesh),
        Format::Gltf => gltf::write_gltf(mesh),
        Format::Ply => ply::write(mesh),
        Format::Stl => stl::write(mesh),
        Format::Off => off::write(mesh),
    }
}
