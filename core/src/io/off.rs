//! OFF reading and writing.
//!
//! Read: a header keyword (`OFF`, or a variant such as `COFF`, `NOFF`, `CNOFF`, `STOFF`), the
//! counts `nv nf ne` (on the header line or the next), then one vertex per line and one face per
//! line (`k i1 … ik`, trailing colour values ignored). `#` starts a comment anywhere; blank lines
//! are skipped. With `N` in the keyword the three values after x y z are the normal. Only the
//! text form is read: `OFF BINARY` is refused as unsupported.

use super::lex::{self, Tokens};
use super::{Format, Loaded, ReadOptions};
use crate::error::{Error, Location, Result};
use crate::mesh::{Faces, Mesh};

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

fn err(line: usize, msg: impl Into<String>) -> Error {
    Error::malformed("off", Location::Line(line), msg)
}

/// Non-empty lines with comments removed, numbered from 1.
struct Lines<'a> {
    rest: &'a [u8],
    line: usize,
}

impl<'a> Lines<'a> {
    /// The next line with content, as (line number, tokens); None at the end of the file.
    fn next_content(&mut self) -> Option<(usize, Tokens<'a>)> {
        while !self.rest.is_empty() {
            let end = memchr::memchr(b'\n', self.rest).unwrap_or(self.rest.len());
            let line = &self.rest[..end];
            self.rest = &self.rest[(end + 1).min(self.rest.len())..];
            self.line += 1;
            let line = &line[..memchr::memchr(b'#', line).unwrap_or(line.len())];
            let t = Tokens::new(line);
            if t.clone().next().is_some() {
                return Some((self.line, t));
            }
        }
        None
    }
}

fn count(tok: Option<&[u8]>, what: &str, n: usize) -> Result<u64> {
    tok.and_then(lex::parse_u64).ok_or_else(|| err(n, format!("expected the {what} count")))
}

/// Decodes OFF bytes.
pub fn read(bytes: &[u8], opts: &ReadOptions) -> Result<Loaded> {
    let mut lines = Lines { rest: bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes), line: 0 };
    let (hn, mut t) = lines.next_content().ok_or_else(|| err(1, "empty file"))?;
    let key = t.next().unwrap_or(b"");
    if !(key.ends_with(b"OFF") && key.len() <= 8) {
        return Err(err(hn, "missing `OFF` header"));
    }
    let has_normals = key[..key.len() - 3].contains(&b'N');
    if t.clone().next() == Some(b"BINARY") {
        return Err(Error::UnsupportedFormat("binary OFF is not supported; use the text form".into()));
    }
    let (cn, mut t) = if t.clone().next().is_some() {
        (hn, t)
    } else {
        lines.next_content().ok_or_else(|| err(lines.line, "file ends before the counts line"))?
    };
    let nv = count(t.next(), "vertex", cn)?;
    let nf = count(t.next(), "face", cn)?;
    if nv > opts.max_vertices as u64 {
        return Err(Error::TooLarge { what: "vertices".into(), limit: opts.max_vertices as u64, actual: nv });
    }
    if nf > opts.max_faces as u64 {
        return Err(Error::TooLarge { what: "faces".into(), limit: opts.max_faces as u64, actual: nf });
    }
    if nv == 0 {
        return Err(err(cn, "no vertices"));
    }
    let (positions, normals) = read_vertices(&mut lines, nv, has_normals)?;
    let faces = read_faces(&mut lines, nf, nv)?;
    let mut warnings = Vec::new();
    if lines.next_content().is_some() {
        warnings.push(format!("ignored content after the {nf} declared faces"));
    }
    let mesh = Mesh { positions, faces, normals, ..Default::default() };
    Ok(Loaded { mesh, format: Format::Off, warnings })
}

/// Capacity for `count` lines of at least `min` bytes, given the bytes left.
fn cap(count: u64, min: usize, lines: &Lines) -> usize {
    count.min((lines.rest.len() / min) as u64) as usize
}

type Vertices = (Vec<[f64; 3]>, Option<Vec<[f64; 3]>>);

fn read_vertices(lines: &mut Lines, nv: u64, has_normals: bool) -> Result<Vertices> {
    let mut positions = Vec::with_capacity(cap(nv, 6, lines));
    let mut normals = has_normals.then(|| Vec::with_capacity(positions.capacity()));
    for i in 0..nv {
        let (n, mut t) = lines
            .next_content()
            .ok_or_else(|| err(lines.line, format!("file ends after {i} of {nv} declared vertices")))?;
        let p = numbers(&mut t, n)?;
        positions.push(p);
        if let Some(nr) = normals.as_mut() {
            nr.push(numbers(&mut t, n)?);
        }
    }
    Ok((positions, normals))
}

fn numbers(t: &mut Tokens, n: usize) -> Result<[f64; 3]> {
    let mut p = [0.0; 3];
    for c in &mut p {
        let tok = t.next().ok_or_else(|| err(n, "a vertex needs 3 numbers"))?;
        *c = lex::parse_f64(tok)
            .ok_or_else(|| err(n, format!("`{}` is not a number", String::from_utf8_lossy(tok))))?;
        if !c.is_finite() {
            return Err(Error::InvalidMesh {
                location: Location::Line(n),
                message: "NaN or infinite value".into(),
            });
        }
    }
    Ok(p)
}

fn read_faces(lines: &mut Lines, nf: u64, nv: u64) -> Result<Faces> {
    let c = cap(nf, 8, lines);
    let mut faces = Faces::with_capacity(c, c * 3);
    let mut face = Vec::with_capacity(8);
    for i in 0..nf {
        let (n, mut t) = lines
            .next_content()
            .ok_or_else(|| err(lines.line, format!("file ends after {i} of {nf} declared faces")))?;
        let k = count(t.next(), "face vertex", n)?;
        if k < 3 {
            return Err(err(n, format!("face has {k} vertices, at least 3 are needed")));
        }
        face.clear();
        for _ in 0..k {
            let tok = t.next().ok_or_else(|| err(n, format!("face declares {k} vertices, fewer follow")))?;
            let v = lex::parse_i64(tok)
                .ok_or_else(|| err(n, format!("`{}` is not a vertex index", String::from_utf8_lossy(tok))))?;
            if v < 0 || v as u64 >= nv {
                return Err(Error::InvalidMesh {
                    location: Location::Line(n),
                    message: format!("vertex index {v} out of range ({nv} vertices)"),
                });
            }
            face.push(v as u32);
        }
        if faces.indices().len() + face.len() >= u32::MAX as usize {
            return Err(Error::TooLarge {
                what: "face corners".into(),
                limit: u32::MAX as u64 - 1,
                actual: u32::MAX as u64,
            });
        }
        faces.push(&face, 0);
    }
    Ok(faces)
}

/// Encodes `mesh` as text OFF (`NOFF` with per-vertex normals when the mesh has them), numbers in
/// shortest round-trip form. OFF has no groups, texture coordinates or polylines: they are not written.
pub fn write(mesh: &Mesh) -> Result<Vec<u8>> {
    mesh.check()?;
    let mut out = Vec::with_capacity(mesh.positions.len() * 40 + mesh.faces.indices().len() * 8 + 64);
    out.extend_from_slice(if mesh.normals.is_some() { b"NOFF\n" } else { b"OFF\n" });
    out.extend_from_slice(format!("{} {} 0\n", mesh.positions.len(), mesh.faces.len()).as_bytes());
    let mut buf = ryu::Buffer::new();
    for (i, p) in mesh.positions.iter().enumerate() {
        let n = mesh.normals.as_ref().map(|n| n[i]);
        for (k, &c) in p.iter().chain(n.iter().flatten()).enumerate() {
            if k > 0 {
                out.push(b' ');
            }
            lex::push_f64(&mut out, &mut buf, c);
        }
        out.push(b'\n');
    }
    for f in mesh.faces.iter() {
        lex::push_u64(&mut out, f.len() as u64);
        for &i in f {
            out.push(b' ');
            lex::push_u64(&mut out, i as u64);
        }
        out.push(b'\n');
    }
    Ok(out)
}
