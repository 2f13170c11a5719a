//! PLY writing (binary little-endian).

use crate::error::Result;
use crate::mesh::Mesh;

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
