//! Re-triangulating a folded neighbourhood among fixed vertices in its own plane.
//!
//! Where no flip sequence of [`super::flip_search`] reaches an unfolded state (a fold whose
//! corners are curve or chain points, several faces deep), the neighbourhood's faces are replaced
//! by a new triangulation of the same vertices: the same boundary loop (so nothing outside
//! changes), every interior vertex used, every locked (curve) edge kept, no vertex moved. It is
//! made in the plane of the neighbourhood's mean normal, where "turned the right way" means
//! counter-clockwise:
//! 1. the constrained edges (the loop and the locked edges) are taken, then every other pair of
//!    vertices by increasing length whenever the segment lies inside the loop and crosses no
//!    edge taken (a greedy triangulation: every maximal set of non-crossing diagonals is one);
//! 2. its triangles are the mutually joined triples empty of other vertices;
//! 3. Lawson flips of the unconstrained edges make it Delaunay (the fattest faces among
//!    triangulations with those constraints).
//!
//! Only done where the projection is faithful: the loop projects to a simple counter-clockwise
//! polygon, every interior vertex inside it, no two constrained edges crossing. Anything else
//! (a patch that is not a disk, a loop that overlaps itself in the plane) gives None.

use std::collections::HashSet;

use crate::geometry::{add, dot, norm2, normalize, scale};
use crate::mesh::Point3;

use super::super::trimesh::TriMesh;
use super::{Ctx, RingFrame};

/// Every vertex's normal must be within this cosine of the patch's mean normal: 0 accepts any
/// vertex not turned beyond perpendicular (the faithfulness checks below decide; 0.7 rejected
/// most of the patches the last repair meets on the deformed sets, session 24).
const MIN_PLANE_COS: f64 = 0.0;

/// Orientation tests count as zero within this fraction of the patch's size squared.
const EPS_REL: f64 = 1e-12;

/// Lawson passes at most (each flips every non-Delaunay edge it finds).
const MAX_DELAUNAY_PASSES: usize = 20;

/// The new faces for the disk `faces` (corner ids of `mesh`), or None when it is not a disk or
/// its projection is not faithful (see the module doc).
pub(super) fn retriangulate(mesh: &TriMesh, ctx: &Ctx, faces: &[[u32; 3]]) -> Option<Vec<[u32; 3]>> {
    let ring = boundary_loop(faces)?;
    let verts = patch_vertices(faces, &ring);
    let interior = verts.len() - ring.len();
    let expected = ring.len() + 2 * interior - 2;
    // Euler: a triangulated disk with these vertices has exactly this many faces (anything else
    // has a handle or a hole the loop does not show).
    if faces.len() != expected {
        return None;
    }
    let plane = Plane::project(mesh, ctx, &verts)?;
    // Local ids: `verts` starts with the loop, so the loop is local 0..n in order.
    let n = ring.len();
    let loop_local: Vec<usize> = (0..n).collect();
    plane.check_loop(&loop_local)?;
    if (n..verts.len()).any(|i| !plane.strictly_inside(&loop_local, plane.pts[i])) {
        return None;
    }
    let local = |v: u32| verts.iter().position(|&w| w == v);
    let on_loop = |i: usize, j: usize| i < n && j < n && (j == (i + 1) % n || i == (j + 1) % n);
    let patch_edges: HashSet<(u32, u32)> = faces.iter().flat_map(|t| edges_of(*t)).collect();
    let mut fixed: Vec<(usize, usize)> = (0..n).map(|k| (k, (k + 1) % n)).collect();
    let mut sorted_edges: Vec<(u32, u32)> = patch_edges.iter().copied().collect();
    sorted_edges.sort_unstable();
    for &(a, b) in &sorted_edges {
        let (Some(i), Some(j)) = (local(a), local(b)) else { return None };
        if ctx.locked(a, b) && !on_loop(i, j) {
            if !plane.admissible(&loop_local, &fixed, i, j) {
                return None;
            }
            fixed.push((i, j));
        }
    }
    // An edge joining two patch vertices outside the patch must not be made inside it too.
    let outside = |i: usize, j: usize| {
        let (a, b) = (verts[i], verts[j]);
        mesh.has_edge(a, b) && !patch_edges.contains(&(a.min(b), a.max(b)))
    };
    let n_fixed = fixed.len();
    let mut edges = fixed;
    plane.greedy_edges(&loop_local, &mut edges, &outside);
    let mut tris = plane.triangles(&loop_local, &edges);
    if tris.len() != expected {
        return None;
    }
    let constrained: HashSet<(usize, usize)> =
        edges[..n_fixed].iter().map(|&(i, j)| (i.min(j), i.max(j))).collect();
    plane.delaunay_flips(&mut tris, &constrained, &outside);
    Some(tris.iter().map(|t| [verts[t[0]], verts[t[1]], verts[t[2]]]).collect())
}

/// The undirected edges of a triangle, each as (smaller id, larger id).
fn edges_of(t: [u32; 3]) -> [(u32, u32); 3] {
    std::array::from_fn(|k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])))
}

/// The boundary of `faces` as one loop in the faces' direction, or None when a directed edge is
/// used twice or the boundary is not a single loop through distinct vertices.
fn boundary_loop(faces: &[[u32; 3]]) -> Option<Vec<u32>> {
    let mut directed: HashSet<(u32, u32)> = HashSet::new();
    for t in faces {
        for k in 0..3 {
            if !directed.insert((t[k], t[(k + 1) % 3])) {
                return None;
            }
        }
    }
    let mut next: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    let mut start = None;
    for &(a, b) in &directed {
        if !directed.contains(&(b, a)) {
            if next.insert(a, b).is_some() {
                return None; // the boundary passes twice through a
            }
            start = Some(start.map_or(a, |s: u32| s.min(a)));
        }
    }
    let start = start?;
    let mut ring = vec![start];
    let mut v = *next.get(&start)?;
    while v != start {
        if ring.len() > next.len() {
            return None;
        }
        ring.push(v);
        v = *next.get(&v)?;
    }
    (ring.len() == next.len() && ring.len() >= 3).then_some(ring)
}

/// The loop's vertices in order, then the interior ones in order of first appearance.
fn patch_vertices(faces: &[[u32; 3]], ring: &[u32]) -> Vec<u32> {
    let mut verts = ring.to_vec();
    for t in faces {
        for &v in t {
            if !verts.contains(&v) {
                verts.push(v);
            }
        }
    }
    verts
}

/// The patch's vertices projected on the plane through their centroid, normal to their mean
/// normal; `pts[i]` is local vertex `i`.
struct Plane {
    pts: Vec<[f64; 2]>,
    eps: f64,
}

impl Plane {
    fn project(mesh: &TriMesh, ctx: &Ctx, verts: &[u32]) -> Option<Plane> {
        let normals: Vec<Point3> = verts.iter().map(|&v| ctx.normal_at(mesh, v)).collect();
        let n = normalize(normals.iter().fold([0.0; 3], |s, &m| add(s, m)));
        if norm2(n) == 0.0 || normals.iter().any(|&m| dot(m, n) <= MIN_PLANE_COS) {
            return None;
        }
        let centroid = scale(
            verts.iter().fold([0.0; 3], |s, &v| add(s, mesh.pos[v as usize])),
            1.0 / verts.len() as f64,
        );
        let frame = RingFrame::at(centroid, n)?;
        let pts: Vec<[f64; 2]> = verts.iter().map(|&v| frame.flat(mesh.pos[v as usize])).collect();
        let size2 = pts.iter().map(|&p| norm2_2(p)).fold(0.0, f64::max);
        (size2 > 0.0).then_some(Plane { pts, eps: EPS_REL * size2 })
    }

    /// Twice the signed area of (a, b, c): positive when counter-clockwise.
    fn orient(&self, a: usize, b: usize, c: usize) -> f64 {
        orient2(self.pts[a], self.pts[b], self.pts[c])
    }

    /// Whether closed segments a–b and c–d meet anywhere (crossing, touching or overlapping),
    /// for segments with no shared end.
    fn meet(&self, a: usize, b: usize, c: usize, d: usize) -> bool {
        let (p, q, r, s) = (self.pts[a], self.pts[b], self.pts[c], self.pts[d]);
        let sign = |x: f64| {
            if x > self.eps {
                1
            } else if x < -self.eps {
                -1
            } else {
                0
            }
        };
        let (o1, o2) = (sign(orient2(p, q, r)), sign(orient2(p, q, s)));
        let (o3, o4) = (sign(orient2(r, s, p)), sign(orient2(r, s, q)));
        if o1 * o2 < 0 && o3 * o4 < 0 {
            return true;
        }
        (o1 == 0 && within(p, q, r))
            || (o2 == 0 && within(p, q, s))
            || (o3 == 0 && within(r, s, p))
            || (o4 == 0 && within(r, s, q))
    }

    /// Whether vertex `v` lies on segment a–b (other than at its ends).
    fn on_segment(&self, a: usize, b: usize, v: usize) -> bool {
        v != a
            && v != b
            && self.orient(a, b, v).abs() <= self.eps
            && within(self.pts[a], self.pts[b], self.pts[v])
    }

    /// Even-odd rule, with points on the loop (within the tolerance) counted outside.
    fn strictly_inside(&self, ring: &[usize], p: [f64; 2]) -> bool {
        let mut inside = false;
        for k in 0..ring.len() {
            let (a, b) = (self.pts[ring[k]], self.pts[ring[(k + 1) % ring.len()]]);
            if orient2(a, b, p).abs() <= self.eps && within(a, b, p) {
                return false;
            }
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > p[0] {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// The loop must run counter-clockwise and be simple: no two edges meet except neighbours at
    /// their shared vertex, and no neighbours fold back along each other.
    fn check_loop(&self, ring: &[usize]) -> Option<()> {
        let n = ring.len();
        let area2: f64 = (0..n)
            .map(|k| {
                let (a, b) = (self.pts[ring[k]], self.pts[ring[(k + 1) % n]]);
                a[0] * b[1] - a[1] * b[0]
            })
            .sum();
        if area2 <= self.eps {
            return None;
        }
        for k in 0..n {
            let (a, b, c) = (ring[k], ring[(k + 1) % n], ring[(k + 2) % n]);
            let (pa, pb, pc) = (self.pts[a], self.pts[b], self.pts[c]);
            let back = dot2(sub2(pa, pb), sub2(pc, pb)) > 0.0;
            if self.orient(a, b, c).abs() <= self.eps && back {
                return None;
            }
            for l in k + 2..n {
                if (l + 1) % n == k {
                    continue; // the edge before k's: neighbours
                }
                if self.meet(a, b, ring[l], ring[(l + 1) % n]) {
                    return None;
                }
            }
        }
        Some(())
    }

    /// Whether segment i–j can be an edge given the edges taken: through no vertex, inside the
    /// loop, crossing no taken edge without a shared end.
    fn admissible(&self, ring: &[usize], taken: &[(usize, usize)], i: usize, j: usize) -> bool {
        if (0..self.pts.len()).any(|v| self.on_segment(i, j, v)) {
            return false;
        }
        let mid = [(self.pts[i][0] + self.pts[j][0]) / 2.0, (self.pts[i][1] + self.pts[j][1]) / 2.0];
        if !self.strictly_inside(ring, mid) {
            return false;
        }
        taken.iter().all(|&(a, b)| a == i || a == j || b == i || b == j || !self.meet(i, j, a, b))
    }

    /// Adds to `edges` (the constrained ones) every admissible pair, shortest first, skipping
    /// pairs `outside` refuses.
    fn greedy_edges(
        &self,
        ring: &[usize],
        edges: &mut Vec<(usize, usize)>,
        outside: &dyn Fn(usize, usize) -> bool,
    ) {
        let n = self.pts.len();
        let mut cand: Vec<(f64, usize, usize)> = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                if edges.iter().any(|&(a, b)| (a, b) == (i, j) || (a, b) == (j, i)) {
                    continue;
                }
                cand.push((norm2_2(sub2(self.pts[i], self.pts[j])), i, j));
            }
        }
        cand.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (_, i, j) in cand {
            if !outside(i, j) && self.admissible(ring, edges, i, j) {
                edges.push((i, j));
            }
        }
    }

    /// The counter-clockwise triangles of mutually joined triples with no vertex inside or on
    /// them and their centroid inside the loop.
    fn triangles(&self, ring: &[usize], edges: &[(usize, usize)]) -> Vec<[usize; 3]> {
        let n = self.pts.len();
        let mut adj = vec![vec![false; n]; n];
        for &(a, b) in edges {
            adj[a][b] = true;
            adj[b][a] = true;
        }
        let mut out = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                if !adj[i][j] {
                    continue;
                }
                for k in j + 1..n {
                    if !adj[i][k] || !adj[j][k] {
                        continue;
                    }
                    let t = if self.orient(i, j, k) > 0.0 { [i, j, k] } else { [i, k, j] };
                    if self.orient(t[0], t[1], t[2]) <= self.eps || !self.empty(t) {
                        continue;
                    }
                    let c = [
                        (self.pts[i][0] + self.pts[j][0] + self.pts[k][0]) / 3.0,
                        (self.pts[i][1] + self.pts[j][1] + self.pts[k][1]) / 3.0,
                    ];
                    if self.strictly_inside(ring, c) {
                        out.push(t);
                    }
                }
            }
        }
        out
    }

    /// No other vertex inside counter-clockwise triangle `t` or on its sides.
    fn empty(&self, t: [usize; 3]) -> bool {
        (0..self.pts.len())
            .filter(|v| !t.contains(v))
            .all(|v| (0..3).any(|k| self.orient(t[k], t[(k + 1) % 3], v) < -self.eps))
    }

    /// Whether `d` lies strictly inside the circumcircle of counter-clockwise (a, b, c).
    fn in_circle(&self, a: usize, b: usize, c: usize, d: usize) -> bool {
        let p = self.pts[d];
        let rows: Vec<[f64; 3]> = [a, b, c]
            .iter()
            .map(|&v| {
                let q = sub2(self.pts[v], p);
                [q[0], q[1], norm2_2(q)]
            })
            .collect();
        let det = rows[0][0] * (rows[1][1] * rows[2][2] - rows[1][2] * rows[2][1])
            - rows[0][1] * (rows[1][0] * rows[2][2] - rows[1][2] * rows[2][0])
            + rows[0][2] * (rows[1][0] * rows[2][1] - rows[1][1] * rows[2][0]);
        // The determinant has units of length⁴: the tolerance is eps · size².
        det > self.eps * self.eps / EPS_REL
    }

    /// Lawson flips: every unconstrained edge whose opposite vertex lies inside the other face's
    /// circumcircle is flipped (when the quad is convex and the new edge is not already an edge
    /// outside), until none is left or [`MAX_DELAUNAY_PASSES`].
    fn delaunay_flips(
        &self,
        tris: &mut [[usize; 3]],
        constrained: &HashSet<(usize, usize)>,
        outside: &dyn Fn(usize, usize) -> bool,
    ) {
        for _ in 0..MAX_DELAUNAY_PASSES {
            let mut flipped = false;
            for x in 0..tris.len() {
                for k in 0..3 {
                    let t = tris[x];
                    let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                    if constrained.contains(&(a.min(b), a.max(b))) {
                        continue;
                    }
                    let Some(y) = tris.iter().position(|s| (0..3).any(|m| s[m] == b && s[(m + 1) % 3] == a))
                    else {
                        continue;
                    };
                    let Some(&d) = tris[y].iter().find(|&&v| v != a && v != b) else { continue };
                    if !self.in_circle(a, b, c, d) || outside(c, d) {
                        continue;
                    }
                    let (n1, n2) = ([c, a, d], [d, b, c]);
                    if self.orient(n1[0], n1[1], n1[2]) <= self.eps
                        || self.orient(n2[0], n2[1], n2[2]) <= self.eps
                    {
                        continue;
                    }
                    tris[x] = n1;
                    tris[y] = n2;
                    flipped = true;
                    break;
                }
            }
            if !flipped {
                break;
            }
        }
    }
}

fn orient2(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn sub2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn dot2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn norm2_2(a: [f64; 2]) -> f64 {
    dot2(a, a)
}

/// Whether p, known to be on the line through a and b, lies within the segment's extent.
fn within(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> bool {
    let t = dot2(sub2(p, a), sub2(b, a));
    t >= 0.0 && t <= norm2_2(sub2(b, a))
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::flip_search::tests::collinear_overlap;
    use super::super::EdgeSet;
    use super::*;
    use crate::geometry::triangle_cross;

    /// A 4 × 4 vertex grid of unit squares in z = 0 (vertex (i, j) is 4j + i), each square split
    /// along its rising diagonal, faces counter-clockwise seen from +z.
    pub(crate) fn grid() -> (Vec<Point3>, Vec<[u32; 3]>) {
        let pos = (0..16).map(|v| [(v % 4) as f64, (v / 4) as f64, 0.0]).collect();
        let mut tris = Vec::new();
        for j in 0..3u32 {
            for i in 0..3u32 {
                let a = 4 * j + i;
                tris.push([a, a + 1, a + 5]);
                tris.push([a, a + 5, a + 4]);
            }
        }
        (pos, tris)
    }

    /// The re-triangulation of all of `tris`, reference +z at every vertex.
    fn run(pos: &[Point3], tris: &[[u32; 3]], locked: &[(u32, u32)]) -> Option<Vec<[u32; 3]>> {
        let mesh = TriMesh::new(pos.to_vec(), tris.to_vec()).unwrap();
        let reference = vec![[0.0, 0.0, 1.0]; pos.len()];
        let fixed = vec![true; pos.len()];
        let locked: EdgeSet = locked.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
        let ctx = Ctx { reference: &reference, fixed: &fixed, locked: &locked };
        retriangulate(&mesh, &ctx, tris)
    }

    /// z of each face's normal, by a cross product here, and the summed area.
    fn up_and_area(pos: &[Point3], tris: &[[u32; 3]]) -> (bool, f64) {
        let z: Vec<f64> = tris
            .iter()
            .map(|t| triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize])[2])
            .collect();
        (z.iter().all(|&z| z > 1e-9), z.iter().sum::<f64>() / 2.0)
    }

    fn has(tris: &[[u32; 3]], a: u32, b: u32) -> bool {
        tris.iter().any(|t| t.contains(&a) && t.contains(&b))
    }

    #[test]
    fn a_grid_with_two_inner_points_swapped_is_unfolded_through_every_vertex() {
        let (mut pos, tris) = grid();
        pos.swap(5, 10);
        assert!(!up_and_area(&pos, &tris).0, "the swap folds faces");
        let out = run(&pos, &tris, &[]).expect("a faithful disk");
        // 12 loop vertices and 4 inside: 12 + 2·4 − 2 = 18 faces, all up, covering the 3 × 3
        // square exactly once (area 9), every vertex used.
        assert_eq!(out.len(), 18);
        let (up, area) = up_and_area(&pos, &out);
        assert!(up, "{out:?}");
        assert!((area - 9.0).abs() < 1e-12, "{area}");
        for v in 0..16 {
            assert!(out.iter().any(|t| t.contains(&v)), "vertex {v} dropped");
        }
    }

    #[test]
    fn locked_edges_stay_and_the_rest_is_delaunay() {
        let (mut pos, tris) = grid();
        pos.swap(5, 10);
        // (4,5): (0,1)–(2,2) after the swap; (6,10): (2,1)–(1,1). Both are edges of the grid.
        let out = run(&pos, &tris, &[(4, 5), (6, 10)]).expect("a faithful disk");
        let (up, area) = up_and_area(&pos, &out);
        assert!(up && (area - 9.0).abs() < 1e-12, "{out:?}");
        assert!(has(&out, 4, 5) && has(&out, 6, 10));
        // Every other interior edge: the far vertex of the face across lies on or outside the
        // circumcircle of the face (centre and radius computed here from the perpendicular
        // bisectors).
        let p = |v: u32| pos[v as usize];
        for t in &out {
            for k in 0..3 {
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                if [(4, 5), (6, 10)].contains(&(a.min(b), a.max(b))) {
                    continue;
                }
                let Some(s) = out.iter().find(|s| s.contains(&a) && s.contains(&b) && !s.contains(&c)) else {
                    continue;
                };
                let d = *s.iter().find(|&&v| v != a && v != b).unwrap();
                let (ax, ay, bx, by, cx, cy) = (p(a)[0], p(a)[1], p(b)[0], p(b)[1], p(c)[0], p(c)[1]);
                let den = 2.0 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by));
                let ux = ((ax * ax + ay * ay) * (by - cy)
                    + (bx * bx + by * by) * (cy - ay)
                    + (cx * cx + cy * cy) * (ay - by))
                    / den;
                let uy = ((ax * ax + ay * ay) * (cx - bx)
                    + (bx * bx + by * by) * (ax - cx)
                    + (cx * cx + cy * cy) * (bx - ax))
                    / den;
                let r2 = (ax - ux).powi(2) + (ay - uy).powi(2);
                let d2 = (p(d)[0] - ux).powi(2) + (p(d)[1] - uy).powi(2);
                assert!(d2 >= r2 - 1e-9, "edge {a}-{b}: {d} inside the circle of {t:?}");
            }
        }
    }

    #[test]
    fn three_collinear_fixed_points_get_no_face_along_their_line() {
        let (pos, tris) = collinear_overlap();
        let out = run(&pos, &tris, &[(0, 1), (2, 6)]).expect("a faithful disk");
        assert_eq!(out.len(), 10);
        let (up, area) = up_and_area(&pos, &out);
        assert!(up, "{out:?}");
        assert!((area - 8.8).abs() < 1e-12, "{area}");
        assert!(has(&out, 0, 1) && has(&out, 2, 6));
        assert!(!has(&out, 0, 2), "edge 0–2 passes through vertex 1");
    }

    #[test]
    fn no_triangulation_when_a_point_is_outside_or_chain_edges_cross() {
        let (pos, tris) = grid();
        let mut out_of_loop = pos.clone();
        out_of_loop[5] = [-1.0, 1.5, 0.0];
        assert!(run(&out_of_loop, &tris, &[]).is_none());
        // 5 ↔ 6 swapped: the locked (5,9) runs (2,1)–(1,2), the locked (6,10) runs (1,1)–(2,2);
        // they cross at (1.5, 1.5).
        let mut crossed = pos;
        crossed.swap(5, 6);
        assert!(run(&crossed, &tris, &[(5, 9), (6, 10)]).is_none());
    }

    #[test]
    fn a_boundary_turned_clockwise_in_the_plane_is_refused() {
        let (mut pos, tris) = grid();
        for p in &mut pos {
            p[0] = -p[0];
        }
        assert!(run(&pos, &tris, &[]).is_none());
    }
}
