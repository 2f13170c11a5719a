//! PLY reading (ascii, binary little- and big-endian) and writing (binary little-endian).
//!
//! The header is parsed into [`Element`]s; the body is then read element by element through one
//! [`Body`] interface over the ascii token stream or the binary cursor, so both encodings share the
//! logic that maps properties to roles (x/y/z, normals, texture coordinates, face indices, the
//! `vertex1`/`vertex2` of loose edges, read as two-point curves) and skips everything else,
//! including unknown elements and list properties.
//!
//! Declared counts are never trusted for allocation: capacity is capped by what the remaining
//! bytes can hold, and a binary body shorter than the header's counts demand is refused before
//! reading (a "lying header"), with the byte offset.

mod body;
mod header;
mod writer;

use body::{Ascii, Binary, Body};
use header::{header_err, parse_header, Element, Encoding, Header, Role, Ty};
pub use writer::write;

use super::{Format, Loaded, ReadOptions};
use crate::error::{Error, Location, Result};
use crate::mesh::{Faces, Mesh};

// ---------------------------------------------------------------------------------------------
// Reading elements
// ---------------------------------------------------------------------------------------------

#[derive(Default)]
struct Out {
    positions: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    uvs: Vec<[f64; 2]>,
    faces: Faces,
    /// Loose edges (`element edge`), as two-point polylines.
    curves: Vec<Vec<u32>>,
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
            "edge" if el.has(Role::EdgeEnd(0)) && el.has(Role::EdgeEnd(1)) => read_edges(el, body, out)?,
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
        // Normals and texture coordinates too, as the OBJ, OFF and glTF readers do: a NaN normal
        // was read and then written to an OBJ that no reader accepts.
        let bad = if !p.iter().all(|c| c.is_finite()) {
            Some("coordinate")
        } else if has_n && !n.iter().all(|c| c.is_finite()) {
            Some("normal")
        } else if has_uv && !uv.iter().all(|c| c.is_finite()) {
            Some("texture coordinate")
        } else {
            None
        };
        if let Some(what) = bad {
            return Err(Error::InvalidMesh {
                location: at,
                message: format!("vertex {i}: {what} is NaN or infinite"),
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

/// Loose edges: `vertex1`, `vertex2` (any integer type; other properties skipped), each a
/// two-point curve. An index out of range is an error naming the edge.
fn read_edges(el: &Element, body: &mut dyn Body, out: &mut Out) -> Result<()> {
    let cap = capacity(el.count, el.min_binary_size() as usize, body);
    out.curves.reserve(cap);
    for ei in 0..el.count {
        let at = body.location();
        let mut ends = [0u32; 2];
        for prop in &el.props {
            if let Some(ct) = prop.list {
                let k = list_len(body, ct)?;
                body.skip(prop.ty, k)?;
                continue;
            }
            match prop.role {
                Role::EdgeEnd(k) => {
                    let v = body.int(prop.ty)?;
                    if v < 0 || v as u64 >= out.nv {
                        return Err(Error::InvalidMesh {
                            location: at,
                            message: format!(
                                "edge {ei}: vertex index {v} out of range ({} vertices)",
                                out.nv
                            ),
                        });
                    }
                    ends[k] = v as u32;
                }
                _ => body.skip(prop.ty, 1)?,
            }
        }
        out.curves.push(ends.to_vec());
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
            .filter(|p| p.role == Role::Skip && matches!(el.name.as_str(), "vertex" | "face" | "edge"))
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
        curves: out.curves,
        ..Default::default()
    };
    Ok(Loaded { mesh, format: Format::Ply, warnings })
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

    /// Loose edges (Blender's `element edge`) become two-point curves, with the edge's other
    /// properties skipped; an index past the vertices names the edge.
    #[test]
    fn edges_are_read_as_two_point_curves() {
        let src = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                   property float z\nelement edge 2\nproperty int vertex1\nproperty uchar red\n\
                   property int vertex2\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 9 1\n1 9 2\n";
        let l = read_b(src.as_bytes()).unwrap();
        assert_eq!(l.mesh.curves, vec![vec![0, 1], vec![1, 2]]);
        assert_eq!(l.mesh.faces.len(), 0);
        assert!(l.warnings.iter().any(|w| w.contains("red")), "{:?}", l.warnings);
        let bad = src.replace("1 9 2\n", "1 9 3\n");
        let e = read_b(bad.as_bytes()).unwrap_err().to_string();
        assert!(e.contains("edge 1") && e.contains("line 16"), "{e}");
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
