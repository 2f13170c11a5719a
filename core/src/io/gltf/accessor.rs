//! Buffers, buffer views and accessors: turning `accessors[i]` into numbers.
//!
//! Every size is checked with overflow-checked arithmetic against the bytes really present
//! before anything is allocated, so a lying `count` costs nothing. Handles `byteStride`,
//! normalized integers (which is all KHR_mesh_quantization needs), and sparse accessors.

use std::borrow::Cow;

use super::base64;
use super::json::{array, bad, boolean, index, join, object, required_uint, string, uint, Obj};
use crate::error::{Error, Location, Result};

/// A component type of an accessor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Component {
    I8,
    U8,
    I16,
    U16,
    U32,
    F32,
}

impl Component {
    fn from_code(code: u64) -> Option<Component> {
        Some(match code {
            5120 => Component::I8,
            5121 => Component::U8,
            5122 => Component::I16,
            5123 => Component::U16,
            5125 => Component::U32,
            5126 => Component::F32,
            _ => return None,
        })
    }

    pub fn size(self) -> usize {
        match self {
            Component::I8 | Component::U8 => 1,
            Component::I16 | Component::U16 => 2,
            Component::U32 | Component::F32 => 4,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Component::I8 => "BYTE",
            Component::U8 => "UNSIGNED_BYTE",
            Component::I16 => "SHORT",
            Component::U16 => "UNSIGNED_SHORT",
            Component::U32 => "UNSIGNED_INT",
            Component::F32 => "FLOAT",
        }
    }

    pub fn is_index_type(self) -> bool {
        matches!(self, Component::U8 | Component::U16 | Component::U32)
    }
}

/// An accessor's declaration, checked against its buffer view.
#[derive(Clone, Debug)]
pub(super) struct Header {
    pub index: usize,
    pub component: Component,
    pub normalized: bool,
    /// Number of elements.
    pub count: usize,
    /// Components per element (1 for SCALAR … 4 for VEC4).
    pub width: usize,
    pub type_name: String,
    layout: Option<Layout>,
}

/// Where an accessor's elements lie in its buffer view (already bounds-checked).
#[derive(Clone, Copy, Debug)]
struct Layout {
    view: usize,
    offset: usize,
    stride: usize,
}

impl Header {
    pub fn path(&self) -> String {
        format!("accessors[{}]", self.index)
    }
}

/// The binary side of a glTF document: decoded buffers plus the JSON arrays that index them.
pub(super) struct Store<'a> {
    buffers: Vec<Cow<'a, [u8]>>,
    views: &'a [serde_json::Value],
    accessors: &'a [serde_json::Value],
}

/// Decodes every buffer: the GLB BIN chunk for a `uri`-less buffer 0, base64 `data:` URIs, and
/// nothing else: a file path or URL is refused, never opened.
fn load_buffers<'a>(root: &'a Obj, bin: Option<&'a [u8]>) -> Result<Vec<Cow<'a, [u8]>>> {
    let mut out = Vec::new();
    for (i, b) in array(root, "buffers", "")?.iter().enumerate() {
        let path = format!("buffers[{i}]");
        let buffer = object(b, &path)?;
        let declared = required_uint(buffer, "byteLength", &path)?;
        let data: Cow<'a, [u8]> = match string(buffer, "uri", &path)? {
            None => match (i, bin) {
                (0, Some(bin)) => Cow::Borrowed(bin),
                _ => return Err(bad(&path, "has no uri and is not the GLB BIN chunk")),
            },
            Some(uri) if uri.starts_with("data:") => Cow::Owned(decode_data_uri(uri, &path)?),
            Some(uri) => {
                return Err(Error::ExternalReference {
                    location: Location::Gltf(join(&path, "uri")),
                    message: format!(
                        "buffer points outside the file ({}); only GLB binary chunks and data: URIs are read",
                        shorten(uri)
                    ),
                })
            }
        };
        if (data.len() as u64) < declared {
            return Err(bad(
                join(&path, "byteLength"),
                format!("declares {declared} bytes but the data holds {}", data.len()),
            ));
        }
        out.push(match data {
            Cow::Borrowed(d) => Cow::Borrowed(&d[..declared as usize]),
            Cow::Owned(mut d) => {
                d.truncate(declared as usize);
                Cow::Owned(d)
            }
        });
    }
    Ok(out)
}

fn shorten(s: &str) -> String {
    if s.chars().count() > 80 {
        format!("{}…", s.chars().take(80).collect::<String>())
    } else {
        s.to_owned()
    }
}

fn decode_data_uri(uri: &str, path: &str) -> Result<Vec<u8>> {
    let p = join(path, "uri");
    let comma = uri.find(',').ok_or_else(|| bad(&p, "data: URI without a comma"))?;
    let header = &uri[5..comma];
    if !header.ends_with(";base64") {
        return Err(bad(&p, "only base64 data: URIs are supported"));
    }
    base64::decode(&uri.as_bytes()[comma + 1..])
        .map_err(|at| bad(&p, format!("invalid base64 at character {at} of the data")))
}

impl<'a> Store<'a> {
    pub fn new(root: &'a Obj, bin: Option<&'a [u8]>) -> Result<Store<'a>> {
        Ok(Store {
            buffers: load_buffers(root, bin)?,
            views: array(root, "bufferViews", "")?,
            accessors: array(root, "accessors", "")?,
        })
    }

    pub fn accessor_count(&self) -> usize {
        self.accessors.len()
    }

    /// The bytes of `bufferViews[i]` and its byteStride.
    fn view(&self, i: usize) -> Result<(&[u8], Option<usize>)> {
        let path = format!("bufferViews[{i}]");
        let view = object(&self.views[i], &path)?;
        let buffer = index(view, "buffer", &path, self.buffers.len(), "buffer")?
            .ok_or_else(|| bad(join(&path, "buffer"), "is required"))?;
        let offset = uint(view, "byteOffset", &path)?.unwrap_or(0);
        let length = required_uint(view, "byteLength", &path)?;
        let data = &self.buffers[buffer];
        let end = offset.checked_add(length).filter(|&e| e <= data.len() as u64).ok_or_else(|| {
            bad(
                &path,
                format!(
                    "bytes {offset}..{offset}+{length} lie outside buffers[{buffer}] ({} bytes)",
                    data.len()
                ),
            )
        })?;
        let stride = match uint(view, "byteStride", &path)? {
            None => None,
            Some(s) if (4..=252).contains(&s) => Some(s as usize),
            Some(s) => return Err(bad(join(&path, "byteStride"), format!("{s} is outside 4..=252"))),
        };
        Ok((&data[offset as usize..end as usize], stride))
    }

    /// Reads and checks the declaration of `accessors[i]` (the caller has range-checked `i`).
    pub fn header(&self, i: usize) -> Result<Header> {
        let path = format!("accessors[{i}]");
        let acc = object(&self.accessors[i], &path)?;
        let code = required_uint(acc, "componentType", &path)?;
        let component = Component::from_code(code).ok_or_else(|| {
            bad(join(&path, "componentType"), format!("{code} is not a glTF component type"))
        })?;
        let count = required_uint(acc, "count", &path)?;
        if count == 0 {
            return Err(bad(join(&path, "count"), "must be at least 1"));
        }
        let type_name = string(acc, "type", &path)?.ok_or_else(|| bad(join(&path, "type"), "is required"))?;
        let width = match type_name {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT2" | "MAT3" | "MAT4" => {
                return Err(bad(
                    join(&path, "type"),
                    format!("{type_name} accessors are not used by mesh geometry"),
                ))
            }
            other => return Err(bad(join(&path, "type"), format!("unknown type {other:?}"))),
        };
        let normalized = boolean(acc, "normalized", &path)?;
        if normalized && matches!(component, Component::F32 | Component::U32) {
            return Err(bad(join(&path, "normalized"), format!("{} cannot be normalized", component.name())));
        }
        let count = usize::try_from(count).map_err(|_| bad(join(&path, "count"), "too large"))?;
        let layout = self.layout(acc, &path, count, component.size() * width)?;
        Ok(Header { index: i, component, normalized, count, width, type_name: type_name.to_owned(), layout })
    }

    /// Where the elements are, after checking (overflow-checked) that all `count` elements of
    /// `elem` bytes lie inside the buffer view. `None`: no buffer view (all zeros).
    fn layout(&self, acc: &Obj, path: &str, count: usize, elem: usize) -> Result<Option<Layout>> {
        let Some(v) = index(acc, "bufferView", path, self.views.len(), "buffer view")? else {
            return Ok(None);
        };
        let (bytes, stride) = self.view(v)?;
        let stride = stride.unwrap_or(elem);
        if stride < elem {
            return Err(bad(
                format!("bufferViews[{v}].byteStride"),
                format!("{stride} is smaller than the {elem}-byte elements of {path}"),
            ));
        }
        let offset = uint(acc, "byteOffset", path)?.unwrap_or(0);
        let need = (count as u64 - 1)
            .checked_mul(stride as u64)
            .and_then(|x| x.checked_add(elem as u64))
            .and_then(|x| x.checked_add(offset));
        match need {
            Some(need) if need <= bytes.len() as u64 => Ok(Some(Layout { view: v, offset: offset as usize, stride })),
            _ => Err(bad(
                path,
                format!(
                    "{count} elements of {elem} bytes (stride {stride}) from byte {offset} do not fit in bufferViews[{v}] ({} bytes)",
                    bytes.len()
                ),
            )),
        }
    }

    /// Decodes the elements of `h` as f64 (normalized integers mapped to [0, 1] or [-1, 1]),
    /// `count × width` values, sparse substitutions applied. `max_count` bounds accessors that
    /// have no buffer view (all zeros plus sparse values), whose count no data backs.
    pub fn floats(&self, h: &Header, max_count: usize) -> Result<Vec<f64>> {
        let n = h.normalized;
        match h.component {
            Component::F32 => {
                self.decode(h, max_count, |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64)
            }
            Component::U32 => {
                self.decode(h, max_count, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64)
            }
            Component::I8 => self.decode(h, max_count, move |b| {
                let v = b[0] as i8 as f64;
                if n {
                    (v / 127.0).max(-1.0)
                } else {
                    v
                }
            }),
            Component::U8 => self.decode(h, max_count, move |b| {
                let v = b[0] as f64;
                if n {
                    v / 255.0
                } else {
                    v
                }
            }),
            Component::I16 => self.decode(h, max_count, move |b| {
                let v = i16::from_le_bytes([b[0], b[1]]) as f64;
                if n {
                    (v / 32767.0).max(-1.0)
                } else {
                    v
                }
            }),
            Component::U16 => self.decode(h, max_count, move |b| {
                let v = u16::from_le_bytes([b[0], b[1]]) as f64;
                if n {
                    v / 65535.0
                } else {
                    v
                }
            }),
        }
    }

    /// Decodes an index accessor (the caller checked the component type is an index type).
    pub fn indices(&self, h: &Header, max_count: usize) -> Result<Vec<u32>> {
        match h.component {
            Component::U8 => self.decode(h, max_count, |b| u32::from(b[0])),
            Component::U16 => self.decode(h, max_count, |b| u32::from(u16::from_le_bytes([b[0], b[1]]))),
            Component::U32 => self.decode(h, max_count, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            other => Err(bad(h.path(), format!("{} is not an index component type", other.name()))),
        }
    }

    fn decode<T: Copy + Default>(
        &self,
        h: &Header,
        max_count: usize,
        read: impl Fn(&[u8]) -> T,
    ) -> Result<Vec<T>> {
        let path = h.path();
        let acc = object(&self.accessors[h.index], &path)?;
        let total = h.count.checked_mul(h.width).ok_or_else(|| bad(join(&path, "count"), "too large"))?;
        let mut out: Vec<T>;
        match h.layout {
            Some(Layout { view, offset, stride }) => {
                // header() checked that every element lies inside the view: the allocation is
                // bounded by the data actually present.
                let (bytes, _) = self.view(view)?;
                let elem = h.component.size() * h.width;
                out = Vec::with_capacity(total);
                let cs = h.component.size();
                if stride == elem {
                    // Tightly packed (the common case): one pass over the components.
                    out.extend(bytes[offset..offset + h.count * elem].chunks_exact(cs).map(&read));
                } else {
                    for e in 0..h.count {
                        let start = offset + e * stride;
                        out.extend(bytes[start..start + elem].chunks_exact(cs).map(&read));
                    }
                }
            }
            None => {
                if h.count > max_count {
                    return Err(Error::TooLarge {
                        what: format!("{path}.count (an accessor without a buffer view)"),
                        limit: max_count as u64,
                        actual: h.count as u64,
                    });
                }
                out = vec![T::default(); total];
            }
        }
        if let Some(sparse) = acc.get("sparse") {
            self.apply_sparse(h, sparse, &mut out, &read)?;
        }
        Ok(out)
    }

    /// Replaces the elements listed by `accessors[i].sparse`.
    fn apply_sparse<T: Copy>(
        &self,
        h: &Header,
        sparse: &serde_json::Value,
        out: &mut [T],
        read: &impl Fn(&[u8]) -> T,
    ) -> Result<()> {
        let path = format!("{}.sparse", h.path());
        let sparse = object(sparse, &path)?;
        let count = required_uint(sparse, "count", &path)?;
        if count == 0 || count > h.count as u64 {
            return Err(bad(join(&path, "count"), format!("{count} is not in 1..={}", h.count)));
        }
        let count = count as usize;

        let ipath = join(&path, "indices");
        let idx = object(sparse.get("indices").unwrap_or(&serde_json::Value::Null), &ipath)?;
        let icode = required_uint(idx, "componentType", &ipath)?;
        let icomp = Component::from_code(icode).filter(|c| c.is_index_type()).ok_or_else(|| {
            bad(join(&ipath, "componentType"), format!("{icode} is not an index component type"))
        })?;
        let ibytes = self.sparse_slice(idx, &ipath, count, icomp.size())?;

        let vpath = join(&path, "values");
        let vals = object(sparse.get("values").unwrap_or(&serde_json::Value::Null), &vpath)?;
        let elem = h.component.size() * h.width;
        let vbytes = self.sparse_slice(vals, &vpath, count, elem)?;

        let cs = h.component.size();
        for k in 0..count {
            let ib = &ibytes[k * icomp.size()..(k + 1) * icomp.size()];
            let target = match icomp {
                Component::U8 => ib[0] as usize,
                Component::U16 => u16::from_le_bytes([ib[0], ib[1]]) as usize,
                _ => u32::from_le_bytes([ib[0], ib[1], ib[2], ib[3]]) as usize,
            };
            if target >= h.count {
                return Err(super::json::invalid(
                    &ipath,
                    format!(
                        "sparse index {target} (entry {k}) is outside the accessor's {} elements",
                        h.count
                    ),
                ));
            }
            let el = &vbytes[k * elem..(k + 1) * elem];
            for c in 0..h.width {
                out[target * h.width + c] = read(&el[c * cs..(c + 1) * cs]);
            }
        }
        Ok(())
    }

    /// `count × size` tightly packed bytes at `{bufferView, byteOffset}` of a sparse part.
    fn sparse_slice(&self, obj: &Obj, path: &str, count: usize, size: usize) -> Result<&[u8]> {
        let v = index(obj, "bufferView", path, self.views.len(), "buffer view")?
            .ok_or_else(|| bad(join(path, "bufferView"), "is required"))?;
        let (bytes, _) = self.view(v)?;
        let offset = uint(obj, "byteOffset", path)?.unwrap_or(0);
        let end = (count as u64).checked_mul(size as u64).and_then(|n| n.checked_add(offset));
        match end {
            Some(end) if end <= bytes.len() as u64 => Ok(&bytes[offset as usize..end as usize]),
            _ => Err(bad(
                path,
                format!("{count} entries of {size} bytes from byte {offset} do not fit in bufferViews[{v}] ({} bytes)", bytes.len()),
            )),
        }
    }
}
