//! A reference-free fold measure: what a user without a truth surface (and without the job's
//! internal reference normals) can check on the output alone.
//!
//! An interior edge is *folded* when the normals of its two faces make an angle above
//! [`FOLD_ANGLE_DEG`], i.e. the two faces are turned back onto each other to within
//! 180° − [`FOLD_ANGLE_DEG`] (a crease sharper than that). A face turned over among unfolded
//! neighbours has normals nearly opposite to theirs, so each of its edges to them counts; a
//! whole mirrored patch counts along its border. Real models can have creases that sharp (the
//! template's own count is reported next to the output's, so the fit's contribution is the
//! difference), but a smooth surface sampled finely enough has none.
//!
//! Degenerate faces (zero normal) have no direction to fold; they are counted separately.

use serde::Serialize;

use crate::geometry::{dot, norm2, triangle_cross};
use crate::mesh::Point3;

use super::super::trimesh::IntMap;

/// Angle between adjacent face normals (degrees) above which their common edge counts as folded.
/// 150° = the two faces meet at an interior dihedral angle under 30°: sharper than any crease of
/// the shared test meshes (their largest is measured in `core/tests/fit_folds.rs`), and far from
/// the ~180° of a face turned over.
pub const FOLD_ANGLE_DEG: f64 = 150.0;

#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq)]
pub struct FoldStats {
    /// Interior edges whose two faces' normals differ by more than [`FOLD_ANGLE_DEG`].
    pub folded_edges: usize,
    /// Faces with at least one folded edge.
    pub folded_faces: usize,
    /// Largest angle between the normals of two adjacent non-degenerate faces (degrees).
    pub max_normal_angle_deg: f64,
    /// Faces with zero area (no normal; not counted above).
    pub degenerate_faces: usize,
}

/// Fold statistics of the triangle mesh `pos`/`tris` (edges used by more than two faces are
/// compared pairwise in the order the faces come).
pub fn fold_stats(pos: &[Point3], tris: &[[u32; 3]]) -> FoldStats {
    let normals: Vec<Point3> = tris
        .iter()
        .map(|t| triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]))
        .collect();
    let mut first: IntMap<(u32, u32), u32> = IntMap::default();
    first.reserve(tris.len() * 3 / 2);
    let cos_fold = FOLD_ANGLE_DEG.to_radians().cos();
    let mut folded_face = vec![false; tris.len()];
    let mut s = FoldStats::default();
    let mut min_cos = 1.0f64;
    for (f, t) in tris.iter().enumerate() {
        let nf = normals[f];
        if norm2(nf) == 0.0 {
            s.degenerate_faces += 1;
        }
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            let Some(&g) = first.get(&key) else {
                first.insert(key, f as u32);
                continue;
            };
            let ng = normals[g as usize];
            let d = (norm2(nf) * norm2(ng)).sqrt();
            if d == 0.0 {
                continue;
            }
            let c = dot(nf, ng) / d;
            min_cos = min_cos.min(c);
            if c < cos_fold {
                s.folded_edges += 1;
                folded_face[f] = true;
                folded_face[g as usize] = true;
            }
        }
    }
    s.folded_faces = folded_face.iter().filter(|&&x| x).count();
    s.max_normal_angle_deg = min_cos.clamp(-1.0, 1.0).acos().to_degrees();
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_turned_face_folds_its_three_edges_and_a_flat_grid_none() {
        let g = crate::shapes::grid(4, 4, 1.0, false);
        let tris = crate::shapes::fan_triangles(&g.faces);
        let s = fold_stats(&g.positions, &tris);
        assert_eq!((s.folded_edges, s.folded_faces, s.degenerate_faces), (0, 0, 0));
        assert!(s.max_normal_angle_deg < 1e-6);
        // Move one interior vertex across its ring: the faces between it and the far side turn over.
        let mut pos = g.positions.clone();
        let v = 6; // (1, 1) on the 5×5 vertex grid
        pos[v][0] += 1.6;
        let s = fold_stats(&pos, &tris);
        assert!(s.folded_edges > 0 && s.folded_faces > 0, "{s:?}");
        assert!((s.max_normal_angle_deg - 180.0).abs() < 1e-6, "{s:?}");
    }

    #[test]
    fn a_cube_crease_is_not_a_fold() {
        // Two faces at a right angle: normals 90° apart.
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let tris = vec![[0, 1, 2], [1, 0, 3]];
        let s = fold_stats(&pos, &tris);
        assert_eq!(s.folded_edges, 0);
        assert!((s.max_normal_angle_deg - 90.0).abs() < 1e-9, "{s:?}");
        // Folded to 20° (normals 160° apart): a fold.
        let a = 20f64.to_radians();
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, a.cos(), a.sin()]];
        let tris = vec![[0, 1, 2], [1, 0, 3]];
        let s = fold_stats(&pos, &tris);
        assert_eq!((s.folded_edges, s.folded_faces), (1, 2));
        assert!((s.max_normal_angle_deg - 160.0).abs() < 1e-9, "{s:?}");
    }
}
