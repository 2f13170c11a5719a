//! Template preparation before the fit: vertices at exactly one position are welded where that
//! keeps an oriented manifold ([`weld_coincident`]), vertices no face uses are removed (both
//! counted in the report).
//!
//! Every spatial search of the fit (alignment, closest points, insertion) runs over the template's
//! vertices; a vertex in no face (a duplicate left by an exporter, the rim of a deleted hole) can
//! be the nearest one to a curve point and has no face to walk from. The pairs refer to the
//! template's own numbering, so they are renumbered with it; a pair on a removed vertex is an
//! error naming the pair.

use crate::error::{Error, Result};
use crate::mesh::Mesh;

use super::compact::Renumber;
use super::FitPair;

/// The template without its unreferenced vertices, the pairs renumbered to match (None when
/// nothing changed) and the number of vertices removed.
pub fn drop_unreferenced(
    mut template: Mesh,
    pairs: &[FitPair],
) -> Result<(Mesh, Option<Vec<FitPair>>, usize)> {
    let nv = template.positions.len();
    let mut used = vec![false; nv];
    for &v in template.faces.indices() {
        if let Some(u) = used.get_mut(v as usize) {
            *u = true;
        }
    }
    for (i, p) in pairs.iter().enumerate() {
        let v = p.template_vertex as usize;
        if v >= nv {
            return Err(Error::params(
                format!("pairs[{i}].template_vertex"),
                format!("vertex {v} does not exist (the template has {nv} vertices)"),
            ));
        }
        if !used[v] {
            return Err(Error::params(
                format!("pairs[{i}].template_vertex"),
                format!("vertex {v} is in no face of the template"),
            ));
        }
    }
    let removed: Vec<u32> = (0..nv as u32).filter(|&v| !used[v as usize]).collect();
    if removed.is_empty() {
        return Ok((template, None, 0));
    }
    let keep = Renumber::new(nv, &removed);
    template.positions = keep.vec(&template.positions);
    template.normals = template.normals.as_ref().map(|n| keep.vec(n));
    template.uvs = template.uvs.as_ref().map(|uv| keep.vec(uv));
    keep.apply(template.faces.indices_mut());
    // Template curves are not used by the fit; indices into removed vertices would dangle.
    template.curves.clear();
    let pairs = pairs
        .iter()
        .map(|p| FitPair { template_vertex: keep.index(p.template_vertex), curve_point: p.curve_point })
        .collect();
    Ok((template, Some(pairs), removed.len()))
}

/// What [`drop_repeated_corners`] changed (the report's `template_repeated_corners`).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct RepeatedCorners {
    /// Corners removed because they repeat the corner before them (a quad `a a b c` is the
    /// triangle `a b c`).
    pub corners_removed: usize,
    /// Faces removed: fewer than three distinct corners left, or a vertex repeated elsewhere in
    /// the face (a pinched polygon). Their indices, first ten.
    pub faces_removed: usize,
    pub first_faces_removed: Vec<usize>,
}

/// Removes the corners of template faces that repeat the corner before them (cyclically) and
/// the faces left with fewer than three corners or with another repeat. Exporters write such
/// faces for collapsed edges (`f 3 3 5`); they have no area and no orientation, and a repeated
/// vertex makes no triangle of a mesh, so the fit would have to refuse the template. Counted in
/// the report, never silent.
pub fn drop_repeated_corners(template: &mut Mesh) -> RepeatedCorners {
    let mut r = RepeatedCorners::default();
    let bad = |f: &[u32]| (0..f.len()).any(|k| f[k] == f[(k + 1) % f.len()]) || f.len() < 3;
    if !template.faces.iter().any(|f| bad(f) || (1..f.len()).any(|k| f[..k].contains(&f[k]))) {
        return r;
    }
    let mut faces = crate::mesh::Faces::with_capacity(template.faces.len(), template.faces.indices().len());
    let mut corners: Vec<u32> = Vec::new();
    for (i, f) in template.faces.iter().enumerate() {
        corners.clear();
        for k in 0..f.len() {
            if f[k] != f[(k + 1) % f.len()] {
                corners.push(f[k]);
            }
        }
        r.corners_removed += f.len() - corners.len();
        let pinched = (1..corners.len()).any(|k| corners[..k].contains(&corners[k]));
        if corners.len() < 3 || pinched {
            r.faces_removed += 1;
            if r.first_faces_removed.len() < 10 {
                r.first_faces_removed.push(i);
            }
            continue;
        }
        faces.push(&corners, template.faces.group(i));
    }
    template.faces = faces;
    r
}

/// Welds template vertices at exactly the same position (−0 = +0), so that a raw mesh exported
/// as separate patches or with unwelded seams (the Utah teapot's 32 patches: 403 duplicates) is
/// one surface: a curve crossing a seam can then be a chain of edges, which no re-triangulation
/// can make across a crack of two boundaries (the raw teapot lost 43 segments that way). The STL
/// reader welds the same way. Not welded: vertices whose UVs differ (a texture seam stays a seam),
/// vertices in no face or on no boundary edge, and nothing at all when the welded faces would repeat a vertex or use an edge twice in one
/// direction (the template is then used as given). Pairs follow their vertex (onto the kept one);
/// the welded-away vertices are left in no face, for [`drop_unreferenced`]. Returns the number of
/// vertices welded away.
pub fn weld_coincident(template: &mut Mesh, pairs: &mut [FitPair]) -> usize {
    use std::collections::HashMap;
    let nv = template.positions.len();
    let key = |p: &crate::mesh::Point3| p.map(|c| (c + 0.0).to_bits());
    let mut first: HashMap<([u64; 3], Option<[u64; 2]>), u32> = HashMap::with_capacity(nv);
    let mut to: Vec<u32> = (0..nv as u32).collect();
    let mut welded = 0;
    // Only vertices of faces: one in no face is no seam (and a pair on it must still be refused).
    let mut used = vec![false; nv];
    for &v in template.faces.indices() {
        if let Some(u) = used.get_mut(v as usize) {
            *u = true;
        }
    }
    // Only boundary vertices: a seam is a crack of boundary edges. Interior vertices at one
    // position (raw suzanne has two pairs, each with its own closed fan) would be pinched into
    // non-manifold vertices by a weld (measured: 7 flips instead of 0).
    let tris = crate::shapes::fan_triangles(&template.faces);
    let on_rim = super::trimesh::boundary_vertices(nv, &tris);
    for v in (0..nv).filter(|&v| used[v] && on_rim[v]) {
        let uv = template.uvs.as_ref().and_then(|u| u.get(v)).map(|t| t.map(|c| (c + 0.0).to_bits()));
        let k = first.entry((key(&template.positions[v]), uv)).or_insert(v as u32);
        if *k != v as u32 {
            to[v] = *k;
            welded += 1;
        }
    }
    if welded == 0 {
        return 0;
    }
    let mut faces = template.faces.clone();
    for i in faces.indices_mut() {
        if let Some(&t) = to.get(*i as usize) {
            *i = t;
        }
    }
    let repeats = faces.iter().any(|f| (1..f.len()).any(|k| f[..k].contains(&f[k])));
    if repeats || super::trimesh::check_oriented_manifold(&crate::shapes::fan_triangles(&faces)).is_err() {
        return 0;
    }
    template.faces = faces;
    for p in pairs.iter_mut() {
        if let Some(&t) = to.get(p.template_vertex as usize) {
            p.template_vertex = t;
        }
    }
    welded
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Faces;

    /// Two triangles of a unit square given as separate patches (6 vertices, the diagonal's ends
    /// repeated): welded to 4 vertices used by both faces, the pair on a repeat moves to the kept
    /// vertex. Hand truth: vertices 3 and 4 repeat 0 and 2.
    #[test]
    fn coincident_vertices_are_welded_unless_uvs_differ_or_orientation_breaks() {
        let pos = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [-0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let m = Mesh::new(pos.clone(), Faces::from_triangles(&[[0, 1, 2], [3, 4, 5]]));
        let mut pairs = vec![FitPair { template_vertex: 4, curve_point: [0.0; 3] }];
        let mut w = m.clone();
        assert_eq!(weld_coincident(&mut w, &mut pairs), 2);
        assert_eq!(w.faces.get(1), &[0, 2, 5]);
        assert_eq!(pairs[0].template_vertex, 2);
        let (w, _, dropped) = drop_unreferenced(w, &[]).unwrap();
        assert_eq!((dropped, w.positions.len()), (2, 4));
        // Different UVs at vertex 4 (a texture seam): only 3 is welded.
        let mut t = m.clone();
        t.uvs = Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 0.0], [0.5, 1.0], [0.0, 1.0]]);
        assert_eq!(weld_coincident(&mut t, &mut []), 1);
        assert_eq!(t.faces.get(1), &[0, 4, 5]);
        // The second patch turned over: welding would use edge 0→2 twice; nothing is welded.
        let mut f = Mesh::new(pos, Faces::from_triangles(&[[0, 1, 2], [3, 5, 4]]));
        assert_eq!(weld_coincident(&mut f, &mut []), 0);
        assert_eq!(f.faces.get(1), &[3, 5, 4]);
    }

    /// Hand-made faces: a triangle with a doubled corner, a quad whose last corner repeats its
    /// first (a triangle), a face of two distinct corners and a pinched pentagon.
    #[test]
    fn repeated_corners_are_removed_and_counted() {
        let pos = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0]];
        let mut faces = Faces::new();
        faces.push(&[0, 1, 2], 0);
        faces.push(&[1, 1, 3, 2], 1);
        faces.push(&[4, 3, 1, 4], 0);
        faces.push(&[0, 0, 1, 1], 0);
        faces.push(&[0, 1, 3, 1, 4], 0);
        let mut m = Mesh::new(pos, faces);
        let r = drop_repeated_corners(&mut m);
        assert_eq!((r.corners_removed, r.faces_removed), (4, 2));
        assert_eq!(r.first_faces_removed, vec![3, 4]);
        assert_eq!(m.faces.len(), 3);
        assert_eq!((m.faces.get(1), m.faces.group(1)), (&[1, 3, 2][..], 1));
        assert_eq!(m.faces.get(2), &[4, 3, 1]);
        // Nothing to do: the same faces object.
        let before = m.faces.clone();
        assert_eq!(drop_repeated_corners(&mut m).faces_removed, 0);
        assert_eq!(m.faces, before);
    }

    #[test]
    fn unreferenced_vertices_go_and_pairs_follow() {
        // Vertices 0 and 3 are in no face; the triangle is 1 2 4.
        let pos = vec![[9.0; 3], [0.0; 3], [1.0, 0.0, 0.0], [7.0; 3], [0.0, 1.0, 0.0]];
        let m = Mesh::new(pos, Faces::from_triangles(&[[1, 2, 4]]));
        let pair = |v| FitPair { template_vertex: v, curve_point: [0.0; 3] };
        let (t, pairs, n) = drop_unreferenced(m.clone(), &[pair(4), pair(1)]).unwrap();
        assert_eq!(n, 2);
        assert_eq!(t.positions, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(t.faces.get(0), &[0, 1, 2]);
        let pairs = pairs.unwrap();
        assert_eq!((pairs[0].template_vertex, pairs[1].template_vertex), (2, 0));
        let e = drop_unreferenced(m.clone(), &[pair(3)]).unwrap_err().to_string();
        assert!(e.contains("pairs[0].template_vertex") && e.contains("no face"), "{e}");
        let e = drop_unreferenced(m, &[pair(5)]).unwrap_err().to_string();
        assert!(e.contains("does not exist"), "{e}");
    }
}
