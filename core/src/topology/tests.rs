//! Topology on hand-built face lists: counts, loops, pinches, non-manifold fans.

use super::*;
use crate::mesh::Faces;
use crate::shapes;

fn topo(n: usize, faces: &[&[u32]]) -> Topology {
    let mut f = Faces::new();
    for face in faces {
        f.push(face, 0);
    }
    Topology::from_faces(&f, n)
}

#[test]
fn single_triangle() {
    let t = topo(3, &[&[0, 1, 2]]);
    assert_eq!(t.edges(), &[[0, 1], [0, 2], [1, 2]]);
    assert_eq!(t.boundary_edges().len(), 3);
    let loops = t.boundary_loops();
    assert_eq!(loops.len(), 1);
    assert!(loops[0].closed);
    assert_eq!(loops[0].vertices, vec![0, 1, 2]);
    assert_eq!(t.vertex_kinds(), vec![VertexKind::Boundary; 3]);
    assert_eq!(t.find_edge(2, 0), Some(1));
    assert_eq!(t.find_edge(0, 0), None);
}

#[test]
fn icosphere_is_closed_manifold_consistent() {
    let m = shapes::icosphere(2, 1.0);
    let t = Topology::new(&m);
    // V − E + F = 2 with E = 3F/2.
    assert_eq!(t.edge_count(), m.face_count() * 3 / 2);
    assert!(t.boundary_edges().is_empty());
    assert!(t.non_manifold_edges().is_empty());
    assert!(t.inconsistent_edges().is_empty());
    assert!(t.vertex_kinds().iter().all(|&k| k == VertexKind::Interior));
    assert_eq!(t.components(Connectivity::SharedEdge).count(), 1);
    // Every vertex of an icosphere has valence 5 or 6.
    let ring = t.vertex_neighbors();
    assert!((0..ring.rows()).all(|v| matches!(ring.row(v).len(), 5 | 6)));
}

#[test]
fn quad_grid_has_one_loop_of_perimeter_length() {
    let m = shapes::grid(4, 3, 1.0, true);
    let t = Topology::new(&m);
    let loops = t.boundary_loops();
    assert_eq!(loops.len(), 1);
    assert_eq!(loops[0].vertices.len(), 2 * (4 + 3));
    assert!(loops[0].closed);
    // A loop is a closed walk: consecutive vertices are joined by the listed edge.
    let l = &loops[0];
    for i in 0..l.vertices.len() {
        let (a, b) = (l.vertices[i], l.vertices[(i + 1) % l.vertices.len()]);
        assert_eq!(t.find_edge(a, b), Some(l.edges[i]));
    }
}

/// 5×5-vertex grid, each quad split along its (i,j)–(i+1,j+1) diagonal; `skip` removes faces.
fn grid5(skip: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut tris = Vec::new();
    for j in 0..4u32 {
        for i in 0..4u32 {
            let (a, b, c, d) = (j * 5 + i, j * 5 + i + 1, (j + 1) * 5 + i, (j + 1) * 5 + i + 1);
            for t in [[a, b, d], [a, d, c]] {
                if !skip.contains(&t) {
                    tris.push(t);
                }
            }
        }
    }
    tris
}

/// Seed 003 Fig. 4.6: two holes sharing a vertex. Removing two triangles of a grid that touch
/// only at the centre vertex 12 leaves two open fans there: a pinch, not a non-manifold vertex,
/// and each hole is a loop of its own (3 edges each) besides the 16-edge rim.
#[test]
fn two_holes_sharing_a_vertex_is_a_pinch() {
    let tris = grid5(&[[6, 7, 12], [12, 13, 18]]);
    assert_eq!(tris.len(), 30);
    let f: Vec<&[u32]> = tris.iter().map(|t| &t[..]).collect();
    let t = topo(25, &f);
    let kinds = t.vertex_kinds();
    assert_eq!(kinds[12], VertexKind::Pinch);
    assert_eq!(t.fans(12), (2, 0, false));
    assert!(!kinds.contains(&VertexKind::NonManifold));
    let mut lens: Vec<usize> = t.boundary_loops().iter().map(|l| l.edges.len()).collect();
    lens.sort();
    assert_eq!(lens, vec![3, 3, 16]);
    let loops = t.boundary_loops();
    assert!(loops.iter().all(|l| l.closed));
    for l in loops.iter().filter(|l| l.edges.len() == 3) {
        let mut v = l.vertices.clone();
        v.sort();
        assert!(v == vec![6, 7, 12] || v == vec![12, 13, 18], "{v:?}");
    }
}

/// `vertex_kinds` (global union-find) agrees with the per-vertex `fans` on every case here.
#[test]
fn vertex_kinds_agree_with_per_vertex_fans() {
    let cases: Vec<Vec<[u32; 3]>> = vec![
        grid5(&[[6, 7, 12], [12, 13, 18]]),
        grid5(&[[6, 7, 12]]),
        grid5(&[]),
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [0, 5, 6], [0, 6, 7], [0, 7, 5]],
    ];
    for tris in cases {
        let f: Vec<&[u32]> = tris.iter().map(|t| &t[..]).collect();
        let t = topo(25, &f);
        let kinds = t.vertex_kinds();
        for v in 0..25u32 {
            let (fans, closed, nm) = t.fans(v);
            let expect = match (fans, closed, nm) {
                (0, _, _) => VertexKind::Unreferenced,
                (_, _, true) => VertexKind::OnNonManifoldEdge,
                (1, 1, _) => VertexKind::Interior,
                (1, _, _) => VertexKind::Boundary,
                (_, 0, _) => VertexKind::Pinch,
                _ => VertexKind::NonManifold,
            };
            assert_eq!(kinds[v as usize], expect, "vertex {v}");
        }
    }
}

#[test]
fn figure_eight_walk_splits_into_two_cycles() {
    let l =
        BoundaryLoop { vertices: vec![0, 1, 2, 0, 3, 4], edges: vec![10, 11, 12, 13, 14, 15], closed: true };
    let c = l.simple_cycles();
    assert_eq!(c.len(), 2);
    assert_eq!(c[0].vertices, vec![0, 1, 2]);
    assert_eq!(c[0].edges, vec![10, 11, 12]);
    assert_eq!(c[1].vertices, vec![0, 3, 4]);
    assert_eq!(c[1].edges, vec![13, 14, 15]);
}

/// The bow-tie: two triangles sharing only a vertex. Both fans are open: a pinch too.
#[test]
fn bowtie_is_a_pinch() {
    let t = topo(5, &[&[0, 1, 2], &[0, 3, 4]]);
    assert_eq!(t.vertex_kinds()[0], VertexKind::Pinch);
    assert_eq!(t.boundary_loops().iter().map(|l| l.edges.len()).sum::<usize>(), 6);
}

/// Two tetrahedra glued at one vertex: two closed fans there = a real non-manifold vertex.
#[test]
fn two_closed_fans_is_non_manifold() {
    let tet = |o: u32| [[o, o + 2, o + 1], [o, o + 1, o + 3], [o + 1, o + 2, o + 3], [o + 2, o, o + 3]];
    let mut faces: Vec<[u32; 3]> = tet(0).to_vec();
    // Second tetrahedron: vertices 3 (shared), 4, 5, 6.
    for f in tet(3).iter() {
        faces.push(*f);
    }
    let f: Vec<&[u32]> = faces.iter().map(|f| &f[..]).collect();
    // tet(3) uses 3,4,5,6 with 3 as its apex "o".
    let t = topo(7, &f);
    let kinds = t.vertex_kinds();
    assert_eq!(kinds[3], VertexKind::NonManifold);
    assert_eq!(kinds.iter().filter(|&&k| k == VertexKind::NonManifold).count(), 1);
    assert!(t.boundary_edges().is_empty());
    assert_eq!(t.components(Connectivity::SharedVertex).count(), 1);
    assert_eq!(t.components(Connectivity::SharedEdge).count(), 2);
}

#[test]
fn three_faces_on_one_edge() {
    let t = topo(5, &[&[0, 1, 2], &[1, 0, 3], &[0, 1, 4]]);
    let nm = t.non_manifold_edges();
    assert_eq!(nm.len(), 1);
    assert_eq!(t.edge(nm[0]), [0, 1]);
    assert_eq!(t.edge_valence(nm[0]), 3);
    let k = t.vertex_kinds();
    assert_eq!(k[0], VertexKind::OnNonManifoldEdge);
    assert_eq!(k[2], VertexKind::Boundary);
    // No panic walking loops around a non-manifold edge; each boundary edge in one loop.
    let loops = t.boundary_loops();
    assert_eq!(loops.iter().map(|l| l.edges.len()).sum::<usize>(), 6);
}

#[test]
fn flipped_face_gives_inconsistent_edges() {
    let m = shapes::icosphere(1, 1.0);
    let mut faces = Faces::new();
    for (i, f) in m.faces.iter().enumerate() {
        if i == 7 {
            faces.push(&[f[0], f[2], f[1]], 0);
        } else {
            faces.push(f, 0);
        }
    }
    let t = Topology::from_faces(&faces, m.vertex_count());
    assert_eq!(t.inconsistent_edges().len(), 3);
}

#[test]
fn degenerate_and_out_of_range_do_not_panic() {
    let t = topo(2, &[&[0, 0, 1], &[5], &[1, 2]]);
    assert_eq!(t.vertex_count(), 6);
    assert_eq!(t.degenerate_half_edges(), 2);
    let _ = t.boundary_loops();
    let _ = t.vertex_kinds();
    let _ = t.components(Connectivity::SharedVertex);
}

#[test]
fn vertex_faces_dedup_and_neighbors() {
    let t = topo(4, &[&[0, 1, 2], &[0, 2, 3]]);
    let vf = t.vertex_faces();
    assert_eq!(vf.row(0), &[0, 1]);
    assert_eq!(vf.row(1), &[0]);
    let nb = t.vertex_neighbors();
    assert_eq!(nb.row(0), &[1, 2, 3]);
    assert_eq!(nb.row(1), &[0, 2]);
}

#[test]
fn vertex_triangles_lists_each_face_once_per_vertex_in_face_order() {
    // A fin (faces 0, 1, 3 on edge 0–1), a face repeating vertex 2, and one with an index past nv.
    let tris = [[0, 1, 2], [1, 0, 3], [2, 2, 4], [0, 1, 4], [4, 9, 1]];
    let vf = Csr::vertex_triangles(5, &tris);
    assert_eq!(vf.rows(), 5);
    assert_eq!(vf.row(0), &[0, 1, 3]);
    assert_eq!(vf.row(1), &[0, 1, 3, 4]);
    assert_eq!(vf.row(2), &[0, 2]);
    assert_eq!(vf.row(3), &[1]);
    assert_eq!(vf.row(4), &[2, 3, 4]);
    let on = |a, b| vf.triangles_on_edge(&tris, a, b).collect::<Vec<_>>();
    assert_eq!(on(0, 1), vec![0, 1, 3]);
    assert_eq!(on(1, 0), vec![0, 1, 3]);
    assert_eq!(on(2, 4), vec![2]);
    assert_eq!(on(3, 4), Vec::<u32>::new());
    assert_eq!(on(7, 1), Vec::<u32>::new(), "a vertex past nv has no row");
}
