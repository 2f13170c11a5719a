//! Parsing one newline-aligned chunk of an OBJ file into a [`Chunk`].
//!
//! A chunk is parsed without knowing what came before it, so that large files can be parsed in
//! parallel: positive indices are made 0-based right away, negative (relative) ones are recorded
//! as [`Fixup`]s, and line numbers are chunk-local. The [`super::stitch`] step resolves all three.

use memchr::memchr;

use super::{invalid, malformed, NONE};
use crate::error::Result;
use crate::io::lex::{self, Tokens};

/// Which index array a relative (negative) index lives in.
#[derive(Clone, Copy, Debug)]
pub(super) enum Slot {
    Vertex,
    Uv,
    Normal,
    /// Curve number (within the chunk).
    Curve(u32),
}

/// A negative OBJ index, relative to the chunk start until the stitcher knows the counts before it.
#[derive(Debug)]
pub(super) struct Fixup {
    pub(super) slot: Slot,
    /// Position in the corner array (or in the curve).
    pub(super) pos: usize,
    /// Index relative to the first element of its kind in this chunk (may be negative).
    pub(super) rel: i64,
    pub(super) line: usize,
}

/// What one chunk of lines contains, with indices either absolute (positive OBJ indices, made
/// 0-based) or recorded as fixups.
#[derive(Default, Debug)]
pub(super) struct Chunk {
    pub(super) lines: usize,
    pub(super) positions: Vec<[f64; 3]>,
    pub(super) uvs: Vec<[f64; 2]>,
    pub(super) normals: Vec<[f64; 3]>,
    /// End of each face in `corners` (chunk-local).
    pub(super) face_ends: Vec<u32>,
    pub(super) corners: Vec<u32>,
    /// Per-corner `vt`/`vn` index, created at the first corner that has one.
    pub(super) corner_uv: Option<Vec<u32>>,
    pub(super) corner_normal: Option<Vec<u32>>,
    pub(super) curves: Vec<Vec<u32>>,
    pub(super) fixups: Vec<Fixup>,
    /// (first face of the run, group name) for every `g`/`o` line.
    pub(super) group_runs: Vec<(usize, String)>,
    /// Ignored statements by keyword.
    pub(super) ignored: Vec<(String, usize)>,
    /// `v` lines with more than 4 numbers (vertex colours), ignored.
    pub(super) vertex_extras: usize,
}

/// One parsed OBJ index: absolute 0-based, or relative to the chunk's first element.
enum Index {
    Abs(u32),
    Rel(i64),
}

pub(super) fn parse_chunk(data: &[u8]) -> Result<Chunk> {
    let mut c = Chunk::default();
    let mut pos = 0;
    while pos < data.len() {
        let end = memchr(b'\n', &data[pos..]).map_or(data.len(), |i| pos + i);
        let line = &data[pos..end];
        pos = end + 1;
        c.lines += 1;
        let n = c.lines;
        parse_line(&mut c, line, n)?;
    }
    Ok(c)
}

fn parse_line(c: &mut Chunk, line: &[u8], n: usize) -> Result<()> {
    let line = match memchr(b'#', line) {
        Some(i) => &line[..i],
        None => line,
    };
    let mut toks = Tokens::new(line);
    let Some(key) = toks.next() else { return Ok(()) };
    match key {
        b"v" => parse_position(c, toks, n),
        b"vt" => parse_uv(c, toks, n),
        b"vn" => parse_normal(c, toks, n),
        b"f" => parse_face(c, toks, n),
        b"l" => parse_curve(c, toks, n),
        b"g" | b"o" => {
            let name = String::from_utf8_lossy(toks.rest()).into_owned();
            c.group_runs.push((c.face_ends.len(), name));
            Ok(())
        }
        other => {
            if let Some(&b) = other.iter().find(|&&b| b < 0x20 || b == 0x7f) {
                return Err(malformed(n, format!("binary data (byte 0x{b:02x}) in a text file")));
            }
            count_ignored(c, other);
            Ok(())
        }
    }
}

fn count_ignored(c: &mut Chunk, key: &[u8]) {
    match c.ignored.iter_mut().find(|(k, _)| k.as_bytes() == key) {
        Some((_, n)) => *n += 1,
        None => c.ignored.push((String::from_utf8_lossy(key).into_owned(), 1)),
    }
}

/// Reads `N` finite numbers; `min` of them are required.
fn numbers<const N: usize>(toks: &mut Tokens, min: usize, what: &str, n: usize) -> Result<[f64; N]> {
    let mut out = [0.0; N];
    for (k, slot) in out.iter_mut().enumerate() {
        match toks.next() {
            Some(t) => {
                let v = lex::parse_f64(t).ok_or_else(|| {
                    malformed(n, format!("`{what}`: `{}` is not a number", String::from_utf8_lossy(t)))
                })?;
                if !v.is_finite() {
                    return Err(invalid(n, format!("`{what}` coordinate is NaN or infinite")));
                }
                *slot = v;
            }
            None if k < min => {
                return Err(malformed(n, format!("`{what}` needs at least {min} numbers, found {k}")));
            }
            None => break,
        }
    }
    Ok(out)
}

fn parse_position(c: &mut Chunk, mut toks: Tokens, n: usize) -> Result<()> {
    let p = numbers::<3>(&mut toks, 3, "v", n)?;
    let _w = toks.next();
    if toks.next().is_some() {
        c.vertex_extras += 1;
    }
    c.positions.push(p);
    Ok(())
}

fn parse_uv(c: &mut Chunk, mut toks: Tokens, n: usize) -> Result<()> {
    let uv = numbers::<2>(&mut toks, 1, "vt", n)?;
    c.uvs.push(uv);
    Ok(())
}

fn parse_normal(c: &mut Chunk, mut toks: Tokens, n: usize) -> Result<()> {
    let nr = numbers::<3>(&mut toks, 3, "vn", n)?;
    c.normals.push(nr);
    Ok(())
}

/// One OBJ index (1-based, or negative = counted back from the last element defined so far).
#[inline]
fn parse_index(tok: &[u8], local_count: usize, what: &str, n: usize) -> Result<Index> {
    match lex::parse_i64(tok) {
        // The common case, kept small so it inlines into the face loop.
        Some(v) if v > 0 && v <= u32::MAX as i64 => Ok(Index::Abs((v - 1) as u32)),
        _ => parse_index_rare(tok, local_count, what, n),
    }
}

#[cold]
fn parse_index_rare(tok: &[u8], local_count: usize, what: &str, n: usize) -> Result<Index> {
    let v = lex::parse_i64(tok).ok_or_else(|| {
        malformed(n, format!("{what} index `{}` is not an integer", String::from_utf8_lossy(tok)))
    })?;
    match v {
        0 => Err(invalid(n, format!("{what} index 0 (OBJ indices start at 1)"))),
        v if v > 0 => Err(invalid(n, format!("{what} index {v} out of range"))),
        v => Ok(Index::Rel(local_count as i64 + v)),
    }
}

/// Stores an index at `pos` of the array `slot` (returns the value to store, recording a fixup
/// for relative indices).
fn place(c: &mut Chunk, idx: Index, slot: Slot, pos: usize, n: usize) -> u32 {
    match idx {
        Index::Abs(i) => i,
        Index::Rel(rel) => {
            c.fixups.push(Fixup { slot, pos, rel, line: n });
            0
        }
    }
}

/// Splits `v`, `v/vt`, `v//vn` or `v/vt/vn`.
#[inline]
fn split_corner(tok: &[u8]) -> (&[u8], Option<&[u8]>, Option<&[u8]>) {
    let Some(a) = tok.iter().position(|&b| b == b'/') else { return (tok, None, None) };
    let rest = &tok[a + 1..];
    let (vt, vn) = match rest.iter().position(|&b| b == b'/') {
        Some(b) => (&rest[..b], Some(&rest[b + 1..])),
        None => (rest, None),
    };
    (&tok[..a], Some(vt).filter(|t| !t.is_empty()), vn.filter(|t| !t.is_empty()))
}

fn parse_face(c: &mut Chunk, toks: Tokens, n: usize) -> Result<()> {
    let start = c.corners.len();
    for tok in toks {
        let (v, vt, vn) = split_corner(tok);
        let pos = c.corners.len();
        let vi = parse_index(v, c.positions.len(), "vertex", n)?;
        let vi = place(c, vi, Slot::Vertex, pos, n);
        c.corners.push(vi);
        let uv = match vt {
            Some(t) => {
                let i = parse_index(t, c.uvs.len(), "texture coordinate", n)?;
                Some(place(c, i, Slot::Uv, pos, n))
            }
            None => None,
        };
        push_attr(&mut c.corner_uv, uv, pos);
        let nr = match vn {
            Some(t) => {
                let i = parse_index(t, c.normals.len(), "normal", n)?;
                Some(place(c, i, Slot::Normal, pos, n))
            }
            None => None,
        };
        push_attr(&mut c.corner_normal, nr, pos);
    }
    let arity = c.corners.len() - start;
    if arity < 3 {
        return Err(malformed(n, format!("face has {arity} vertices, at least 3 are needed")));
    }
    let end =
        u32::try_from(c.corners.len()).map_err(|_| malformed(n, "too many face corners in one chunk"))?;
    c.face_ends.push(end);
    Ok(())
}

/// Appends a corner's attribute index, creating the array (back-filled with NONE) on first use.
fn push_attr(arr: &mut Option<Vec<u32>>, value: Option<u32>, pos: usize) {
    match (arr.as_mut(), value) {
        (Some(a), v) => a.push(v.unwrap_or(NONE)),
        (None, Some(v)) => {
            let mut a = vec![NONE; pos];
            a.push(v);
            *arr = Some(a);
        }
        (None, None) => {}
    }
}

fn parse_curve(c: &mut Chunk, toks: Tokens, n: usize) -> Result<()> {
    let ci = u32::try_from(c.curves.len()).map_err(|_| malformed(n, "too many curves"))?;
    let mut curve = Vec::new();
    for tok in toks {
        let (v, _, _) = split_corner(tok);
        let idx = parse_index(v, c.positions.len(), "vertex", n)?;
        let pos = curve.len();
        let value = place(c, idx, Slot::Curve(ci), pos, n);
        curve.push(value);
    }
    if curve.len() < 2 {
        return Err(malformed(n, format!("`l` has {} vertices, at least 2 are needed", curve.len())));
    }
    c.curves.push(curve);
    Ok(())
}

/// The 1-based line (within `data`) of the `k`-th (0-based) statement starting with `key`.
/// Used only to locate an error found after parsing, so speed does not matter.
pub(super) fn line_of_statement(data: &[u8], key: &[u8], k: usize) -> usize {
    let mut seen = 0;
    for (i, line) in data.split(|&b| b == b'\n').enumerate() {
        if Tokens::new(line).next() == Some(key) {
            if seen == k {
                return i + 1;
            }
            seen += 1;
        }
    }
    0
}
