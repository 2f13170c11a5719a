//! Removing isolated small parts (seed 003 §4.2.3).

use serde::Serialize;

use crate::mesh::Mesh;
use crate::topology::{Connectivity, Topology};

#[derive(Debug, Clone, Serialize, Default)]
pub struct ComponentsReport {
    /// Components by shared edges before the step.
    pub components_before: usize,
    pub components_removed: usize,
    pub faces_removed: usize,
}

/// Drops components (faces connected through edges) with fewer than `min_faces` faces, or all
/// but the largest when `keep_largest` (ties: the first in face order).
pub fn remove_small(mesh: &mut Mesh, min_faces: usize, keep_largest: bool) -> ComponentsReport {
    let comps = Topology::new(mesh).components(Connectivity::SharedEdge);
    let largest = (0..comps.count()).max_by_key(|&c| (comps.sizes[c], std::cmp::Reverse(c)));
    let keep: Vec<bool> = (0..comps.count())
        .map(|c| (comps.sizes[c] as usize) >= min_faces && (!keep_largest || Some(c) == largest))
        .collect();
    let faces_removed = (0..comps.count()).filter(|&c| !keep[c]).map(|c| comps.sizes[c] as usize).sum();
    mesh.faces.retain(|f| keep[comps.face_label[f] as usize]);
    ComponentsReport {
        components_before: comps.count(),
        components_removed: keep.iter().filter(|&&k| !k).count(),
        faces_removed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    #[test]
    fn small_and_largest() {
        let big = shapes::icosphere(1, 1.0); // 80 faces
        let mut m = big.clone();
        let off = m.positions.len() as u32;
        m.positions.extend([[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0]]);
        m.faces.push(&[off, off + 1, off + 2], 0);
        let mut a = m.clone();
        let r = remove_small(&mut a, 2, false);
        assert_eq!((r.components_before, r.components_removed, r.faces_removed), (2, 1, 1));
        assert_eq!(a.faces.len(), 80);
        let mut b = m.clone();
        let r = remove_small(&mut b, 0, true);
        assert_eq!(r.faces_removed, 1);
        let mut c = m;
        assert_eq!(remove_small(&mut c, 0, false).faces_removed, 0);
    }
}
