//! Connected components of the faces under a chosen connectivity.

use super::{find, union, Topology, NONE};

/// How faces are considered connected when labelling components.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Connectivity {
    /// Faces sharing at least one vertex are connected (a bow-tie is one component).
    SharedVertex,
    /// Faces sharing an edge (any number of uses) are connected.
    SharedEdge,
    /// Faces sharing an edge with exactly two uses are connected (the patches orientation can be
    /// propagated across).
    ManifoldEdge,
}

/// Connected components of the faces.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Components {
    /// Component id of each face, `0..count`, numbered in order of first face.
    pub face_label: Vec<u32>,
    /// Number of faces in each component.
    pub sizes: Vec<u32>,
}

impl Components {
    pub fn count(&self) -> usize {
        self.sizes.len()
    }
}

impl Topology {
    /// Connected components of the faces under the given connectivity.
    pub fn components(&self, how: Connectivity) -> Components {
        let nf = self.face_count();
        let mut parent: Vec<u32> = (0..nf as u32).collect();
        match how {
            Connectivity::SharedVertex => {
                for v in 0..self.n_vertices as u32 {
                    let cs = self.vertex_corners(v);
                    if let Some(&c0) = cs.first() {
                        let f0 = self.corner_face[c0 as usize];
                        for &c in &cs[1..] {
                            union(&mut parent, f0, self.corner_face[c as usize]);
                        }
                    }
                }
            }
            Connectivity::SharedEdge | Connectivity::ManifoldEdge => {
                for e in 0..self.edges.len() as u32 {
                    let u = self.edge_uses(e);
                    if how == Connectivity::ManifoldEdge && u.len() != 2 {
                        continue;
                    }
                    for w in &u[1..] {
                        union(&mut parent, u[0].face, w.face);
                    }
                }
            }
        }
        let mut label = vec![NONE; nf];
        let mut root_label = vec![NONE; nf];
        let mut sizes = Vec::new();
        for f in 0..nf {
            let r = find(&mut parent, f as u32) as usize;
            if root_label[r] == NONE {
                root_label[r] = sizes.len() as u32;
                sizes.push(0);
            }
            label[f] = root_label[r];
            sizes[root_label[r] as usize] += 1;
        }
        Components { face_label: label, sizes }
    }
}
