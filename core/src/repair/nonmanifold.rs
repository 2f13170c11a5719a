//! Resolving non-manifold edges and vertices (seed 003 §4.2.1–4.2.2).
//!
//! Both modes first decide, at every edge with more than two faces, which pair of faces stays
//! *glued*: among the pairs that traverse the edge in opposite directions (so a consistent
//! orientation is possible) the one whose face normals agree best (the smoothest continuation of
//! the surface, which is what a doubled sheet glued onto a surface, seed 003 Fig. 4.4, breaks).
//! Edges with two faces are always glued. Then, around each vertex that is non-manifold or on a
//! non-manifold edge, faces connected through glued edges form fans:
//! - `split` gives every fan but the largest its own copy of the vertex (position, normal, UV), so
//!   the loose faces become a separate sheet with a boundary there;
//! - `remove` deletes the faces of every fan but the largest, and the unglued faces of
//!   non-manifold edges.
//!
//! Pinch vertices (several open fans, no non-manifold edge: holes touching) are left alone: they
//! are not non-manifold (seed 003 Fig. 4.6) and splitting them would merge the two holes.

use serde::Serialize;

use super::NonManifoldMode;
use crate::error::Result;
use crate::geometry::{dot, normalize};
use crate::job::Progress;
use crate::mesh::{Mesh, Point3};
use crate::topology::{find, union, Topology, VertexKind, NONE};

#[derive(Debug, Clone, Serialize, Default)]
pub struct NonManifoldReport {
    pub non_manifold_edges_before: usize,
    pub non_manifold_vertices_before: usize,
    /// Vertices split into several (split mode).
    pub vertices_split: usize,
    /// New vertex copies created (split mode).
    pub vertices_added: usize,
    /// Faces deleted (remove mode, or split's fallback for tangles splitting cannot undo).
    pub faces_removed: usize,
    pub non_manifold_edges_after: usize,
    pub non_manifold_vertices_after: usize,
}

/// Applies `mode` (split or remove) to every non-manifold edge and vertex.
pub fn resolve(mesh: &mut Mesh, mode: NonManifoldMode, progress: &Progress) -> Result<NonManifoldReport> {
    let mut r = NonManifoldReport::default();
    let topo = Topology::new(mesh);
    let kinds = topo.vertex_kinds();
    r.non_manifold_edges_before = topo.non_manifold_edges().len();
    r.non_manifold_vertices_before = kinds.iter().filter(|&&k| k == VertexKind::NonManifold).count();
    if mode == NonManifoldMode::Keep
        || (r.non_manifold_edges_before == 0 && r.non_manifold_vertices_before == 0)
    {
        return Ok(r);
    }
    // Two rounds: the second catches tangles where a fan reconnected around a vertex kept an edge
    // non-manifold; whatever survives it in split mode is removed.
    for round in 0..3 {
        progress.check()?;
        let topo = Topology::new(mesh);
        let kinds = topo.vertex_kinds();
        let bad_edges = topo.non_manifold_edges();
        if bad_edges.is_empty() && !kinds.contains(&VertexKind::NonManifold) {
            break;
        }
        let partner = glue(mesh, &topo);
        let use_mode = if round == 2 { NonManifoldMode::Remove } else { mode };
        let mut remove_face = vec![false; mesh.faces.len()];
        if use_mode == NonManifoldMode::Remove {
            // Unglued faces at non-manifold edges go.
            for &e in &bad_edges {
                for u in topo.edge_uses(e) {
                    if partner[topo.use_corner(u)] == NONE {
                        remove_face[u.face as usize] = true;
                    }
                }
            }
        }
        let mut fans = FanScratch::default();
        for v in 0..topo.vertex_count() as u32 {
            if !matches!(kinds[v as usize], VertexKind::NonManifold | VertexKind::OnNonManifoldEdge) {
                continue;
            }
            let classes = fans.classes(&topo, &partner, v);
            if classes.len() < 2 {
                continue;
            }
            let corners = topo.vertex_corners(v);
            // Keep the largest fan on the original vertex.
            let keep =
                (0..classes.len()).max_by_key(|&k| (classes[k].len(), std::cmp::Reverse(k))).unwrap_or(0);
            match use_mode {
                NonManifoldMode::Split => {
                    r.vertices_split += 1;
                    for (k, class) in classes.iter().enumerate() {
                        if k == keep {
                            continue;
                        }
                        let p = mesh.positions[v as usize];
                        let nv = super::push_vertex(mesh, p, &[v]);
                        r.vertices_added += 1;
                        for &i in class {
                            mesh.faces.indices_mut()[corners[i as usize] as usize] = nv;
                        }
                    }
                }
                _ => {
                    for (k, class) in classes.iter().enumerate() {
                        if k != keep {
                            for &i in class {
                                remove_face[topo.corner_face(corners[i as usize] as usize) as usize] = true;
                            }
                        }
                    }
                }
            }
        }
        let removed = remove_face.iter().filter(|&&b| b).count();
        if removed > 0 {
            r.faces_removed += removed;
            mesh.faces.retain(|i| !remove_face[i]);
        }
    }
    let topo = Topology::new(mesh);
    r.non_manifold_edges_after = topo.non_manifold_edges().len();
    r.non_manifold_vertices_after =
        topo.vertex_kinds().iter().filter(|&&k| k == VertexKind::NonManifold).count();
    Ok(r)
}

/// Unit normals of the faces (Newell), zero for degenerate faces.
pub(crate) fn face_normals(positions: &[Point3], topo: &Topology) -> Vec<Point3> {
    (0..topo.face_count() as u32)
        .map(|f| {
            let vs = topo.face_vertices(f);
            let mut s = [0.0; 3];
            for k in 0..vs.len() {
                let a = positions[vs[k] as usize];
                let b = positions[vs[(k + 1) % vs.len()] as usize];
                s[0] += (a[1] - b[1]) * (a[2] + b[2]);
                s[1] += (a[2] - b[2]) * (a[0] + b[0]);
                s[2] += (a[0] - b[0]) * (a[1] + b[1]);
            }
            normalize(s)
        })
        .collect()
}

/// For every half-edge (global corner), the half-edge it is glued to, or [`NONE`].
fn glue(mesh: &Mesh, topo: &Topology) -> Vec<u32> {
    let mut partner = vec![NONE; mesh.faces.indices().len()];
    let normals = face_normals(&mesh.positions, topo);
    for e in 0..topo.edge_count() as u32 {
        let uses = topo.edge_uses(e);
        let pair = match uses.len() {
            2 => Some((0, 1)),
            k if k > 2 => {
                let mut best: Option<((bool, f64), usize, usize)> = None;
                for i in 0..k {
                    for j in i + 1..k {
                        if uses[i].face == uses[j].face {
                            continue;
                        }
                        let opposite = uses[i].forward != uses[j].forward;
                        let agree = dot(normals[uses[i].face as usize], normals[uses[j].face as usize]);
                        // Orientation-compatible pairs first; then the flattest continuation.
                        let agree = if opposite { agree } else { -agree };
                        let score = (opposite, agree);
                        if best.is_none_or(|(s, _, _)| score > s) {
                            best = Some((score, i, j));
                        }
                    }
                }
                best.map(|(_, i, j)| (i, j))
            }
            _ => None,
        };
        if let Some((i, j)) = pair {
            let (ci, cj) = (topo.use_corner(&uses[i]), topo.use_corner(&uses[j]));
            partner[ci] = cj as u32;
            partner[cj] = ci as u32;
        }
    }
    partner
}

#[derive(Default)]
struct FanScratch {
    parent: Vec<u32>,
}

impl FanScratch {
    /// The fans at `v` (as lists of local corner positions), joined through glued half-edges.
    fn classes(&mut self, topo: &Topology, partner: &[u32], v: u32) -> Vec<Vec<u32>> {
        let corners = topo.vertex_corners(v);
        let m = corners.len();
        self.parent.clear();
        self.parent.extend(0..m as u32);
        for (i, &c) in corners.iter().enumerate() {
            let c = c as usize;
            for h in [c, topo.prev_corner(c)] {
                let p = partner[h];
                if p == NONE {
                    continue;
                }
                let p = p as usize;
                let pc = if topo.corner_vertex(p) == v { p } else { topo.next_corner(p) };
                if let Ok(j) = corners.binary_search(&(pc as u32)) {
                    union(&mut self.parent, i as u32, j as u32);
                }
            }
        }
        let mut root_class = vec![NONE; m];
        let mut classes: Vec<Vec<u32>> = Vec::new();
        for i in 0..m {
            let r = find(&mut self.parent, i as u32) as usize;
            if root_class[r] == NONE {
                root_class[r] = classes.len() as u32;
                classes.push(Vec::new());
            }
            classes[root_class[r] as usize].push(i as u32);
        }
        classes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::validate::analyze;

    /// A flat square of two triangles with a fin standing on its diagonal: the diagonal has three
    /// faces. Split keeps the two flat faces glued (normals agree) and detaches the fin.
    fn fin() -> Mesh {
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 1.0]];
        Mesh::from_triangles(p, &[[0, 1, 2], [0, 2, 3], [2, 0, 4]])
    }

    #[test]
    fn split_detaches_the_fin() {
        let mut m = fin();
        let r = resolve(&mut m, NonManifoldMode::Split, &Progress::new()).unwrap();
        assert_eq!(r.non_manifold_edges_before, 1);
        assert_eq!(r.non_manifold_edges_after, 0);
        assert_eq!(r.vertices_added, 2);
        assert_eq!(r.faces_removed, 0);
        assert_eq!(m.faces.len(), 3);
        // The flat pair still shares the diagonal; the fin uses copies 5, 6 of 2 and 0.
        assert_eq!(m.faces.get(0), &[0, 1, 2]);
        assert_eq!(m.faces.get(1), &[0, 2, 3]);
        let mut fin_v = m.faces.get(2).to_vec();
        fin_v.sort();
        assert_eq!(fin_v, vec![4, 5, 6]);
        let a = analyze(&m);
        assert!(a.manifold);
        assert_eq!(a.components, 2);
    }

    #[test]
    fn remove_drops_the_fin() {
        let mut m = fin();
        let r = resolve(&mut m, NonManifoldMode::Remove, &Progress::new()).unwrap();
        assert_eq!(r.faces_removed, 1);
        assert_eq!(m.faces.len(), 2);
        assert!(analyze(&m).manifold);
    }

    /// Two tetrahedra touching at a vertex: split gives each its own vertex → two closed genus-0
    /// components.
    #[test]
    fn split_non_manifold_vertex() {
        let mut p: Vec<Point3> = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        p.extend([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]);
        // Tet A = 0,1,2,3 ; tet B = 0,4,5,6 (shares vertex 0).
        let tris = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3], [0, 4, 5], [0, 6, 4], [4, 6, 5], [5, 6, 0]];
        let mut m = Mesh::from_triangles(p, &tris);
        assert_eq!(analyze(&m).non_manifold_vertices, 1);
        let r = resolve(&mut m, NonManifoldMode::Split, &Progress::new()).unwrap();
        assert_eq!(r.vertices_split, 1);
        assert_eq!(r.vertices_added, 1);
        let a = analyze(&m);
        assert_eq!(a.non_manifold_vertices, 0);
        assert_eq!(a.components_by_vertex, 2);
        assert_eq!(a.genus, Some(0));
    }

    #[test]
    fn pinch_left_alone() {
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, -1.0, 0.0]];
        let mut m = Mesh::from_triangles(p, &[[0, 1, 2], [0, 3, 4]]);
        let before = m.clone();
        resolve(&mut m, NonManifoldMode::Split, &Progress::new()).unwrap();
        assert_eq!(m, before);
    }
}
