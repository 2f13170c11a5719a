//! OBJ writing: `v` (+ `vt`/`vn`), `g` on group changes, `f` as given, `l` for curves; numbers as
//! the shortest decimal that reads back to the same f64, formatted in parallel blocks.

use rayon::prelude::*;

use super::super::lex;
use crate::error::Result;
use crate::mesh::Mesh;

/// Elements per block when formatting in parallel.
const WRITE_BLOCK: usize = 1 << 15;

/// Encodes `mesh`: `v` (+ `vt`/`vn` when the mesh has them, with the same index as the vertex),
/// `g` whenever the group changes, `f` with the arity as given, `l` for curves. Numbers are the
/// shortest decimal that reads back to the same f64.
pub fn write(mesh: &Mesh) -> Result<Vec<u8>> {
    mesh.check()?;
    let mut out = Vec::with_capacity(mesh.positions.len() * 40 + mesh.faces.indices().len() * 10 + 128);
    out.extend_from_slice(
        format!("# meshwork: {} vertices, {} faces\n", mesh.positions.len(), mesh.faces.len()).as_bytes(),
    );
    write_blocks(&mut out, mesh.positions.len(), |o, r| write_vec(o, b"v ", &mesh.positions[r]));
    if let Some(uv) = &mesh.uvs {
        write_blocks(&mut out, uv.len(), |o, r| write_vec(o, b"vt ", &uv[r]));
    }
    if let Some(nr) = &mesh.normals {
        write_blocks(&mut out, nr.len(), |o, r| write_vec(o, b"vn ", &nr[r]));
    }
    let style = match (mesh.uvs.is_some(), mesh.normals.is_some()) {
        (false, false) => CornerStyle::V,
        (true, false) => CornerStyle::VVt,
        (false, true) => CornerStyle::VVn,
        (true, true) => CornerStyle::VVtVn,
    };
    write_blocks(&mut out, mesh.faces.len(), |o, r| write_faces(o, mesh, r, style));
    for c in &mesh.curves {
        out.extend_from_slice(b"l");
        for &i in c {
            out.push(b' ');
            lex::push_u64(&mut out, i as u64 + 1);
        }
        out.push(b'\n');
    }
    Ok(out)
}

/// Formats `0..n` in blocks (in parallel when large) and appends them in order.
fn write_blocks(out: &mut Vec<u8>, n: usize, f: impl Fn(&mut Vec<u8>, std::ops::Range<usize>) + Sync) {
    if n <= WRITE_BLOCK {
        f(out, 0..n);
        return;
    }
    let blocks: Vec<Vec<u8>> = (0..n.div_ceil(WRITE_BLOCK))
        .into_par_iter()
        .map(|b| {
            let r = b * WRITE_BLOCK..((b + 1) * WRITE_BLOCK).min(n);
            let mut o = Vec::with_capacity(r.len() * 40);
            f(&mut o, r);
            o
        })
        .collect();
    for b in blocks {
        out.extend_from_slice(&b);
    }
}

fn write_vec<const N: usize>(out: &mut Vec<u8>, key: &[u8], vs: &[[f64; N]]) {
    let mut buf = ryu::Buffer::new();
    for v in vs {
        out.extend_from_slice(key);
        for (k, &x) in v.iter().enumerate() {
            if k > 0 {
                out.push(b' ');
            }
            lex::push_f64(out, &mut buf, x);
        }
        out.push(b'\n');
    }
}

#[derive(Clone, Copy)]
enum CornerStyle {
    V,
    VVt,
    VVn,
    VVtVn,
}

fn write_faces(out: &mut Vec<u8>, mesh: &Mesh, range: std::ops::Range<usize>, style: CornerStyle) {
    let faces = &mesh.faces;
    let mut prev = if range.start == 0 { None } else { Some(faces.group(range.start - 1)) };
    for fi in range {
        let g = faces.group(fi);
        if prev != Some(g) && !(prev.is_none() && mesh.groups.is_empty() && g == 0) {
            write_group(out, mesh, g);
        }
        prev = Some(g);
        out.push(b'f');
        for &i in faces.get(fi) {
            out.push(b' ');
            let i = i as u64 + 1;
            lex::push_u64(out, i);
            match style {
                CornerStyle::V => {}
                CornerStyle::VVt => {
                    out.push(b'/');
                    lex::push_u64(out, i);
                }
                CornerStyle::VVn => {
                    out.extend_from_slice(b"//");
                    lex::push_u64(out, i);
                }
                CornerStyle::VVtVn => {
                    out.push(b'/');
                    lex::push_u64(out, i);
                    out.push(b'/');
                    lex::push_u64(out, i);
                }
            }
        }
        out.push(b'\n');
    }
}

/// `g name`. Names cannot contain line breaks in OBJ; a mesh without names gets `group<id>`.
fn write_group(out: &mut Vec<u8>, mesh: &Mesh, g: u32) {
    out.push(b'g');
    let name = if mesh.groups.is_empty() {
        format!("group{g}")
    } else {
        mesh.group_name(g).replace(['\n', '\r'], "_")
    };
    if !name.is_empty() {
        out.push(b' ');
        out.extend_from_slice(name.trim().as_bytes());
    }
    out.push(b'\n');
}
