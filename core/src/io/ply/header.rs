//! The PLY header: format line, elements and their properties, each property mapped to a role
//! (x/y/z, normals, texture coordinates, face indices, or skipped).

use super::super::lex::{self, Tokens};
use crate::error::{Error, Location, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Encoding {
    Ascii,
    BinaryLe,
    BinaryBe,
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Ty {
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
    pub(super) fn parse(s: &[u8]) -> Option<Ty> {
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

    pub(super) fn size(self) -> usize {
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
pub(super) enum Role {
    Pos(usize),
    Normal(usize),
    Uv(usize),
    FaceIndices,
    /// `vertex1` / `vertex2` of an `edge` element (loose edges, as Blender writes them).
    EdgeEnd(usize),
    Skip,
}

#[derive(Debug)]
pub(super) struct Property {
    pub(super) name: String,
    /// `Some(count type)` for list properties.
    pub(super) list: Option<Ty>,
    pub(super) ty: Ty,
    pub(super) role: Role,
}

#[derive(Debug)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) props: Vec<Property>,
    /// Header line declaring the element (for error messages).
    pub(super) line: usize,
}

impl Element {
    /// The fewest bytes one binary record can take (lists may be empty).
    pub(super) fn min_binary_size(&self) -> u64 {
        self.props.iter().map(|p| p.list.unwrap_or(p.ty).size() as u64).sum()
    }

    pub(super) fn has(&self, role: Role) -> bool {
        self.props.iter().any(|p| p.role == role)
    }
}

pub(super) struct Header {
    pub(super) encoding: Encoding,
    pub(super) elements: Vec<Element>,
    /// Byte offset of the body.
    pub(super) body: usize,
    /// Lines in the header (the ascii body starts on the next one).
    pub(super) lines: usize,
}

pub(super) fn header_err(line: usize, msg: impl Into<String>) -> Error {
    Error::malformed("ply", Location::Line(line), msg)
}

/// Parses the header up to and including `end_header`.
pub(super) fn parse_header(bytes: &[u8]) -> Result<Header> {
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
        ("edge", "vertex1", false) => Role::EdgeEnd(0),
        ("edge", "vertex2", false) => Role::EdgeEnd(1),
        _ => Role::Skip,
    }
}
