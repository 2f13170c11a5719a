//! Zero-area faces in the finished mesh: removed by an edge flip or an edge collapse where one
//! keeps the faces around valid, counted and named (where, why) otherwise.
//!
//! How they arise: three vertices end up on one line, most often a vertex lying on a straight
//! curve segment (a split or snapped chain vertex, or a smoothed vertex pinned between two fixed
//! ones) with a face spanning the segment's two ends; or a face far smaller than the mesh (split
//! points kept a fixed fraction off an edge's end, split again and again near one vertex: faces of
//! 1e-7 of the diagonal, below single-precision round-off, measured in the rocker-arm template
//! fitted to homer's sections). Every earlier stage measures folds against a normal, and a
//! zero-area face has none, so it passes them unseen. Remedies, in order:
//! - the "cap" (vertex c inside the opposite edge a–b): flip a–b; the two new faces split the
//!   neighbour across a–b at c, both with the neighbour's orientation;
//! - a short edge (a needle, or a tiny face): collapse it, moving a free vertex onto its
//!   neighbour (both positions are within the face's size, so the surface is unchanged at the
//!   mesh's precision). A chain vertex that is no curve point may be collapsed along its chain
//!   onto its chain neighbour (the chain loses a vertex a face's size from the next one); curve
//!   points and boundary vertices never move.
//!
//! Faces neither can fix (e.g. two curve points at one place, a cap on a curve edge whose corners
//! are all fixed) stay; the report counts them and names where they are and why.

use serde::Serialize;

use crate::geometry::{add, dot, norm, sub, triangle_cross, Aabb};
use crate::mesh::Point3;

use super::trimesh::{EdgeSet, TriMesh};

/// What [`remove_zero_area`] did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct DegenerateStats {
    /// Zero-area faces before the pass.
    pub before: usize,
    /// Edge flips that removed one.
    pub flips: usize,
    /// Edge collapses that removed one (each removes a vertex and the faces on its edge).
    pub collapses: usize,
    /// Zero-area faces left (in the output; goal 0).
    pub after: usize,
    /// The faces left (the first [`NAMED`]): where and why no fix applied.
    pub left: Vec<LeftFace>,
    /// Vertices the collapses removed (in no face now): the caller drops them from the output.
    #[serde(skip)]
    pub removed_vertices: Vec<u32>,
}

/// A zero-area face the pass could not remove.
#[derive(Debug, Clone, Serialize)]
pub struct LeftFace {
    /// The face's centroid.
    pub at: Point3,
    /// Its longest edge over its shortest (infinite: two corners at one place).
    pub longest_over_shortest: f64,
    pub why: &'static str,
}

/// The most faces named in [`DegenerateStats::left`].
const NAMED: usize = 20;

/// |cross| ≤ this × (longest edge)²: the largest angle is within ~1e-10 rad of 180° (or an edge
/// is ~1e-10 of the longest): no normal can be trusted.
const FLAT: f64 = 1e-10;

/// |cross| ≤ this × (mesh diagonal)²: the face is below single-precision round-off of the mesh's
/// coordinates (edges ~1e-7 of the diagonal), so it has no area in an f32 output (STL, glTF).
const TINY: f64 = 1e-14;

/// Passes over the faces left (a fix can expose a neighbour's).
const PASSES: usize = 4;

/// True when the face's area is zero relative to its size.
pub fn is_zero_area(a: Point3, b: Point3, c: Point3) -> bool {
    let l2 = [sub(b, a), sub(c, b), sub(a, c)].iter().map(|e| dot(*e, *e)).fold(0.0, f64::max);
    norm(triangle_cross(a, b, c)) <= FLAT * l2
}

/// Which vertices may move and which edges must stay.
pub struct Constraints<'a> {
    /// Curve points and boundary vertices: never moved.
    pub fixed: &'a [bool],
    /// Vertices on a chain (curve points and vertices added to chains).
    pub on_chain: &'a [bool],
    /// Chain edges; a collapse along one updates the set (the chain's next edge joins the
    /// vertex it was collapsed onto).
    pub curve_edges: &'a mut EdgeSet,
}

impl Constraints<'_> {
    fn fixed(&self, v: u32) -> bool {
        self.fixed.get(v as usize).copied().unwrap_or(true)
    }
    fn on_chain(&self, v: u32) -> bool {
        self.on_chain.get(v as usize).copied().unwrap_or(true)
    }
    fn locked(&self, a: u32, b: u32) -> bool {
        self.curve_edges.contains(&(a.min(b), a.max(b)))
    }
    /// The chain edges at `v`.
    fn chain_edges_at(&self, mesh: &TriMesh, v: u32) -> Vec<u32> {
        let mut nb: Vec<u32> = mesh.faces_of(v).iter().flat_map(|&f| mesh.tris[f as usize]).collect();
        nb.sort_unstable();
        nb.dedup();
        nb.into_iter().filter(|&w| w != v && self.locked(v, w)).collect()
    }
    /// May `q` move onto its neighbour `p`: a free vertex, or a chain vertex that is no curve
    /// point moving along its chain (p–q a chain edge, q inside one chain).
    fn may_collapse(&self, mesh: &TriMesh, q: u32, p: u32) -> bool {
        if self.fixed(q) {
            return false;
        }
        if !self.on_chain(q) {
            return !self.locked(p, q);
        }
        self.locked(p, q) && self.chain_edges_at(mesh, q).len() == 2
    }
}

/// A collapse moves a vertex by the edge's length: at most this fraction of the face's longest
/// edge (a needle's short edge; a cap's vertex well inside its long edge is flipped, not moved)...
const SHORT: f64 = 0.01;
/// ...or of the mesh diagonal (a face far below the mesh's size, whatever its shape).
const NEGLIGIBLE: f64 = 1e-5;

/// Zero-area test of the pass: flat for its size, or tiny for the mesh.
struct Test {
    tiny: f64,
    diag: f64,
}

impl Test {
    fn degenerate(&self, a: Point3, b: Point3, c: Point3) -> bool {
        is_zero_area(a, b, c) || norm(triangle_cross(a, b, c)) <= self.tiny
    }
    fn face(&self, mesh: &TriMesh, f: u32) -> bool {
        let t = mesh.tris[f as usize];
        self.degenerate(mesh.pos[t[0] as usize], mesh.pos[t[1] as usize], mesh.pos[t[2] as usize])
    }
}

/// Flips or collapses away every zero-area face it can; curve points and boundary vertices never
/// move, chain edges are never flipped. Face ids change only for the faces edited.
pub fn remove_zero_area(mesh: &mut TriMesh, c: &mut Constraints) -> DegenerateStats {
    let diag = Aabb::of(&mesh.pos).map_or(0.0, |b| b.diagonal());
    let test = Test { tiny: TINY * diag * diag, diag };
    let zero = |m: &TriMesh| -> Vec<u32> { m.alive_faces().filter(|&f| test.face(m, f)).collect() };
    let mut found = zero(mesh);
    let mut stats = DegenerateStats { before: found.len(), ..Default::default() };
    for _ in 0..PASSES {
        let mut changed = false;
        for &f in &found {
            // A face an earlier fix replaced is gone (ids are never reused).
            if !mesh.alive[f as usize] || !test.face(mesh, f) {
                continue;
            }
            if flip_longest(mesh, f, c.curve_edges, &test) {
                stats.flips += 1;
                changed = true;
            } else if let Some(q) = collapse_shortest(mesh, f, c, &test) {
                stats.collapses += 1;
                stats.removed_vertices.push(q);
                changed = true;
            }
        }
        found = zero(mesh);
        if !changed || found.is_empty() {
            break;
        }
    }
    stats.after = found.len();
    stats.left = found.iter().take(NAMED).map(|&f| name_left(mesh, f, c)).collect();
    stats
}

/// Where a face left is and why nothing applied.
fn name_left(mesh: &TriMesh, f: u32, c: &Constraints) -> LeftFace {
    let t = mesh.tris[f as usize];
    let p = t.map(|v| mesh.pos[v as usize]);
    let at = add(add(p[0], p[1]), p[2]).map(|x| x / 3.0);
    let lens: Vec<f64> = (0..3).map(|k| mesh.len(t[k], t[(k + 1) % 3])).collect();
    let longest = lens.iter().copied().fold(0.0, f64::max);
    let shortest = lens.iter().copied().fold(f64::INFINITY, f64::min);
    let longest_over_shortest = if shortest > 0.0 { longest / shortest } else { f64::INFINITY };
    let why = if t.iter().all(|&v| c.fixed(v)) {
        "every corner is a curve point or on the boundary"
    } else if t.iter().all(|&v| c.on_chain(v)) {
        "every corner is on a chain and no collapse along a chain is valid"
    } else {
        "no edge flip or collapse leaves the faces around valid"
    };
    LeftFace { at, longest_over_shortest, why }
}

/// Flips the edge opposite the vertex that lies inside it (the longest edge) of face `f`.
fn flip_longest(mesh: &mut TriMesh, f: u32, curve_edges: &EdgeSet, test: &Test) -> bool {
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
        !test.degenerate(p(x), p(y), p(z)) && dot(n, ng) > 0.0
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

/// Collapses the shortest edge of face `f` that may be collapsed (one end moved onto the other);
/// the vertex removed.
fn collapse_shortest(mesh: &mut TriMesh, f: u32, c: &mut Constraints, test: &Test) -> Option<u32> {
    let t = mesh.tris[f as usize];
    let mut edges: Vec<(u32, u32)> = (0..3).map(|k| (t[k], t[(k + 1) % 3])).collect();
    edges.sort_by(|x, y| mesh.len(x.0, x.1).total_cmp(&mesh.len(y.0, y.1)));
    let longest = mesh.len(edges[2].0, edges[2].1);
    let short = (SHORT * longest).max(NEGLIGIBLE * test.diag);
    for (a, b) in edges {
        if mesh.len(a, b) > short {
            break;
        }
        for (q, p) in [(b, a), (a, b)] {
            if !c.may_collapse(mesh, q, p) {
                continue;
            }
            let chain_nb = c.chain_edges_at(mesh, q);
            if collapse(mesh, q, p, test) {
                // q was inside one chain p–q–w: the chain now runs p–w.
                for w in chain_nb {
                    c.curve_edges.remove(&(q.min(w), q.max(w)));
                    if w != p {
                        c.curve_edges.insert((p.min(w), p.max(w)));
                    }
                }
                return Some(q);
            }
        }
    }
    None
}

/// The vertices sharing a face with `v`.
fn neighbours(mesh: &TriMesh, v: u32) -> Vec<u32> {
    let mut nb: Vec<u32> =
        mesh.faces_of(v).iter().flat_map(|&f| mesh.tris[f as usize]).filter(|&w| w != v).collect();
    nb.sort_unstable();
    nb.dedup();
    nb
}

/// Moves `q` onto `p` (q's faces re-pointed to p, the faces on edge p–q removed) when that keeps
/// the mesh manifold (the link condition: p and q share no neighbour but the third corners of
/// the faces on their edge), turns no face over and makes no zero-area face. `q` is then in no
/// face.
fn collapse(mesh: &mut TriMesh, q: u32, p: u32, test: &Test) -> bool {
    let star: Vec<u32> = mesh.faces_of(q).to_vec();
    let (on_edge, moved): (Vec<u32>, Vec<u32>) =
        star.iter().partition(|&&f| mesh.tris[f as usize].contains(&p));
    if on_edge.is_empty() {
        return false;
    }
    let mut opposite: Vec<u32> = on_edge
        .iter()
        .filter_map(|&f| mesh.tris[f as usize].iter().copied().find(|&v| v != p && v != q))
        .collect();
    opposite.sort_unstable();
    let nq = neighbours(mesh, q);
    let common: Vec<u32> = neighbours(mesh, p).into_iter().filter(|v| nq.binary_search(v).is_ok()).collect();
    if common != opposite {
        return false;
    }
    // An edge p–q with a face on one side only is a boundary edge; q then is on the boundary and
    // fixed, so both sides are here. The faces that stay must keep their side and have area.
    let pp = mesh.pos[p as usize];
    let at = |v: u32| if v == q { pp } else { mesh.pos[v as usize] };
    // The star's own orientation, for faces that were zero-area themselves (no normal of their own).
    let star_normal = star.iter().fold([0.0; 3], |n, &f| add(n, mesh.face_normal(f)));
    let valid = moved.iter().all(|&f| {
        let t = mesh.tris[f as usize];
        let [a, b, c] = t.map(at);
        let n1 = triangle_cross(a, b, c);
        let n0 = if test.face(mesh, f) { star_normal } else { mesh.face_normal(f) };
        !test.degenerate(a, b, c) && dot(n0, n1) > 0.0
    });
    if !valid {
        return false;
    }
    let old: Vec<[u32; 3]> = moved.iter().map(|&f| mesh.tris[f as usize]).collect();
    let removed: Vec<[u32; 3]> = star.iter().map(|&f| mesh.tris[f as usize]).collect();
    for &f in &star {
        mesh.remove_face(f);
    }
    let mut added = Vec::with_capacity(old.len());
    for t in &old {
        match mesh.add_face(t.map(|v| if v == q { p } else { v })) {
            Ok(g) => added.push(g),
            Err(()) => {
                // A directed edge taken twice (cannot happen under the link condition): undone.
                for g in added {
                    mesh.remove_face(g);
                }
                for t in &removed {
                    let _ = mesh.add_face(*t);
                }
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the pass with `fixed` vertices and `chain` edges (their ends on a chain).
    fn run(m: &mut TriMesh, fixed: &[u32], chain: &[(u32, u32)]) -> (DegenerateStats, EdgeSet) {
        let n = m.pos.len();
        let mut is_fixed = vec![false; n];
        for &v in fixed {
            is_fixed[v as usize] = true;
        }
        let mut on_chain = is_fixed.clone();
        let mut edges = EdgeSet::default();
        for &(a, b) in chain {
            on_chain[a as usize] = true;
            on_chain[b as usize] = true;
            edges.insert((a.min(b), a.max(b)));
        }
        let mut c = Constraints { fixed: &is_fixed, on_chain: &on_chain, curve_edges: &mut edges };
        let s = remove_zero_area(m, &mut c);
        (s, edges)
    }

    /// Every live face has area (by the plain cross product, not the code's test) and faces +z.
    fn all_up(m: &TriMesh) -> bool {
        m.alive_faces().all(|f| m.face_normal(f)[2] > 1e-20)
    }

    #[test]
    fn a_cap_face_is_flipped_away() {
        // Square a(0,0) b(2,0) d(1,-1) and c(1,0) on a–b: faces (a,b,c) flat, (b,a,d) fine,
        // plus (a,c,e), (c,b,e) above so c is a real vertex.
        let pos = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]];
        let (a, b, c, d, e) = (0, 1, 2, 3, 4);
        let tris = vec![[a, b, c], [b, a, d], [a, c, e], [c, b, e]];
        let mut m = TriMesh::new(pos, tris).unwrap();
        let (s, _) = run(&mut m, &[], &[]);
        assert_eq!((s.before, s.flips, s.collapses, s.after), (1, 1, 0, 0));
        assert_eq!(m.live_triangles().len(), 4);
        assert!(all_up(&m));
    }

    #[test]
    fn a_cap_on_a_curve_edge_is_not_flipped_nor_collapsed_and_is_named() {
        // The same cap with a–b a curve edge: no flip; c is free but half the edge from either
        // end, so a collapse would move the surface: the face stays, named at its centroid (1, 0).
        let pos = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]];
        let tris = vec![[0, 1, 2], [1, 0, 3], [0, 2, 4], [2, 1, 4]];
        let mut m = TriMesh::new(pos.clone(), tris.clone()).unwrap();
        let (s, _) = run(&mut m, &[0, 1], &[(0, 1)]);
        assert_eq!((s.before, s.flips, s.collapses, s.after), (1, 0, 0, 1));
        assert_eq!(s.left.len(), 1);
        assert!(crate::geometry::dist(s.left[0].at, [1.0, 0.0, 0.0]) < 1e-12, "{:?}", s.left);
        assert_eq!((m.live_triangles(), m.pos), (tris, pos));
    }

    /// Square a(0,0) b(2,0) c(2,2) d(0,2) with v(1,1) and q 1e-12 to its right: the two faces on
    /// edge v–q are needles of zero area (cross 1e-12, hand value), the vertex inside at an end.
    fn needle_fan() -> TriMesh {
        let pos = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0 + 1e-12, 1.0, 0.0],
        ];
        let (a, b, c, d, v, q) = (0, 1, 2, 3, 4, 5);
        let tris = vec![[a, b, q], [b, c, q], [c, d, v], [d, a, v], [a, q, v], [c, v, q]];
        TriMesh::new(pos, tris).unwrap()
    }

    #[test]
    fn a_needle_is_collapsed_onto_its_short_edge() {
        // No flip can help (the inner vertex is at an end of the long edge): one of v, q (both
        // free) moves onto the other, the two needles go, 4 faces with area remain and the
        // vertex removed is in none; the other keeps its place.
        let mut m = needle_fan();
        let pos = m.pos.clone();
        let (s, _) = run(&mut m, &[0, 1, 2, 3], &[]);
        assert_eq!((s.before, s.flips, s.collapses, s.after), (2, 0, 1, 0));
        let gone = s.removed_vertices[0];
        assert!(s.removed_vertices.len() == 1 && (gone == 4 || gone == 5), "{:?}", s.removed_vertices);
        assert!(m.faces_of(gone).is_empty());
        assert_eq!(m.live_triangles().len(), 4);
        assert!(all_up(&m));
        assert_eq!(m.pos, pos);
    }

    #[test]
    fn a_curve_point_never_moves_the_free_end_does() {
        // q a curve point: v (free) moves onto it instead; both curve points: nothing moves and
        // both needles are named.
        let mut m = needle_fan();
        let (s, _) = run(&mut m, &[0, 1, 2, 3, 5], &[]);
        assert_eq!((s.collapses, s.after, s.removed_vertices.clone()), (1, 0, vec![4]));
        assert_eq!(m.pos[5], [1.0 + 1e-12, 1.0, 0.0]);
        assert!(all_up(&m));
        let mut m = needle_fan();
        let pos = m.pos.clone();
        let (s, _) = run(&mut m, &[0, 1, 2, 3, 4, 5], &[]);
        assert_eq!((s.before, s.collapses, s.after, s.left.len()), (2, 0, 2, 2));
        assert_eq!(m.pos, pos);
    }

    #[test]
    fn a_chain_vertex_collapses_along_its_chain_and_the_chain_joins() {
        // Chain a → v → q → c with a, v, c curve points and q a chain vertex: q moves onto v along
        // the chain edge v–q, and the chain's edges become a–v, v–c.
        let mut m = needle_fan();
        let (s, edges) = run(&mut m, &[0, 1, 2, 3, 4], &[(0, 4), (4, 5), (5, 2)]);
        assert_eq!((s.collapses, s.after), (1, 0));
        let mut e: Vec<(u32, u32)> = edges.into_iter().collect();
        e.sort_unstable();
        assert_eq!(e, vec![(0, 4), (2, 4)]);
        assert!(m.has_edge(2, 4));
    }

    #[test]
    fn a_tiny_well_shaped_face_is_found_and_collapsed() {
        // In the square of side 2, the triangle v(1,1) q(1+δ,1) r(1+δ/2,1+0.8δ), δ = 1e-8: not
        // flat (angles 58°–64°) but its area 4e-17 is below single precision for a mesh of
        // diagonal 2.8. The old relative test did not see it at all.
        let dl = 1e-8;
        let pos = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0 + dl, 1.0, 0.0],
            [1.0 + dl / 2.0, 1.0 + 0.8 * dl, 0.0],
        ];
        let (a, b, c, d, v, q, r) = (0, 1, 2, 3, 4, 5, 6);
        let tris =
            vec![[v, q, r], [a, b, q], [a, q, v], [b, c, r], [b, r, q], [c, d, r], [d, a, v], [d, v, r]];
        let mut m = TriMesh::new(pos, tris).unwrap();
        assert!(!is_zero_area(m.pos[4], m.pos[5], m.pos[6]));
        let (s, _) = run(&mut m, &[0, 1, 2, 3], &[]);
        assert_eq!((s.before, s.collapses, s.after), (1, 1, 0));
        assert_eq!(m.live_triangles().len(), 6);
        assert!(all_up(&m));
    }
}
