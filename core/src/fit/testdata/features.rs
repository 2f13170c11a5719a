//! Feature-line networks: the sharp edges of a mesh (normals of the two faces more than a given
//! angle apart), each edge given as its own two-point polyline, as a crease detector exports them;
//! the fit's reader welds them into a network. Unlike plane sections they end in the open (a crease
//! that fades out) and meet at corners of any valence. The truth they come with: the regions they
//! cut the mesh into, counted on the mesh's own faces (joined across every edge that is not sharp).

use crate::fit::smooth::edge_bends;
use crate::mesh::{Mesh, Point3};
use crate::topology::{find, union};

use super::curves::polylines;

/// The interior edges of `m` whose two faces' normals are more than `deg` degrees apart, each as
/// (smaller, larger) vertex in sorted order, and the number of regions they cut `m` into (faces
/// joined across every other edge of two faces; [`edge_bends`], as smoothing's crease test).
pub fn sharp_edges(m: &Mesh, deg: f64) -> (Vec<[u32; 2]>, usize) {
    let tris = m.faces.triangles();
    let cos = deg.to_radians().cos();
    let mut parent: Vec<u32> = (0..tris.len() as u32).collect();
    let mut sharp = Vec::new();
    for e in edge_bends(&m.positions, &tris) {
        if e.cos < cos {
            sharp.push([e.a.min(e.b), e.a.max(e.b)]);
        } else {
            union(&mut parent, e.f, e.g);
        }
    }
    sharp.sort_unstable();
    let regions = (0..tris.len() as u32).filter(|&f| find(&mut parent, f) == f).count();
    (sharp, regions)
}

/// The sharp edges of `m` ([`sharp_edges`]) as two-point polylines.
pub fn feature_curves(m: &Mesh, deg: f64) -> Mesh {
    let (edges, _) = sharp_edges(m, deg);
    let lines: Vec<Vec<Point3>> =
        edges.iter().map(|e| vec![m.positions[e[0] as usize], m.positions[e[1] as usize]]).collect();
    polylines(&lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::cube;

    /// A cube's 12 edges are sharp (90°) and cut it into its 6 sides; its diagonals are not.
    #[test]
    fn a_cubes_edges_are_its_features_and_cut_six_sides() {
        let m = cube();
        let (edges, regions) = sharp_edges(&m, 45.0);
        assert_eq!(edges.len(), 12);
        assert_eq!(regions, 6);
        assert_eq!(feature_curves(&m, 45.0).curves.len(), 12);
        // Nothing is sharp over 90°.
        assert_eq!(sharp_edges(&m, 91.0), (vec![], 1));
    }
}
