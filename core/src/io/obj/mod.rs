//! OBJ reading and writing.
//!
//! Reading is hand-written for speed: lines are split with `memchr`, and files of 4 MB or more are
//! cut into newline-aligned chunks parsed in parallel ([`chunk::parse_chunk`]), then stitched
//! together ([`stitch::Stitcher`]) in file order. Everything that depends on what came before a chunk (negative
//! indices, the current group, line numbers) is resolved while stitching.
//!
//! What we keep: `v` (positions; a 4th `w` or trailing colours are ignored and counted), `vt`, `vn`,
//! `f` (polygons kept as given, any arity ≥ 3), `l` (polylines → [`Mesh::curves`]), `g`/`o` (both
//! name the group of the faces that follow). Every other statement (`usemtl`, `mtllib`, `s`, `p`,
//! free-form geometry, …) is ignored and counted in the warnings.
//!
//! Vertex indices stay the file's. OBJ indexes texture coordinates and normals per face corner;
//! a [`Mesh`] has them per vertex. When every corner of a vertex agrees we keep the attribute;
//! when some vertex is used with two different `vt` (a texture seam) or `vn` (a crease) we drop
//! that attribute with a warning instead of splitting vertices (which would renumber them).
//! Faces whose corners repeat a vertex are kept (validation counts them as degenerate, repair
//! drops them); faces with fewer than 3 corners are an error.

mod chunk;
mod stitch;
mod writer;
pub use writer::write;

use memchr::memchr;
use rayon::prelude::*;

use super::lex::Tokens;
use super::{Loaded, ReadOptions};
use crate::error::{Error, Location, Result};
use chunk::{parse_chunk, Chunk};
use stitch::Stitcher;

/// Files at least this large are parsed in parallel chunks.
const PARALLEL_BYTES: usize = 4 << 20;
/// "No attribute index" in per-corner attribute arrays.
const NONE: u32 = u32::MAX;

/// True when the first statement (after comments and blank lines) is an OBJ keyword.
pub(crate) fn looks_like_obj(text: &[u8]) -> bool {
    const KEYS: &[&[u8]] =
        &[b"v", b"vt", b"vn", b"vp", b"f", b"l", b"p", b"g", b"o", b"s", b"usemtl", b"mtllib"];
    for line in text.split(|&b| b == b'\n').take(1000) {
        let line = line.split(|&b| b == b'#').next().unwrap_or(b"");
        if let Some(key) = Tokens::new(line).next() {
            return KEYS.contains(&key);
        }
    }
    false
}

/// Decodes OBJ bytes.
pub fn read(bytes: &[u8], opts: &ReadOptions) -> Result<Loaded> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let joined = join_continuations(bytes);
    let bytes: &[u8] = &joined;
    let target = (bytes.len() / (4 * rayon::current_num_threads().max(1))).max(1 << 20);
    #[allow(clippy::single_range_in_vec_init)] // one range = the whole file, sequentially
    let ranges =
        if bytes.len() < PARALLEL_BYTES { vec![0..bytes.len()] } else { chunk_ranges(bytes, target) };
    read_chunks(bytes, opts, &ranges)
}

/// Joins lines continued with a trailing backslash (`v 1 2 \` + newline + `3`), which the OBJ
/// format allows. The backslash and its line break become spaces and the line break is re-emitted
/// after the end of the joined line, so every line after it keeps its number (and an error inside
/// a joined statement is reported at its first line). Borrowed unchanged when there is nothing to
/// join, which is nearly always.
fn join_continuations(bytes: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    let continued = |i: usize| match bytes.get(i + 1) {
        Some(b'\n') => Some(2),
        Some(b'\r') if bytes.get(i + 2) == Some(&b'\n') => Some(3),
        _ => None,
    };
    if !memchr::memchr_iter(b'\\', bytes).any(|i| continued(i).is_some()) {
        return std::borrow::Cow::Borrowed(bytes);
    }
    let mut out = Vec::with_capacity(bytes.len());
    let mut pending = 0usize;
    let mut i = 0;
    while i < bytes.len() {
        let b = bytes[i];
        if b == b'\\' {
            if let Some(len) = continued(i) {
                out.extend(std::iter::repeat_n(b' ', len));
                pending += 1;
                i += len;
                continue;
            }
        }
        out.push(b);
        if b == b'\n' {
            out.extend(std::iter::repeat_n(b'\n', pending));
            pending = 0;
        }
        i += 1;
    }
    out.extend(std::iter::repeat_n(b'\n', pending));
    std::borrow::Cow::Owned(out)
}

/// Parses the given newline-aligned ranges (in parallel when there are several) and stitches them.
fn read_chunks(bytes: &[u8], opts: &ReadOptions, ranges: &[std::ops::Range<usize>]) -> Result<Loaded> {
    let chunks: Vec<Result<Chunk>> = if ranges.len() > 1 {
        ranges.par_iter().map(|r| parse_chunk(&bytes[r.clone()])).collect()
    } else {
        ranges.iter().map(|r| parse_chunk(&bytes[r.clone()])).collect()
    };
    let mut st = Stitcher::new(opts, &chunks);
    for chunk in chunks {
        match chunk {
            Ok(c) => st.add(c)?,
            Err(e) => return Err(shift_line(e, st.line_offset)),
        }
    }
    st.finish(bytes)
}

/// Newline-aligned byte ranges of about `target` bytes covering `bytes`.
fn chunk_ranges(bytes: &[u8], target: usize) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    while start < bytes.len() {
        let guess = (start + target).min(bytes.len());
        let end = match memchr(b'\n', &bytes[guess..]) {
            Some(i) if guess < bytes.len() => guess + i + 1,
            _ => bytes.len(),
        };
        out.push(start..end);
        start = end;
    }
    out
}

/// Adds the lines of the chunks before this one to an error's line number.
fn shift_line(e: Error, offset: usize) -> Error {
    match e {
        Error::Malformed { format, location: Location::Line(l), message } => {
            Error::Malformed { format, location: Location::Line(l + offset), message }
        }
        Error::InvalidMesh { location: Location::Line(l), message } => {
            Error::InvalidMesh { location: Location::Line(l + offset), message }
        }
        e => e,
    }
}

fn malformed(line: usize, msg: impl Into<String>) -> Error {
    Error::malformed("obj", Location::Line(line), msg)
}

fn invalid(line: usize, msg: impl Into<String>) -> Error {
    Error::InvalidMesh { location: Location::Line(line), message: msg.into() }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_str(s: &str) -> Result<Loaded> {
        read(s.as_bytes(), &ReadOptions::default())
    }

    fn line_of(e: &Error) -> Option<usize> {
        match e {
            Error::Malformed { location: Location::Line(l), .. }
            | Error::InvalidMesh { location: Location::Line(l), .. } => Some(*l),
            _ => None,
        }
    }

    #[test]
    fn reads_polygons_groups_curves_and_negative_indices() {
        let src = "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng top\nf 1 2 3 4\n\
                   g side\nv 0 0 1\nf -5 -4 -1\nl 1 5\ng top\nvt 0.5 0.5\nf 2/1 3 5\n";
        let l = read_str(src).unwrap();
        assert!(l.warnings.iter().any(|w| w.contains("have none")), "{:?}", l.warnings);
        let m = l.mesh;
        assert!(m.uvs.is_none());
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.faces.len(), 3);
        assert_eq!(m.faces.get(0), &[0, 1, 2, 3]);
        assert_eq!(m.faces.get(1), &[0, 1, 4]);
        assert_eq!(m.groups, vec!["top".to_string(), "side".to_string()]);
        assert_eq!(m.faces.groups(), &[0, 1, 0]);
        assert_eq!(m.curves, vec![vec![0, 4]]);
    }

    #[test]
    fn backslash_continues_a_line_and_later_line_numbers_stay() {
        let l = read_str("v 0 0 0\nv 1 0 \\\n 0\nv 0 1 0\r\nf 1 \\\r\n2 3\n").unwrap();
        assert_eq!(l.mesh.positions, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(l.mesh.faces.get(0), &[0, 1, 2]);
        // Line 5 (1-based) is the bad one: the continuation on line 2 must not shift it.
        let e = read_str("v 0 0 0\nv 1 0 \\\n 0\nv 0 1 0\nv x 1 0\n").unwrap_err();
        assert_eq!(line_of(&e), Some(5), "{e}");
        // A backslash that does not end a line is an ordinary character (here: not a number).
        assert!(read_str("v 0 \\ 0 0\n").is_err());
    }

    #[test]
    fn errors_carry_line_numbers() {
        let e = read_str("v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap_err();
        assert!(matches!(e, Error::Malformed { .. }), "{e}");
        assert_eq!(line_of(&e), Some(3));
        let e = read_str("v 0 0 0\n\nv nan 0 0\n").unwrap_err();
        assert!(matches!(e, Error::InvalidMesh { .. }), "{e}");
        assert_eq!(line_of(&e), Some(3));
        let e = read_str("v 0 0 0\nf 1 -2 1\n").unwrap_err();
        assert_eq!(line_of(&e), Some(2), "{e}");
        let e = read_str("v 0 0 0\nv 0 x 0\n").unwrap_err();
        assert_eq!(line_of(&e), Some(2), "{e}");
    }

    /// A file with everything that crosses chunk boundaries: negative indices pointing into the
    /// previous chunk, groups opened in one chunk and used in the next, curves, per-corner normals.
    fn cross_chunk_source() -> String {
        let mut s = String::from("g first\n");
        for i in 0..3000 {
            let x = i as f64 * 0.1;
            s += &format!("v {x} {} 0\nv {x} {} 1\nvn 0 0 1\nvn 0 0 1\n", x * 0.5, x * 0.25);
            if i > 0 {
                s += "f -4//-1 -3//-2 -1//-1 -2//-2\n";
            }
            if i % 700 == 0 {
                s += &format!("g part{}\nl -1 -2 1\n", i % 3);
            }
            if i % 997 == 0 {
                s += "o\n# comment\nusemtl x\n\r\n";
            }
        }
        s
    }

    #[test]
    fn chunked_parse_equals_sequential() {
        let src = cross_chunk_source();
        let opts = ReadOptions::default();
        let whole = std::iter::once(0..src.len()).collect::<Vec<_>>();
        let one = read_chunks(src.as_bytes(), &opts, &whole).unwrap();
        for target in [1, 100, 997, 4096] {
            let ranges = chunk_ranges(src.as_bytes(), target);
            assert!(ranges.len() > 1);
            let many = read_chunks(src.as_bytes(), &opts, &ranges).unwrap();
            assert_eq!(one.mesh, many.mesh, "target {target}");
            assert_eq!(one.warnings, many.warnings);
        }
        let m = &one.mesh;
        assert_eq!(m.positions.len(), 6000);
        assert_eq!(m.faces.len(), 2999);
        assert_eq!(m.faces.get(0), &[0, 1, 3, 2]);
        assert_eq!(m.curves.len(), 5);
        assert_eq!(m.curves[0], vec![1, 0, 0]);
        // "o" with no name (right after "g part0") names the first faces' group ""; groups are
        // numbered by first use and reused by name.
        assert_eq!(m.groups, vec!["", "part1", "part2", "part0"]);
        assert_eq!(m.faces.group(0), 0);
        assert_eq!(m.faces.group(700), 1); // face of i=701 comes after "g part1"
        assert_eq!(m.faces.group(2998), 0); // after the last `o`
        assert!(m.normals.is_some());
        // An error in a later chunk still reports the file's line.
        let bad = format!("{src}v 1 2\n");
        let lines = src.lines().count();
        for target in [usize::MAX, 1000] {
            let ranges = chunk_ranges(bad.as_bytes(), target.min(bad.len()));
            let e = read_chunks(bad.as_bytes(), &opts, &ranges).unwrap_err();
            assert_eq!(line_of(&e), Some(lines + 1), "{e}");
        }
    }

    #[test]
    fn inconsistent_uvs_are_dropped_not_split() {
        let src = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 9 9\n\
                   f 1/1 2/2 3/3\nf 2/2 4/4 3/4\n";
        let l = read_str(src).unwrap();
        assert_eq!(l.mesh.positions.len(), 4);
        assert!(l.mesh.uvs.is_none());
        assert!(l.warnings.iter().any(|w| w.contains("`vt` dropped")), "{:?}", l.warnings);
        // Consistent (two vt lines with equal values count as the same).
        let src = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 0 0\nf 1/1 2/2 3/3\nf 1/4 3/3 2/2\n";
        let m = read_str(src).unwrap().mesh;
        assert_eq!(m.uvs, Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]));
    }
}
