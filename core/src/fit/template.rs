//! Template preparation before the fit: vertices no face uses are removed (and counted).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Faces;

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
