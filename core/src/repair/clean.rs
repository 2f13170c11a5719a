//! Dropping what carries no surface: degenerate faces, duplicate faces, unreferenced vertices.

use serde::Serialize;

use crate::error::Result;
use crate::job::Progress;
use crate::mesh::{Faces, Mesh};
use crate::topology::NONE;
use crate::validate::{distinct_count, polygon_area, ZERO_AREA_REL};

#[derive(Debug, Clone, Serialize, Default)]
pub struct CleanReport {
    /// Corners removed from faces that repeated a vertex consecutively (`[a, b, b, c]` → `[a, b, c]`).
    pub collapsed_corners: usize,
    /// Faces dropped for having < 3 distinct vertices or a vertex repeated non-consecutively.
    pub dropped_repeated_index: usize,
    /// Faces dropped for area ≤ 1e-12 · diagonal² (needles and caps with distinct vertices).
    pub dropped_zero_area: usize,
    /// Faces dropped for having the same vertex set as an earlier face.
    pub dropped_duplicates: usize,
}

/// Removes degenerate and/or duplicate faces, keeping the order and groups of the rest.
pub fn clean(
    mesh: &mut Mesh,
    degenerate: bool,
    duplicates: bool,
    diag: f64,
    progress: &Progress,
) -> Result<CleanReport> {
    let mut r = CleanReport::default();
    let zero = ZERO_AREA_REL * diag * diag;
    let mut out = Faces::with_capacity(mesh.faces.len(), mesh.faces.indices().len());
    let mut buf: Vec<u32> = Vec::with_capacity(8);
    for i in 0..mesh.faces.len() {
        let f = mesh.faces.get(i);
        buf.clear();
        if degenerate {
            for (k, &v) in f.iter().enumerate() {
                if v != f[(k + 1) % f.len()] || f.len() == 1 {
                    buf.push(v);
                }
            }
            r.collapsed_corners += f.len() - buf.len();
            if buf.len() < 3 || distinct_count(&buf) != buf.len() {
                r.dropped_repeated_index += 1;
                continue;
            }
            if !(polygon_area(&mesh.positions, &buf) > zero) {
                r.dropped_zero_area += 1;
                continue;
            }
        } else {
            buf.extend_from_slice(f);
        }
        out.push(&buf, mesh.faces.group(i));
    }
    if duplicates {
        let dups = crate::validate::duplicate_faces_polled(&out, progress)?;
        r.dropped_duplicates = dups.len();
        if !dups.is_empty() {
            let mut drop = vec![false; out.len()];
            for d in dups {
                drop[d] = true;
            }
            out.retain(|i| !drop[i]);
        }
    }
    mesh.faces = out;
    Ok(r)
}

#[derive(Debug, Clone, Serialize, Default)]
pub struct CompactReport {
    /// Vertices used by no face and no curve, removed.
    pub removed_vertices: usize,
    /// `map[old] = new`, [`NONE`] for removed vertices (not serialised; the job reports it on request).
    #[serde(skip)]
    pub map: Vec<u32>,
}

/// Removes vertices no face or curve uses and renumbers the rest in their original order.
pub fn compact(mesh: &mut Mesh) -> CompactReport {
    let n = mesh.positions.len();
    let mut used = vec![false; n];
    for &v in mesh.faces.indices() {
        used[v as usize] = true;
    }
    for c in &mesh.curves {
        for &v in c {
            used[v as usize] = true;
        }
    }
    let mut map = vec![NONE; n];
    let mut next = 0u32;
    for i in 0..n {
        if used[i] {
            map[i] = next;
            next += 1;
        }
    }
    let removed = n - next as usize;
    if removed > 0 {
        keep_used(&mut mesh.positions, &used);
        if let Some(nr) = &mut mesh.normals {
            keep_used(nr, &used);
        }
        if let Some(uv) = &mut mesh.uvs {
            keep_used(uv, &used);
        }
        for v in mesh.faces.indices_mut() {
            *v = map[*v as usize];
        }
        for c in &mut mesh.curves {
            for v in c {
                *v = map[*v as usize];
            }
        }
    }
    CompactReport { removed_vertices: removed, map }
}

fn keep_used<T>(v: &mut Vec<T>, used: &[bool]) {
    let mut k = 0;
    v.retain(|_| {
        k += 1;
        used[k - 1]
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collapse_drop_and_dedupe() {
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0]];
        let mut f = Faces::new();
        f.push(&[0, 1, 1, 2], 3); // collapses to a triangle
        f.push(&[0, 0, 1], 0); // repeated: dropped
        f.push(&[0, 1, 4], 0); // collinear: zero area
        f.push(&[2, 1, 0], 0); // duplicate of face 0 after collapse
        f.push(&[0, 2, 3], 1);
        let mut m = Mesh::new(p, f);
        let r = clean(&mut m, true, true, 2.0, &Progress::new()).unwrap();
        assert_eq!(r.collapsed_corners, 2);
        assert_eq!(r.dropped_repeated_index, 1);
        assert_eq!(r.dropped_zero_area, 1);
        assert_eq!(r.dropped_duplicates, 1);
        assert_eq!(m.faces.len(), 2);
        assert_eq!(m.faces.get(0), &[0, 1, 2]);
        assert_eq!(m.faces.group(0), 3);
        assert_eq!(m.faces.group(1), 1);
        let c = compact(&mut m);
        assert_eq!(c.removed_vertices, 1);
        assert_eq!(c.map, vec![0, 1, 2, 3, NONE]);
        assert_eq!(m.positions.len(), 4);
    }

    #[test]
    fn compact_keeps_curve_vertices_and_attributes() {
        let p = vec![[0.0; 3], [1.0, 0.0, 0.0], [9.0; 3], [0.0, 1.0, 0.0], [5.0; 3]];
        let mut m = Mesh::from_triangles(p, &[[0, 1, 3]]);
        m.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [9.0, 9.0], [0.0, 1.0], [5.0, 5.0]]);
        m.curves = vec![vec![4, 0]];
        let c = compact(&mut m);
        assert_eq!(c.removed_vertices, 1);
        assert_eq!(m.faces.get(0), &[0, 1, 2]);
        assert_eq!(m.curves[0], vec![3, 0]);
        assert_eq!(m.uvs.as_ref().unwrap()[3], [5.0, 5.0]);
    }
}
