//! PLY reading (ascii, binary little- and big-endian) and writing (binary little-endian).
//!
//! The header is parsed into [`Element`]s; the body is then read element by element through one
//! [`Body`] interface over the ascii token stream or the binary cursor, so both encodings share the
//! logic that maps properties to roles (x/y/z, normals, texture coordinates, face indices) and skips
//! everything else, including unknown elements and list properties.
//!
//! Declared counts are never trusted for allocation: capacity is capped by what the remaining
//! bytes can hold, and a binary body shorter than the header's counts demand is refused before
//! reading (a "lying header"), with the byte offset.

use super::lex::{self, Tokens};
use super::{Format, Loaded, ReadOptions};
use crate::error::{Error, Location, Result};
use crate::mesh::{Faces, Mesh};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    BinaryLe,
    BinaryBe,
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(s: &[u8]) -> Option<Ty> {
        Some(match s {
            b"char" | b"int8" => Ty::I8,
            b"uchar" | b"uint8" => Ty::U8,
            b"short" | b"int16" => Ty::I16,
            b"ushort" | b"uint16" => Ty::U16,
            b"int" | b"int32" => Ty::I32,
            b"uint" | b"uint32" => Ty::U32,
            b"float" | b"float32" => Ty::F32,
            b"double" | b"float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
}

/// What a property means to us.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    Pos(usize),
    Normal(usize),
    Uv(usize),
    FaceIndices,
    Skip,
}

#[derive(Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for list properties.
    list: Option<Ty>,
    ty: Ty,
    role: Role,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
    /// Header line declaring the element (for error messages).
    line: usize,
}

impl Element {
    /// The fewest bytes one binary record can take (lists may be empty).
    fn min_binary_size(&self) -> u64 {
        self.props.iter().map(|p| p.list.unwrap_or(p.ty).size() as u64).sum()
    }

    fn has(&self, role: Role) -> bool {
        self.props.iter().any(|p| p.role == role)
    }
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body: usize,
    /// Lines in the header (the ascii body starts on the next one).
    lines: usize,
}

fn header_err(line: usize, msg: impl Into<String>) -> Error {
    Error::malformed("ply", Location::Line(line), msg)
}

/// Parses the header up to and including `end_header`.
fn parse_header(bytes: &[u8]) -> Result<Header> {
    let mut pos = 0;
    let mut line_no = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if pos >= bytes.len() {
            return Err(header_err(line_no.max(1), "header ends without `end_header`"));
        }
        let end = memchr::memchr(b'\n', &bytes[pos..]).map_or(bytes.len(), |i| pos + i);
        let line = &bytes[pos..end];
        pos = (end + 1).min(bytes.len());
        line_no += 1;
        let mut t = Tokens::new(line);
        let key = t.next().unwrap_or(b"");
        match key {
            b"ply" if line_no == 1 => {}
            _ if line_no == 1 => return Err(header_err(1, "missing `ply` magic")),
            b"format" => encoding = Some(parse_format(&mut t, line_no)?),
            b"comment" | b"obj_info" | b"" => {}
            b"element" => elements.push(parse_element(&mut t, line_no)?),
            b"property" => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| header_err(line_no, "`property` before any `element`"))?;
                let p = parse_property(&mut t, &el.name, line_no)?;
                el.props.push(p);
            }
            b"end_header" => break,
            other => {
                return Err(header_err(
                    line_no,
                    format!("unknown header keyword `{}`", String::from_utf8_lossy(other)),
                ))
            }
        }
    }
    let encoding = encoding.ok_or_else(|| header_err(line_no, "no `format` line"))?;
    Ok(Header { encoding, elements, body: pos, lines: line_no })
}

fn parse_format(t: &mut Tokens, n: usize) -> Result<Encoding> {
    let enc = match t.next() {
        Some(b"ascii") => Encoding::Ascii,
        Some(b"binary_little_endian") => Encoding::BinaryLe,
        Some(b"binary_big_endian") => Encoding::BinaryBe,
        other => {
            let s = String::from_utf8_lossy(other.unwrap_or(b""));
            return Err(header_err(n, format!("unknown format `{s}`")));
        }
    };
    if t.next() != Some(b"1.0") {
        return Err(header_err(n, "only PLY version 1.0 is supported"));
    }
    Ok(enc)
}

fn parse_element(t: &mut Tokens, n: usize) -> Result<Element> {
    let name = t.next().ok_or_else(|| header_err(n, "`element` without a name"))?;
    let count = t
        .next()
        .and_then(lex::parse_u64)
        .ok_or_else(|| header_err(n, "`element` needs a non-negative integer count"))?;
    Ok(Element { name: String::from_utf8_lossy(name).into_owned(), count, props: Vec::new(), line: n })
}

fn parse_property(t: &mut Tokens, element: &str, n: usize) -> Result<Property> {
    let ty_tok = t.next().ok_or_else(|| header_err(n, "`property` without a type"))?;
    let bad_type =
        |s: &[u8]| header_err(n, format!("unknown property type `{}`", String::from_utf8_lossy(s)));
    let (list, ty) = if ty_tok == b"list" {
        let c = t.next().ok_or_else(|| header_err(n, "`property list` without a count type"))?;
        let i = t.next().ok_or_else(|| header_err(n, "`property list` without an item type"))?;
        let ct = Ty::parse(c).ok_or_else(|| bad_type(c))?;
        if matches!(ct, Ty::F32 | Ty::F64) {
            return Err(header_err(n, "list count type must be an integer type"));
        }
        (Some(ct), Ty::parse(i).ok_or_else(|| bad_type(i))?)
    } else {
        (None, Ty::parse(ty_tok).ok_or_else(|| bad_type(ty_tok))?)
    };
    let name = String::from_utf8_lossy(t.next().ok_or_else(|| header_err(n, "`property` without a name"))?)
        .into_owned();
    let role = role_of(element, &name, list.is_some());
    Ok(Property { name, list, ty, role })
}

fn role_of(element: &str, name: &str, is_list: bool) -> Role {
    match (element, name, is_list) {
        ("vertex", "x", false) => Role::Pos(0),
        ("vertex", "y", false) => Role::Pos(1),
        ("vertex", "z", false) => Role::Pos(2),
        ("vertex", "nx", false) => Role::Normal(0),
        ("vertex", "ny", false) => Role::Normal(1),
        ("vertex", "nz", false) => Role::Normal(2),
        ("vertex", "u" | "s" | "texture_u" | "texture_s", false) => Role::Uv(0),
        ("vertex", "v" | "t" | "texture_v" | "texture_t", false) => Role::Uv(1),
        ("face", "vertex_indices" | "vertex_index", true) => Role::FaceIndices,
        _ => Role::Skip,
    }
}

// ---------------------------------------------------------------------------------------------
// Body readers
// ---------------------------------------------------------------------------------------------

/// One value source for both encodings.
trait Body {
    fn real(&mut self, ty: Ty) -> Result<f64>;
    fn int(&mut self, ty: Ty) -> Result<i64>;
    /// Where the next value starts (line or byte offset).
    fn location(&mut self) -> Location;
    /// Bytes not yet read (caps allocations).
    fn remaining(&self) -> usize;
    /// Skips `n` values of type `ty`.
    fn skip(&mut self, ty: Ty, n: u64) -> Result<()>;
    /// The fewest bytes a value of type `ty` takes.
    fn min_bytes(&self, ty: Ty) -> u64;
}

struct Binary<'a> {
    bytes: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Binary<'_> {
    #[inline]
    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let Some(s) = self.bytes.get(self.pos..self.pos + N) else {
            return Err(Error::malformed(
                "ply",
                Location::Byte(self.pos),
                format!("data ends early: {N} more bytes needed, {} left", self.bytes.len() - self.pos),
            ));
        };
        self.pos += N;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        if self.big_endian {
            a.reverse();
        }
        Ok(a)
    }
}

impl Body for Binary<'_> {
    #[inline]
    fn real(&mut self, ty: Ty) -> Result<f64> {
        Ok(match ty {
            Ty::F32 => f32::from_le_bytes(self.take()?) as f64,
            Ty::F64 => f64::from_le_bytes(self.take()?),
            _ => self.int(ty)? as f64,
        })
    }

    #[inline]
    fn int(&mut self, ty: Ty) -> Result<i64> {
        Ok(match ty {
            Ty::I8 => i8::from_le_bytes(self.take()?) as i64,
            Ty::U8 => u8::from_le_bytes(self.take()?) as i64,
            Ty::I16 => i16::from_le_bytes(self.take()?) as i64,
            Ty::U16 => u16::from_le_bytes(self.take()?) as i64,
            Ty::I32 => i32::from_le_bytes(self.take()?) as i64,
            Ty::U32 => u32::from_le_bytes(self.take()?) as i64,
            Ty::F32 | Ty::F64 => {
                let at = self.pos;
                let v = self.real(ty)?;
                return integral(v).ok_or_else(|| {
                    Error::malformed("ply", Location::Byte(at), format!("{v} is not an integer"))
                });
            }
        })
    }

    fn location(&mut self) -> Location {
        Location::Byte(self.pos)
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn skip(&mut self, ty: Ty, n: u64) -> Result<()> {
        let len = n.saturating_mul(ty.size() as u64);
        if len > self.remaining() as u64 {
            return Err(Error::malformed(
                "ply",
                Location::Byte(self.pos),
                format!("data ends early: {len} bytes to skip, {} left", self.remaining()),
            ));
        }
        self.pos += len as usize;
        Ok(())
    }

    fn min_bytes(&self, ty: Ty) -> u64 {
        ty.size() as u64
    }
}

fn integral(v: f64) -> Option<i64> {
    (v.fract() == 0.0 && v.abs() < 9e15).then_some(v as i64)
}

/// The ascii body as a stream of whitespace-separated tokens across lines.
struct Ascii<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Line of the current position (1-based, counting the header).
    line: usize,
}

impl<'a> Ascii<'a> {
    /// Moves to the start of the next token (or the end), counting lines.
    fn skip_space(&mut self) {
        loop {
            while self.pos < self.bytes.len() && lex::is_space(self.bytes[self.pos]) {
                self.pos += 1;
            }
            match self.bytes.get(self.pos) {
                Some(b'\n') => {
                    self.pos += 1;
                    self.line += 1;
                }
                _ => break,
            }
        }
    }

    fn token(&mut self) -> Result<&'a [u8]> {
        self.skip_space();
        if self.pos >= self.bytes.len() {
            // Report the file's last line, not the empty one after its final newline.
            let last = self.line - (self.pos > 0 && self.bytes[self.pos - 1] == b'\n') as usize;
            return Err(Error::malformed("ply", Location::Line(last), "data ends early"));
        }
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        Ok(&self.bytes[start..self.pos])
    }

    fn bad(&self, tok: &[u8], what: &str) -> Error {
        Error::malformed(
            "ply",
            Location::Line(self.line),
            format!("`{}` is not {what}", String::from_utf8_lossy(tok)),
        )
    }
}

impl Body for Ascii<'_> {
    fn real(&mut self, _ty: Ty) -> Result<f64> {
        let t = self.token()?;
        lex::parse_f64(t).ok_or_else(|| self.bad(t, "a number"))
    }

    fn int(&mut self, _ty: Ty) -> Result<i64> {
        let t = self.token()?;
        match lex::parse_i64(t) {
            Some(v) => Ok(v),
            None => lex::parse_f64(t).and_then(integral).ok_or_else(|| self.bad(t, "an integer")),
        }
    }

    fn location(&mut self) -> Location {
        self.skip_space();
        Location::Line(self.line)
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn skip(&mut self, _ty: Ty, n: u64) -> Result<()> {
        for _ in 0..n {
            self.token()?;
        }
        Ok(())
    }

    fn min_bytes(&self, _ty: Ty) -> u64 {
        1
    }
}

// ---------------------------------------------------------------------------------------------
// Reading elements
// ---------------------------------------------------------------------------------------------

#[derive(Default)]
struct Out {
    positions: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    uvs: Vec<[f64; 2]>,
    faces: Faces,
    /// Vertex count declared in the header (face indices are checked against it).
    nv: u64,
    skipped: Vec<String>,
}

/// Decodes PLY bytes.
pub fn read(bytes: &[u8], opts: &ReadOptions) -> Result<Loaded> {
    let h = parse_header(bytes)?;
    let vertex = h.elements.iter().find(|e| e.name == "vertex");
    let nv = vertex.map_or(0, |e| e.count);
    let nf = h.elements.iter().find(|e| e.name == "face").map_or(0, |e| e.count);
    check_limits(nv, nf, opts)?;
    if let Some(v) = vertex {
        if !(v.has(Role::Pos(0)) && v.has(Role::Pos(1)) && v.has(Role::Pos(2))) {
            return Err(header_err(v.line, "`vertex` element lacks x, y or z"));
        }
    }
    if nv == 0 {
        return Err(header_err(h.lines, "no vertices (`element vertex` missing or 0)"));
    }
    let mut out = Out { nv, ..Default::default() };
    match h.encoding {
        Encoding::Ascii => {
            let mut body = Ascii { bytes, pos: h.body, line: h.lines + 1 };
            read_elements(&h, &mut body, &mut out)?;
        }
        enc => {
            check_binary_sizes(&h, bytes.len())?;
            let mut body = Binary { bytes, pos: h.body, big_endian: enc == Encoding::BinaryBe };
            read_elements(&h, &mut body, &mut out)?;
        }
    }
    finish(h, out)
}

fn check_limits(nv: u64, nf: u64, opts: &ReadOptions) -> Result<()> {
    if nv > opts.max_vertices as u64 {
        return Err(Error::TooLarge { what: "vertices".into(), limit: opts.max_vertices as u64, actual: nv });
    }
    if nf > opts.max_faces as u64 {
        return Err(Error::TooLarge { what: "faces".into(), limit: opts.max_faces as u64, actual: nf });
    }
    Ok(())
}

/// Refuses a binary body that cannot hold what the header declares, before reading anything.
fn check_binary_sizes(h: &Header, len: usize) -> Result<()> {
    let need: u64 =
        h.elements.iter().map(|e| e.count.saturating_mul(e.min_binary_size())).fold(0, u64::saturating_add);
    let have = (len - h.body) as u64;
    if need > have {
        return Err(Error::malformed(
            "ply",
            Location::Byte(h.body),
            format!("header declares at least {need} bytes of data, only {have} follow (truncated or lying header)"),
        ));
    }
    Ok(())
}

fn read_elements(h: &Header, body: &mut dyn Body, out: &mut Out) -> Result<()> {
    for el in &h.elements {
        match el.name.as_str() {
            "vertex" => read_vertices(el, body, out)?,
            "face" if el.has(Role::FaceIndices) => read_faces(el, body, out)?,
            _ => {
                skip_element(el, body)?;
                if el.count > 0 {
                    out.skipped.push(format!("{} `{}` elements", el.count, el.name));
                }
            }
        }
    }
    Ok(())
}

/// Capacity for `count` records of at least `min_size` bytes each, given what is left.
fn capacity(count: u64, min_size: usize, body: &dyn Body) -> usize {
    count.min((body.remaining() / min_size.max(1)) as u64) as usize
}

fn read_vertices(el: &Element, body: &mut dyn Body, out: &mut Out) -> Result<()> {
    let has_n = el.has(Role::Normal(0)) && el.has(Role::Normal(1)) && el.has(Role::Normal(2));
    let has_uv = el.has(Role::Uv(0)) && el.has(Role::Uv(1));
    let cap = capacity(el.count, el.min_binary_size() as usize, body);
    out.positions.reserve(cap);
    if has_n {
        out.normals.reserve(cap);
    }
    if has_uv {
        out.uvs.reserve(cap);
    }
    for i in 0..el.count {
        let at = body.location();
        let (mut p, mut n, mut uv) = ([0.0; 3], [0.0; 3], [0.0; 2]);
        for prop in &el.props {
            if let Some(ct) = prop.list {
                let k = list_len(body, ct)?;
                body.skip(prop.ty, k)?;
                continue;
            }
            match prop.role {
                Role::Pos(c) => p[c] = body.real(prop.ty)?,
                Role::Normal(c) => n[c] = body.real(prop.ty)?,
                Role::Uv(c) => uv[c] = body.real(prop.ty)?,
                _ => body.skip(prop.ty, 1)?,
            }
        }
        if !p.iter().all(|c| c.is_finite()) {
            return Err(Error::InvalidMesh {
                location: at,
                message: format!("vertex {i}: coordinate is NaN or infinite"),
            });
        }
        out.positions.push(p);
        if has_n {
            out.normals.push(n);
        }
        if has_uv {
            out.uvs.push(uv);
        }
    }
    Ok(())
}

fn list_len(body: &mut dyn Body, ct: Ty) -> Result<u64> {
    let at = body.location();
    let k = body.int(ct)?;
    u64::try_from(k).map_err(|_| Error::malformed("ply", at, format!("negative list length {k}")))
}

fn read_faces(el: &Element, body: &mut dyn Body, out: &mut Out) -> Result<()> {
    let min = el.min_binary_size() as usize + 3;
    let cap = capacity(el.count, min, body);
    out.faces = Faces::with_capacity(cap, cap.saturating_mul(3));
    let mut face = Vec::with_capacity(8);
    for fi in 0..el.count {
        for prop in &el.props {
            match (prop.list, prop.role) {
                (Some(ct), Role::FaceIndices) => {
                    let at = body.location();
                    let k = list_len(body, ct)?;
                    if k < 3 {
                        return Err(Error::malformed(
                            "ply",
                            at,
                            format!("face {fi} has {k} vertices, at least 3 are needed"),
                        ));
                    }
                    if k.saturating_mul(body.min_bytes(prop.ty)) > body.remaining() as u64 {
                        return Err(Error::malformed(
                            "ply",
                            at,
                            format!("face {fi} declares {k} vertices; data ends first"),
                        ));
                    }
                    face.clear();
                    for _ in 0..k {
                        let v = body.int(prop.ty)?;
                        if v < 0 || v as u64 >= out.nv {
                            return Err(Error::InvalidMesh {
                                location: at,
                                message: format!(
                                    "face {fi}: vertex index {v} out of range ({} vertices)",
                                    out.nv
                                ),
                            });
                        }
                        face.push(v as u32);
                    }
                    if out.faces.indices().len() + face.len() >= u32::MAX as usize {
                        return Err(Error::TooLarge {
                            what: "face corners".into(),
                            limit: u32::MAX as u64 - 1,
                            actual: (out.faces.indices().len() + face.len()) as u64,
                        });
                    }
                    out.faces.push(&face, 0);
                }
                (Some(ct), _) => {
                    let k = list_len(body, ct)?;
                    body.skip(prop.ty, k)?;
                }
                (None, _) => body.skip(prop.ty, 1)?,
            }
        }
    }
    Ok(())
}

fn skip_element(el: &Element, body: &mut dyn Body) -> Result<()> {
    if el.props.is_empty() {
        return Ok(()); // nothing to read, however large the count
    }
    for _ in 0..el.count {
        for prop in &el.props {
            let k = match prop.list {
                Some(ct) => list_len(body, ct)?,
                None => 1,
            };
            body.skip(prop.ty, k)?;
        }
    }
    Ok(())
}

fn finish(h: Header, out: Out) -> Result<Loaded> {
    let mut warnings = out.skipped.iter().map(|s| format!("skipped {s}")).collect::<Vec<_>>();
    let n = out.positions.len();
    for el in &h.elements {
        let unused: Vec<&str> = el
            .props
            .iter()
            .filter(|p| p.role == Role::Skip && (el.name == "vertex" || el.name == "face"))
            .map(|p| p.name.as_str())
            .collect();
        if !unused.is_empty() {
            warnings.push(format!("ignored `{}` properties: {}", el.name, unused.join(", ")));
        }
    }
    let mesh = Mesh {
        normals: (out.normals.len() == n).then_some(out.normals),
        uvs: (out.uvs.len() == n).then_some(out.uvs),
        positions: out.positions,
        faces: out.faces,
        ..Default::default()
    };
    Ok(Loaded { mesh, format: Format::Ply, warnings })
}

// ---------------------------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------------------------

/// Encodes `mesh` as binary little-endian PLY: double x y z (+ nx ny nz, s t when present, so
/// f64 round-trips exactly) and a `vertex_indices` list per face (uchar count, or uint when a
/// face has more than 255 corners). PLY has no standard for groups or polylines: they are not written.
pub fn write(mesh: &Mesh) -> Result<Vec<u8>> {
    mesh.check()?;
    let wide = (0..mesh.faces.len()).any(|i| mesh.faces.arity(i) > 255);
    let mut out = Vec::with_capacity(
        256 + mesh.positions.len() * 24 + mesh.faces.indices().len() * 4 + mesh.faces.len(),
    );
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by meshwork\nelement vertex {}\n\
         property double x\nproperty double y\nproperty double z\n",
        mesh.positions.len()
    );
    if mesh.normals.is_some() {
        header += "property double nx\nproperty double ny\nproperty double nz\n";
    }
    if mesh.uvs.is_some() {
        header += "property double s\nproperty double t\n";
    }
    header += &format!(
        "element face {}\nproperty list {} uint vertex_indices\nend_header\n",
        mesh.faces.len(),
        if wide { "uint" } else { "uchar" }
    );
    out.extend_from_slice(header.as_bytes());
    for (i, p) in mesh.positions.iter().enumerate() {
        put(&mut out, p);
        if let Some(n) = &mesh.normals {
            put(&mut out, &n[i]);
        }
        if let Some(uv) = &mesh.uvs {
            put(&mut out, &uv[i]);
        }
    }
    for f in mesh.faces.iter() {
        if wide {
            out.extend_from_slice(&(f.len() as u32).to_le_bytes());
        } else {
            out.push(f.len() as u8);
        }
        for &i in f {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    Ok(out)
}

fn put(out: &mut Vec<u8>, v: &[f64]) {
    for x in v {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_b(b: &[u8]) -> Result<Loaded> {
        read(b, &ReadOptions::default())
    }

    /// A tetrahedron's 4 vertices and 4 faces, hand-written.
    const TETRA: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    const TETRA_F: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];

    #[test]
    fn ascii_with_unknown_elements_and_properties() {
        let src = "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\nproperty float x\nproperty float y\n\
                   property float z\nproperty uchar red\nproperty list uchar int junk\n\
                   element material 2\nproperty list uint float vals\nelement face 4\n\
                   property uchar flags\nproperty list uchar int vertex_index\nend_header\n\
                   0 0 0 255 0\n1 0 0 1 2 7 7\n0 1 0 3 0\n0 0 1 4 1 9\n\
                   2 1.5 2.5\n0\n\
                   9 3 0 2 1\n9 3 0 1 3\n9 3 1 2 3\n9 3 0 3 2\n";
        let l = read_b(src.as_bytes()).unwrap();
        assert_eq!(l.mesh.positions, TETRA.to_vec());
        assert_eq!(l.mesh.faces, Faces::from_triangles(&TETRA_F));
        assert!(l.warnings.iter().any(|w| w.contains("2 `material`")), "{:?}", l.warnings);
    }

    fn binary(big: bool, idx_ty: &str, cnt_ty: &str) -> Vec<u8> {
        let enc = if big { "binary_big_endian" } else { "binary_little_endian" };
        let mut b = format!(
            "ply\nformat {enc} 1.0\nelement vertex 4\nproperty short x\nproperty double y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n\
             element face 4\nproperty list {cnt_ty} {idx_ty} vertex_indices\nproperty int extra\nend_header\n"
        )
        .into_bytes();
        fn put<const N: usize>(b: &mut Vec<u8>, mut a: [u8; N], big: bool) {
            if big {
                a.reverse();
            }
            b.extend_from_slice(&a);
        }
        for p in TETRA {
            put(&mut b, (p[0] as i16).to_le_bytes(), big);
            put(&mut b, p[1].to_le_bytes(), big);
            put(&mut b, (p[2] as f32).to_le_bytes(), big);
            for c in [0.0f32, 0.0, 1.0] {
                put(&mut b, c.to_le_bytes(), big);
            }
        }
        for f in TETRA_F {
            match cnt_ty {
                "uchar" => b.push(3),
                _ => put(&mut b, 3u32.to_le_bytes(), big),
            }
            for i in f {
                match idx_ty {
                    "ushort" => put(&mut b, (i as u16).to_le_bytes(), big),
                    _ => put(&mut b, (i as i32).to_le_bytes(), big),
                }
            }
            put(&mut b, 77i32.to_le_bytes(), big);
        }
        b
    }

    #[test]
    fn binary_both_endians_any_types() {
        for big in [false, true] {
            for (it, ct) in [("int", "uchar"), ("ushort", "uint")] {
                let l = read_b(&binary(big, it, ct)).unwrap();
                assert_eq!(l.mesh.positions, TETRA.to_vec(), "big={big} {it} {ct}");
                assert_eq!(l.mesh.faces, Faces::from_triangles(&TETRA_F));
                assert_eq!(l.mesh.normals, Some(vec![[0.0, 0.0, 1.0]; 4]));
            }
        }
    }

    #[test]
    fn truncated_and_lying_binary() {
        let b = binary(false, "int", "uchar");
        let body = b.len() - 172; // 4 × 26 vertex bytes + 4 × 17 face bytes
        let e = read_b(&b[..b.len() - 1]).unwrap_err();
        // The last face's `extra` int starts at body + 168 and needs 4 bytes, 3 are left.
        assert!(matches!(e, Error::Malformed { location: Location::Byte(o), .. } if o == body + 168), "{e}");
        // Declaring 1000 vertices: at least 1000 × 26 + 4 × 5 bytes needed, refused up front.
        let lying = String::from_utf8_lossy(&b).replacen("element vertex 4", "element vertex 1000", 1);
        let e = read_b(lying.as_bytes()).unwrap_err();
        assert!(e.to_string().contains("at least 26020 bytes"), "{e}");
    }
}
