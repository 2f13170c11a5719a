//! Edge split for the untangling: a new vertex on an edge, the one or two faces on it halved.

use crate::mesh::Point3;

use super::super::trimesh::TriMesh;

/// Splits edge (a, b) at `x` and the one or two faces on it (each into two with the same
/// orientation); the new vertex's id, or None when no face has the edge.
pub(super) fn split_edge(mesh: &mut TriMesh, a: u32, b: u32, x: Point3) -> Option<u32> {
    let faces: Vec<u32> =
        [mesh.face_with_edge(a, b), mesh.face_with_edge(b, a)].into_iter().flatten().collect();
    if faces.is_empty() {
        return None;
    }
    let m = mesh.add_vertex(x);
    for f in faces {
        let t = mesh.tris[f as usize];
        let k = (0..3).find(|&k| (t[k] == a && t[(k + 1) % 3] == b) || (t[k] == b && t[(k + 1) % 3] == a))?;
        let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        mesh.remove_face(f);
        // The removed face freed its directed edges; p→m, m→q and the edges at m are new.
        mesh.add_face([p, m, r]).ok()?;
        mesh.add_face([m, q, r]).ok()?;
    }
    Some(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_split_interior_edge_makes_four_faces_around_the_new_vertex() {
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        let mut mesh = TriMesh::new(pos, vec![[0, 1, 2], [1, 3, 2]]).unwrap();
        let m = split_edge(&mut mesh, 1, 2, [0.5, 0.5, 0.0]).unwrap();
        assert_eq!(m, 4);
        assert_eq!(mesh.faces_of(m).len(), 4);
        assert_eq!(mesh.alive_faces().count(), 4);
        assert!(!mesh.has_edge(1, 2));
        // Same orientation: every live face is counter-clockwise in the plane.
        for f in mesh.alive_faces() {
            let t = mesh.tris[f as usize];
            let c = crate::geometry::triangle_cross(
                mesh.pos[t[0] as usize],
                mesh.pos[t[1] as usize],
                mesh.pos[t[2] as usize],
            );
            assert!(c[2] > 0.0, "{t:?}");
        }
    }
}
