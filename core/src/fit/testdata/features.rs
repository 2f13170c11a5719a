//! Feature-line networks: the sharp edges of a mesh (normals of the two faces more than a given
//! angle apart), each edge given as its own two-point polyline, as a crease detector exports them;
//! the fit's reader welds them into a network. Unlike plane sections they end in the open (a crease
//! that fades out) and meet at corners of any valence. The truth they come with: the regions they
//! cut the mesh into, counted on the mesh's own faces (joined across every edge that is not sharp).

use std::collections::HashMap;

use crate::geometry::{dot, normalize, triangle_cross};
use crate::mesh::{Mesh, Point3};

use super::curves::polylines;

/// The interior edges of `m` whose two faces' normals are more than `deg` degrees apart (in a
/// fixed order), and the number of regions they cut `m` into.
pub fn sharp_edges(m: &Mesh, deg: f64) -> (Vec<[u32; 2]>, usize) {
    let tris = m.faces.triangles();
    let normals: Vec<Point3> = tris
        .iter()
        .map(|t| {
            let p = t.map(|v| m.positions[v as usize]);
            normalize(triangle_cross(p[0], p[1], p[2]))
        })
        .collect();
    let mut by_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut keys: Vec<(u32, u32)> = by_edge.keys().copied().collect();
    keys.sort_unstable();
    let cos = deg.to_radians().cos();
    let mut regions = Regions::new(tris.len());
    let mut sharp = Vec::new();
    for e in keys {
        let &[f, g] = by_edge[&e].as_slice() else { continue };
        if dot(normals[f], normals[g]) < cos {
            sharp.push([e.0, e.1]);
        } else {
            regions.join(f, g);
        }
    }
    (sharp, regions.count())
}

/// The sharp edges of `m` ([`sharp_edges`]) as two-point polylines.
pub fn feature_curves(m: &Mesh, deg: f64) -> Mesh {
    let (edges, _) = sharp_edges(m, deg);
    let lines: Vec<Vec<Point3>> =
        edges.iter().map(|e| vec![m.positions[e[0] as usize], m.positions[e[1] as usize]]).collect();
    polylines(&lines)
}

/// Union-find over faces.
struct Regions(Vec<usize>);

impl Regions {
    fn new(n: usize) -> Regions {
        Regions((0..n).collect())
    }
    fn root(&mut self, mut a: usize) -> usize {
        while self.0[a] != a {
            self.0[a] = self.0[self.0[a]];
            a = self.0[a];
        }
        a
    }
    fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.root(a), self.root(b));
        self.0[a] = b;
    }
    fn count(&mut self) -> usize {
        (0..self.0.len()).filter(|&f| self.root(f) == f).count()
    }
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
