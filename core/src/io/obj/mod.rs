//! OBJ reading and writing.
//!
//! Reading is hand-written for speed: lines are split with `memchr`, and files of 4 MB or more are
//! cut into newline-aligned chunks parsed in parallel ([`parse_chunk`]), then stitched together
//! ([`Stitcher`]) in file order. Everything that depends on what came before a chunk (negative
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

mod writer;
pub use writer::write;

use memchr::memchr;
use rayon::prelude::*;
use std::collections::HashMap;

use super::lex::{self, Tokens};
use super::{Format, Loaded, ReadOptions};
use crate::error::{Error, Location, Result};
use crate::mesh::{Faces, Mesh};

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

// ---------------------------------------------------------------------------------------------
// Per-chunk parsing
// ---------------------------------------------------------------------------------------------

/// Which index array a relative (negative) index lives in.
#[derive(Clone, Copy, Debug)]
enum Slot {
    Vertex,
    Uv,
    Normal,
    /// Curve number (within the chunk).
    Curve(u32),
}

/// A negative OBJ index, relative to the chunk start until the stitcher knows the counts before it.
#[derive(Debug)]
struct Fixup {
    slot: Slot,
    /// Position in the corner array (or in the curve).
    pos: usize,
    /// Index relative to the first element of its kind in this chunk (may be negative).
    rel: i64,
    line: usize,
}

/// What one chunk of lines contains, with indices either absolute (positive OBJ indices, made
/// 0-based) or recorded as fixups.
#[derive(Default, Debug)]
struct Chunk {
    lines: usize,
    positions: Vec<[f64; 3]>,
    uvs: Vec<[f64; 2]>,
    normals: Vec<[f64; 3]>,
    /// End of each face in `corners` (chunk-local).
    face_ends: Vec<u32>,
    corners: Vec<u32>,
    /// Per-corner `vt`/`vn` index, created at the first corner that has one.
    corner_uv: Option<Vec<u32>>,
    corner_normal: Option<Vec<u32>>,
    curves: Vec<Vec<u32>>,
    fixups: Vec<Fixup>,
    /// (first face of the run, group name) for every `g`/`o` line.
    group_runs: Vec<(usize, String)>,
    /// Ignored statements by keyword.
    ignored: Vec<(String, usize)>,
    /// `v` lines with more than 4 numbers (vertex colours), ignored.
    vertex_extras: usize,
}

/// One parsed OBJ index: absolute 0-based, or relative to the chunk's first element.
enum Index {
    Abs(u32),
    Rel(i64),
}

fn parse_chunk(data: &[u8]) -> Result<Chunk> {
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
fn line_of_statement(data: &[u8], key: &[u8], k: usize) -> usize {
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

// ---------------------------------------------------------------------------------------------
// Stitching chunks together
// ---------------------------------------------------------------------------------------------

struct Stitcher<'a> {
    opts: &'a ReadOptions,
    line_offset: usize,
    positions: Vec<[f64; 3]>,
    uvs: Vec<[f64; 2]>,
    normals: Vec<[f64; 3]>,
    faces: Faces,
    corner_uv: Option<Vec<u32>>,
    corner_normal: Option<Vec<u32>>,
    curves: Vec<Vec<u32>>,
    group_ids: HashMap<String, u32>,
    group_names: Vec<String>,
    /// Name of the group faces go to now (None before the first `g`/`o`).
    current_group: Option<String>,
    ignored: Vec<(String, usize)>,
    vertex_extras: usize,
}

impl<'a> Stitcher<'a> {
    fn new(opts: &'a ReadOptions, chunks: &[Result<Chunk>]) -> Self {
        let ok = || chunks.iter().filter_map(|c| c.as_ref().ok());
        let nv: usize = ok().map(|c| c.positions.len()).sum();
        let nf: usize = ok().map(|c| c.face_ends.len()).sum();
        let ni: usize = ok().map(|c| c.corners.len()).sum();
        Stitcher {
            opts,
            line_offset: 0,
            positions: Vec::with_capacity(nv),
            uvs: Vec::new(),
            normals: Vec::new(),
            faces: Faces::with_capacity(nf, ni),
            corner_uv: None,
            corner_normal: None,
            curves: Vec::new(),
            group_ids: HashMap::new(),
            group_names: Vec::new(),
            current_group: None,
            ignored: Vec::new(),
            vertex_extras: 0,
        }
    }

    fn add(&mut self, mut c: Chunk) -> Result<()> {
        self.apply_fixups(&mut c)?;
        self.check_limits(&c)?;
        let corner_base = self.faces.indices().len();
        self.append_faces(&c);
        append_attr(&mut self.corner_uv, c.corner_uv.take(), corner_base, c.corners.len());
        append_attr(&mut self.corner_normal, c.corner_normal.take(), corner_base, c.corners.len());
        self.positions.extend_from_slice(&c.positions);
        self.uvs.extend_from_slice(&c.uvs);
        self.normals.extend_from_slice(&c.normals);
        self.curves.append(&mut c.curves);
        for (k, n) in c.ignored {
            match self.ignored.iter_mut().find(|(kk, _)| *kk == k) {
                Some((_, m)) => *m += n,
                None => self.ignored.push((k, n)),
            }
        }
        self.vertex_extras += c.vertex_extras;
        self.line_offset += c.lines;
        Ok(())
    }

    /// Turns the chunk's relative indices into absolute ones now that the counts before it are known.
    fn apply_fixups(&self, c: &mut Chunk) -> Result<()> {
        for f in &c.fixups {
            let (base, what) = match f.slot {
                Slot::Vertex | Slot::Curve(_) => (self.positions.len(), "vertex"),
                Slot::Uv => (self.uvs.len(), "texture coordinate"),
                Slot::Normal => (self.normals.len(), "normal"),
            };
            let abs = base as i64 + f.rel;
            let line = self.line_offset + f.line;
            let abs = u32::try_from(abs).map_err(|_| {
                invalid(line, format!("relative {what} index points before the first {what}"))
            })?;
            match f.slot {
                Slot::Vertex => c.corners[f.pos] = abs,
                Slot::Uv => set_attr(&mut c.corner_uv, f.pos, abs),
                Slot::Normal => set_attr(&mut c.corner_normal, f.pos, abs),
                Slot::Curve(ci) => c.curves[ci as usize][f.pos] = abs,
            }
        }
        Ok(())
    }

    fn check_limits(&self, c: &Chunk) -> Result<()> {
        let nv = (self.positions.len() + c.positions.len()) as u64;
        if nv > self.opts.max_vertices as u64 {
            return Err(too_large("vertices", self.opts.max_vertices, nv));
        }
        let nf = (self.faces.len() + c.face_ends.len()) as u64;
        if nf > self.opts.max_faces as u64 {
            return Err(too_large("faces", self.opts.max_faces, nf));
        }
        let ni = (self.faces.indices().len() + c.corners.len()) as u64;
        if ni >= u32::MAX as u64 {
            return Err(too_large("face corners", u32::MAX as usize - 1, ni));
        }
        Ok(())
    }

    fn append_faces(&mut self, c: &Chunk) {
        let mut runs = c.group_runs.iter().peekable();
        let mut group = None;
        let mut start = 0usize;
        for (fi, &end) in c.face_ends.iter().enumerate() {
            while let Some((_, name)) = runs.next_if(|(first, _)| *first <= fi) {
                self.current_group = Some(name.clone());
                group = None;
            }
            let g = match group {
                Some(g) => g,
                None => *group.insert(self.group_id_now()),
            };
            self.faces.push(&c.corners[start..end as usize], g);
            start = end as usize;
        }
        if let Some((_, name)) = runs.last() {
            self.current_group = Some(name.clone());
        }
    }

    /// The id of the current group, registering its name on first use (so groups that never
    /// receive a face do not appear).
    fn group_id_now(&mut self) -> u32 {
        let name = self.current_group.clone().unwrap_or_default();
        if let Some(&id) = self.group_ids.get(&name) {
            return id;
        }
        let id = self.group_names.len() as u32;
        self.group_ids.insert(name.clone(), id);
        self.group_names.push(name);
        id
    }

    /// Checks indices against the whole file (they may point forward), then builds the mesh.
    fn finish(self, bytes: &[u8]) -> Result<Loaded> {
        if self.positions.is_empty() {
            return Err(malformed(
                self.line_offset.max(1),
                "no `v` statements: the file defines no vertices",
            ));
        }
        self.check_ranges(bytes)?;
        let Stitcher { faces, positions, uvs, normals, curves, mut group_names, .. } = self;
        let mut warnings = Vec::new();
        let uvs = per_vertex(&faces, self.corner_uv.as_deref(), &uvs, positions.len(), "vt", &mut warnings);
        let normals =
            per_vertex(&faces, self.corner_normal.as_deref(), &normals, positions.len(), "vn", &mut warnings);
        // Group names only appear when some face was given one: a file without g/o keeps "one
        // unnamed group"; faces before the first g/o are in the group named "".
        if group_names.len() == 1 && group_names[0].is_empty() || faces.is_empty() {
            group_names.clear();
        }
        let degenerate =
            (0..faces.len()).into_par_iter().filter(|&i| distinct_count(faces.get(i)) < 3).count();
        if degenerate > 0 {
            warnings.push(format!(
                "{degenerate} faces repeat a vertex (fewer than 3 distinct); kept for validate/repair"
            ));
        }
        for (k, n) in &self.ignored {
            warnings.push(format!("ignored {n} `{k}` statements"));
        }
        if self.vertex_extras > 0 {
            warnings
                .push(format!("ignored extra values (vertex colours) on {} `v` lines", self.vertex_extras));
        }
        let mesh = Mesh { positions, faces, normals, uvs, groups: group_names, curves };
        Ok(Loaded { mesh, format: Format::Obj, warnings })
    }
}

impl Stitcher<'_> {
    /// Every index must name an element the file defines. An out-of-range index is reported at
    /// the line of its statement (found by counting `f`/`l` statements: only on this error path).
    fn check_ranges(&self, bytes: &[u8]) -> Result<()> {
        let checks: [(&[u32], usize, &str); 3] = [
            (self.faces.indices(), self.positions.len(), "vertex"),
            (self.corner_uv.as_deref().unwrap_or(&[]), self.uvs.len(), "texture coordinate"),
            (self.corner_normal.as_deref().unwrap_or(&[]), self.normals.len(), "normal"),
        ];
        for (idx, n, what) in checks {
            if let Some(k) = idx.iter().position(|&i| i != NONE && i as usize >= n) {
                let face = self.faces.offsets().partition_point(|&o| o as usize <= k) - 1;
                let line = line_of_statement(bytes, b"f", face);
                let i = idx[k] as u64 + 1;
                return Err(invalid(line, format!("{what} index {i} out of range (the file defines {n})")));
            }
        }
        let nv = self.positions.len();
        for (ci, c) in self.curves.iter().enumerate() {
            if let Some(&i) = c.iter().find(|&&i| i as usize >= nv) {
                let line = line_of_statement(bytes, b"l", ci);
                let i = i as u64 + 1;
                return Err(invalid(line, format!("vertex index {i} out of range (the file defines {nv})")));
            }
        }
        Ok(())
    }
}

fn too_large(what: &str, limit: usize, actual: u64) -> Error {
    Error::TooLarge { what: what.into(), limit: limit as u64, actual }
}

fn set_attr(arr: &mut Option<Vec<u32>>, pos: usize, v: u32) {
    if let Some(a) = arr.as_mut() {
        a[pos] = v;
    }
}

/// Appends a chunk's per-corner attribute array to the file's, filling NONE where one side has none.
fn append_attr(dst: &mut Option<Vec<u32>>, src: Option<Vec<u32>>, base: usize, len: usize) {
    match (dst.as_mut(), src) {
        (Some(d), Some(s)) => d.extend_from_slice(&s),
        (Some(d), None) => d.resize(base + len, NONE),
        (None, Some(s)) => {
            let mut d = vec![NONE; base];
            d.extend_from_slice(&s);
            *dst = Some(d);
        }
        (None, None) => {}
    }
}

fn distinct_count(f: &[u32]) -> usize {
    if f.len() <= 8 {
        (0..f.len()).filter(|&i| !f[..i].contains(&f[i])).count()
    } else {
        let mut s = f.to_vec();
        s.sort_unstable();
        s.dedup();
        s.len()
    }
}

/// A per-vertex attribute from per-corner indices, or None (with a warning) when corners disagree.
fn per_vertex<const N: usize>(
    faces: &Faces,
    corner: Option<&[u32]>,
    values: &[[f64; N]],
    nv: usize,
    key: &str,
    warnings: &mut Vec<String>,
) -> Option<Vec<[f64; N]>> {
    let Some(corner) = corner else {
        if !values.is_empty() {
            warnings.push(format!("{} `{key}` lines are not used by any face; ignored", values.len()));
        }
        return None;
    };
    let mut slot = vec![NONE; nv];
    let (mut missing, mut conflicts) = (0usize, 0usize);
    for (&v, &a) in faces.indices().iter().zip(corner) {
        if a == NONE {
            missing += 1;
            continue;
        }
        let s = &mut slot[v as usize];
        if *s == NONE {
            *s = a;
        } else if *s != a && values[*s as usize] != values[a as usize] {
            conflicts += 1;
        }
    }
    if conflicts > 0 {
        warnings.push(format!(
            "`{key}` dropped: {conflicts} face corners give a vertex a different `{key}` than another corner \
             (seams/creases); vertices are not split so that indices stay the file's"
        ));
        return None;
    }
    if missing > 0 {
        warnings.push(format!("`{key}` dropped: {missing} face corners have none while others do"));
        return None;
    }
    Some(slot.iter().map(|&s| if s == NONE { [0.0; N] } else { values[s as usize] }).collect())
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
