//! Zero-area faces in the finished mesh: removed where an edge flip can do it, counted otherwise.
//!
//! How they arise: three vertices end up on one line, most often a vertex lying on a straight
//! curve segment (a split or snapped chain vertex, or a smoothed vertex pinned between two fixed
//! ones) with a face spanning the segment's two ends. Every earlier stage measures folds against
//! a normal, and a zero-area face has none, so it passes them unseen (measured: 3 such faces in the
//! icosphere fitted to spot's sections). The remedy for that "cap" shape, the vertex c inside the
//! opposite edge a–b, is to flip a–b: the two new faces split the neighbour across a–b at c, both
//! with the neighbour's orientation. Faces it cannot fix (a curve or boundary edge opposite,
//! two coincident vertices) stay and are counted in the report.

use serde::Serialize;

use crate::geometry::{dot, norm, sub, triangle_cross};
use crate::mesh::Point3;

use super::trimesh::{EdgeSet, TriMesh};

/// What [`remove_zero_area`] did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct DegenerateStats {
    /// Zero-area faces before the pass.
    pub before: usize,
    /// Edge flips that removed one.
    pub flips: usize,
    /// Zero-area faces left (in the output; goal 0).
    pub after: usize,
}

/// |cross| ≤ this × (longest edge)²: the largest angle is within ~1e-10 rad of 180° (or an edge
/// is ~1e-10 of the longest): no normal can be trusted.
const FLAT: f64 = 1e-10;

/// True when the face's area is zero relative to its size.
pub fn is_zero_area(a: Point3, b: Point3, c: Point3) -> bool {
    let l2 = [sub(b, a), sub(c, b), sub(a, c)].iter().map(|e| dot(*e, *e)).fold(0.0, f64::max);
    norm(triangle_cross(a, b, c)) <= FLAT * l2
}

/// Flips the longest edge of every zero-area face where that makes two faces with area; curve
/// edges and boundary edges are never flipped. Face ids change only for flipped faces.
pub fn remove_zero_area(mesh: &mut TriMesh, curve_edges: &EdgeSet) -> DegenerateStats {
    let zero = |m: &TriMesh| -> Vec<u32> {
        m.alive_faces()
            .filter(|&f| {
                let t = m.tris[f as usize];
                is_zero_area(m.pos[t[0] as usize], m.pos[t[1] as usize], m.pos[t[2] as usize])
            })
            .collect()
    };
    let found = zero(mesh);
    let mut stats = DegenerateStats { before: found.len(), ..Default::default() };
    for f in found {
        // A face an earlier flip replaced is gone (ids are never reused).
        if mesh.alive[f as usize] && flip_longest(mesh, f, curve_edges) {
            stats.flips += 1;
        }
    }
    stats.after = zero(mesh).len();
    stats
}

/// Flips the edge opposite the vertex that lies inside it (the longest edge) of face `f`.
fn flip_longest(mesh: &mut TriMesh, f: u32, curve_edges: &EdgeSet) -> bool {
    let t = mesh.tris[f as usize];
    let p = |v: u32| mesh.pos[v as usize];
    // k: the longest edge is t[k] → t[k+1]; c = t[k+2] is the vertex on it.
    let k = (0..3)
        .max_by(|&i, &j| mesh.len(t[i], t[(i + 1) % 3]).total_cmp(&mesh.len(t[j], t[(j + 1) % 3])))
        .unwrap_or(0);
    let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
    if curve_edges.contains(&(a.min(b), a.max(b))) {
        return false;
    }
    // c must lie strictly inside a–b (not on an end: that is two coincident vertices).
    let ab = sub(p(b), p(a));
    let s = dot(sub(p(c), p(a)), ab) / dot(ab, ab).max(f64::MIN_POSITIVE);
    if !(1e-6..=1.0 - 1e-6).contains(&s) {
        return false;
    }
    // The neighbour across a–b has the directed edge b → a; d is its third vertex.
    let Some(g) = mesh.face_with_edge(b, a) else { return false };
    let tg = mesh.tris[g as usize];
    let Some(&d) = tg.iter().find(|&&v| v != a && v != b) else { return false };
    if d == c || mesh.has_edge(c, d) {
        return false;
    }
    let ng = triangle_cross(p(b), p(a), p(d));
    let new = [[c, a, d], [c, d, b]];
    let ok = new.iter().all(|&[x, y, z]| {
        let n = triangle_cross(p(x), p(y), p(z));
        !is_zero_area(p(x), p(y), p(z)) && dot(n, ng) > 0.0
    });
    if !ok {
        return false;
    }
    mesh.remove_face(f);
    mesh.remove_face(g);
    // The directed edges c→a, a→d, d→c, c→d, d→b, b→c are free: a→d and d→b were g's, c→a and
    // b→c were f's (both removed), and no edge c–d exists.
    new.iter().all(|&t| mesh.add_face(t).is_ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cap_face_is_flipped_away() {
        // Square a(0,0) b(2,0) d(1,-1) and c(1,0) on a–b: faces (a,b,c) flat, (b,a,d) fine,
        // plus (a,c,e), (c,b,e) above so c is a real vertex.
        let pos = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]];
        let (a, b, c, d, e) = (0, 1, 2, 3, 4);
        let tris = vec![[a, b, c], [b, a, d], [a, c, e], [c, b, e]];
        let mut m = TriMesh::new(pos, tris).unwrap();
        let s = remove_zero_area(&mut m, &EdgeSet::default());
        assert_eq!((s.before, s.flips, s.after), (1, 1, 0));
        let live = m.live_triangles();
        assert_eq!(live.len(), 4);
        // Every face has area and faces +z, like the template.
        for t in live {
            let n = triangle_cross(m.pos[t[0] as usize], m.pos[t[1] as usize], m.pos[t[2] as usize]);
            assert!(n[2] > 0.5, "{t:?} {n:?}");
        }
    }

    #[test]
    fn a_curve_edge_is_not_flipped_and_the_face_is_counted() {
        let pos = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]];
        let tris = vec![[0, 1, 2], [1, 0, 3], [0, 2, 4], [2, 1, 4]];
        let mut m = TriMesh::new(pos, tris).unwrap();
        let mut locked = EdgeSet::default();
        locked.insert((0, 1));
        let s = remove_zero_area(&mut m, &locked);
        assert_eq!((s.before, s.flips, s.after), (1, 0, 1));
    }
}
