//! The highlight line model of a triangle mesh (seed 001 §2, Algorithm 1): area-weighted vertex
//! normals (eq. 3), the highlight distance of every vertex (eq. 1), highlight nodes on edges (eq. 4)
//! and their connection into polylines, one family per light index.
//!
//! Conventions (the seed note flags both printed slips):
//! - `d` is the *geometric* signed distance `D = (X − A₀)·(Z × H)` of the point `X` where the
//!   vertex's normal line meets the light plane. The printed eq. 1 equals `−D` (checked in the
//!   note and in our tests), so indices here count from `L₀` in the direction `Z × H`, as §2.2 says.
//! - Nodes use `m·s` (eq. 4 prints `m`, right only for `s = 1`).
//! - A vertex lying exactly on a light counts as "above" it (`d/s ≥ m`), the marching-triangles
//!   rule: every triangle is crossed by a level on exactly 0 or 2 of its edges, so the paper's
//!   special "highlight edge" cases (Fig. 2b/c) need no separate code and nodes are never doubled.
//! - `d` is undefined where the normal is parallel to the light plane (`Z·N = 0`) and jumps from
//!   +∞ to −∞ across such a curve. Vertices with `|Z·N| < MIN_NORMAL_DOT` are invalid, and edges
//!   whose ends see the plane from opposite sides (or have an invalid end) carry no nodes; edges
//!   that would carry more than `MAX_NODES_PER_EDGE` nodes are skipped too. Both are counted.

use std::collections::HashMap;

use crate::error::{Error, Location, Result};
use crate::geometry::{add, cross, dot, norm, normalize, scale, sub};
use crate::mesh::{Mesh, Point3};

/// `|Z·N|` below which a vertex's highlight distance is treated as undefined.
pub const MIN_NORMAL_DOT: f64 = 1e-3;
/// More nodes than this on one edge means `d` is exploding there (normal nearly in the plane).
pub const MAX_NODES_PER_EDGE: i64 = 64;

/// The array of coplanar, parallel, equally spaced linear lights.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Lights {
    /// Unit normal `Z` of the light plane.
    pub normal: Point3,
    /// Unit direction `H` of the lights (in the plane).
    pub direction: Point3,
    /// A point `A₀` on the base light `L₀` (in the plane).
    pub origin: Point3,
    /// Distance `s` between neighbouring lights.
    pub spacing: f64,
}

impl Lights {
    /// `W = Z × H`: the in-plane direction in which light indices grow.
    pub fn across(&self) -> Point3 {
        cross(self.normal, self.direction)
    }

    /// Highlight distance of point `p` with (any positive multiple of) normal `n`, or `None` when
    /// the normal is (nearly) parallel to the plane. Geometric sign: `D` of §2.2, i.e. −(eq. 1).
    pub fn distance(&self, p: Point3, n: Point3) -> Option<f64> {
        let nz = dot(n, self.normal);
        if nz.abs() < MIN_NORMAL_DOT * norm(n) || nz == 0.0 {
            return None;
        }
        let a = sub(p, self.origin);
        let w = self.across();
        Some(dot(a, w) - dot(a, self.normal) * dot(n, w) / nz)
    }
}

/// Triangle connectivity the model and the fairing need (built once per job).
#[derive(Debug, Clone)]
pub struct Adjacency {
    pub tris: Vec<[u32; 3]>,
    /// Edges as (lo, hi) vertex pairs.
    pub edges: Vec<[u32; 2]>,
    /// Edge `k` of triangle `t` joins corners `k` and `k + 1`.
    pub tri_edges: Vec<[u32; 3]>,
    /// Triangles per edge (1 = boundary, 2 = interior, more = non-manifold).
    pub edge_tris: Vec<Vec<u32>>,
    /// Triangles around each vertex.
    pub vert_tris: Vec<Vec<u32>>,
    /// Neighbouring vertices (sorted) and the edge to each.
    pub vert_nbrs: Vec<Vec<(u32, u32)>>,
    /// Vertices on a boundary or non-manifold edge, or used by no triangle: they have no
    /// closed one-ring, so no cotangent curvature and they never move.
    pub border: Vec<bool>,
}

impl Adjacency {
    /// Fails on faces that are not triangles (the method is defined for triangle meshes only).
    pub fn new(mesh: &Mesh) -> Result<Adjacency> {
        let n = mesh.vertex_count();
        let mut tris = Vec::with_capacity(mesh.face_count());
        for (fi, f) in mesh.faces.iter().enumerate() {
            if f.len() != 3 {
                return Err(Error::InvalidMesh {
                    location: Location::Face(fi),
                    message: format!(
                        "highlight fairing needs a triangle mesh; this face has {} vertices \
                         (triangulate first, e.g. `repair`)",
                        f.len()
                    ),
                });
            }
            tris.push([f[0], f[1], f[2]]);
        }
        let mut edge_id: HashMap<(u32, u32), u32> = HashMap::with_capacity(tris.len() * 2);
        let mut edges = Vec::new();
        let mut edge_tris: Vec<Vec<u32>> = Vec::new();
        let mut tri_edges = Vec::with_capacity(tris.len());
        let mut vert_tris = vec![Vec::new(); n];
        for (ti, t) in tris.iter().enumerate() {
            let mut te = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                let e = *edge_id.entry(key).or_insert_with(|| {
                    edges.push([key.0, key.1]);
                    edge_tris.push(Vec::new());
                    (edges.len() - 1) as u32
                });
                edge_tris[e as usize].push(ti as u32);
                te[k] = e;
                vert_tris[t[k] as usize].push(ti as u32);
            }
            tri_edges.push(te);
        }
        let mut vert_nbrs = vec![Vec::new(); n];
        let mut border = vec![false; n];
        for (e, &[a, b]) in edges.iter().enumerate() {
            vert_nbrs[a as usize].push((b, e as u32));
            vert_nbrs[b as usize].push((a, e as u32));
            if edge_tris[e].len() != 2 || a == b {
                border[a as usize] = true;
                border[b as usize] = true;
            }
        }
        for (v, nb) in vert_nbrs.iter_mut().enumerate() {
            nb.sort_unstable();
            if nb.is_empty() {
                border[v] = true;
            }
        }
        Ok(Adjacency { tris, edges, tri_edges, edge_tris, vert_tris, vert_nbrs, border })
    }

    /// Sum of the twice-area vectors of the triangles around `v` (eq. 3 before normalising: the
    /// area-weighted sum of unit face normals is exactly half of it).
    pub fn normal_sum(&self, x: &[Point3], v: usize) -> Point3 {
        let mut s = [0.0; 3];
        for &t in &self.vert_tris[v] {
            let [a, b, c] = self.tris[t as usize];
            s = add(s, cross(sub(x[b as usize], x[a as usize]), sub(x[c as usize], x[a as usize])));
        }
        s
    }

    /// Unit vertex normals of eq. 3 (zero for a vertex whose triangles cancel or are degenerate).
    pub fn normals(&self, x: &[Point3]) -> Vec<Point3> {
        (0..x.len()).map(|v| normalize(self.normal_sum(x, v))).collect()
    }
}

/// Per-vertex highlight distances (eq. 1, geometric sign), `None` where undefined.
pub fn distances(adj: &Adjacency, x: &[Point3], lights: &Lights) -> Vec<Option<f64>> {
    (0..x.len())
        .map(|v| {
            let m = adj.normal_sum(x, v);
            if norm(m) == 0.0 {
                None
            } else {
                lights.distance(x[v], m)
            }
        })
        .collect()
}

/// A highlight node: the point of edge `edge` (from its lo vertex `a` to hi vertex `b`) where
/// the interpolated highlight distance equals `m·s`.
#[derive(Debug, Clone, Copy)]
pub struct Node {
    pub edge: u32,
    pub m: i64,
    /// Position parameter from `a` (0) to `b` (1).
    pub t: f64,
    pub pos: Point3,
}

/// One highlight line: consecutive node ids, all with light index `m`.
#[derive(Debug, Clone)]
pub struct Line {
    pub m: i64,
    pub nodes: Vec<u32>,
    /// The last node connects back to the first.
    pub closed: bool,
}

/// The highlight line model (Algorithm 1 output) plus what was skipped and why.
#[derive(Debug, Clone, Default)]
pub struct Model {
    pub d: Vec<Option<f64>>,
    pub nodes: Vec<Node>,
    pub lines: Vec<Line>,
    /// Vertices whose normal is (nearly) parallel to the light plane.
    pub invalid_vertices: usize,
    /// Edges left without nodes: an invalid end, ends on opposite sides of the plane, or more than
    /// `MAX_NODES_PER_EDGE` nodes.
    pub skipped_edges: usize,
}

/// Algorithm 1: nodes per edge (eq. 4 with `m·s`), segments per triangle, chained into polylines.
pub fn model(adj: &Adjacency, x: &[Point3], lights: &Lights) -> Model {
    let d = distances(adj, x, lights);
    let s = lights.spacing;
    let sides: Vec<f64> = (0..x.len()).map(|v| dot(adj.normal_sum(x, v), lights.normal)).collect();
    // Nodes of edge e are ids first[e]..first[e+1], in increasing level.
    let mut first = Vec::with_capacity(adj.edges.len() + 1);
    let mut nodes = Vec::new();
    let mut skipped = 0;
    for (e, &[a, b]) in adj.edges.iter().enumerate() {
        first.push(nodes.len() as u32);
        let (Some(da), Some(db)) = (d[a as usize], d[b as usize]) else {
            skipped += 1;
            continue;
        };
        if sides[a as usize] * sides[b as usize] <= 0.0 {
            skipped += 1;
            continue;
        }
        let (ua, ub) = (da / s, db / s);
        // Levels beyond 2^53 are not exact integers, and near i64's range `hi - lo` and `lo + 1`
        // overflow (a spacing of 1e-300 looped for ever): such an edge has far more than
        // `MAX_NODES_PER_EDGE` nodes anyway.
        if !(ua.abs() < 9.0e15 && ub.abs() < 9.0e15) {
            skipped += 1;
            continue;
        }
        // Levels m with exactly one end "≥ m": lo < m ≤ hi.
        let (lo, hi) = (ua.min(ub).floor() as i64, ua.max(ub).floor() as i64);
        if hi - lo > MAX_NODES_PER_EDGE {
            skipped += 1;
            continue;
        }
        for m in lo + 1..=hi {
            let t = ((m as f64 - ua) / (ub - ua)).clamp(0.0, 1.0);
            let (pa, pb) = (x[a as usize], x[b as usize]);
            nodes.push(Node { edge: e as u32, m, t, pos: add(pa, scale(sub(pb, pa), t)) });
        }
    }
    first.push(nodes.len() as u32);
    // Segments: per triangle and level, the two edges holding that level.
    let mut segments: Vec<[u32; 2]> = Vec::new();
    for te in &adj.tri_edges {
        let mut levels: Vec<(i64, u32)> = Vec::new();
        for &e in te {
            for id in first[e as usize]..first[e as usize + 1] {
                levels.push((nodes[id as usize].m, id));
            }
        }
        levels.sort_unstable();
        let mut i = 0;
        while i < levels.len() {
            let mut j = i + 1;
            while j < levels.len() && levels[j].0 == levels[i].0 {
                j += 1;
            }
            // Exactly two edges hold this level unless an edge was skipped (the line ends there).
            if j - i == 2 {
                segments.push([levels[i].1, levels[i + 1].1]);
            }
            i = j;
        }
    }
    let lines = chain(nodes.len(), &segments, &nodes);
    Model {
        invalid_vertices: d.iter().filter(|v| v.is_none()).count(),
        d,
        nodes,
        lines,
        skipped_edges: skipped,
    }
}

/// Chains segments into polylines: open lines start at nodes of degree ≠ 2, the rest are loops.
fn chain(n_nodes: usize, segments: &[[u32; 2]], nodes: &[Node]) -> Vec<Line> {
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n_nodes];
    for (si, s) in segments.iter().enumerate() {
        adj[s[0] as usize].push(si as u32);
        adj[s[1] as usize].push(si as u32);
    }
    let mut used = vec![false; segments.len()];
    let other = |s: u32, n: u32| {
        if segments[s as usize][0] == n {
            segments[s as usize][1]
        } else {
            segments[s as usize][0]
        }
    };
    let mut lines = Vec::new();
    let walk = |start: u32, seg: u32, used: &mut Vec<bool>| -> Line {
        let mut path = vec![start];
        let mut cur_seg = seg;
        let mut cur = start;
        loop {
            used[cur_seg as usize] = true;
            cur = other(cur_seg, cur);
            if cur == start {
                return Line { m: nodes[start as usize].m, nodes: path, closed: true };
            }
            path.push(cur);
            if adj[cur as usize].len() != 2 {
                break;
            }
            match adj[cur as usize].iter().find(|&&s| !used[s as usize]) {
                Some(&s) => cur_seg = s,
                None => break,
            }
        }
        Line { m: nodes[start as usize].m, nodes: path, closed: false }
    };
    for n in 0..n_nodes as u32 {
        if adj[n as usize].len() != 2 {
            for k in 0..adj[n as usize].len() {
                let s = adj[n as usize][k];
                if !used[s as usize] {
                    lines.push(walk(n, s, &mut used));
                }
            }
        }
    }
    for s in 0..segments.len() as u32 {
        if !used[s as usize] {
            lines.push(walk(segments[s as usize][0], s, &mut used));
        }
    }
    lines
}

/// The lines as point lists (for the report and OBJ export).
pub fn polylines(model: &Model) -> Vec<(i64, Vec<Point3>)> {
    model
        .lines
        .iter()
        .map(|l| {
            let mut pts: Vec<Point3> = l.nodes.iter().map(|&i| model.nodes[i as usize].pos).collect();
            if l.closed {
                pts.push(pts[0]);
            }
            (l.m, pts)
        })
        .collect()
}

/// OBJ text with one `l` polyline per highlight line (`g light_<m>` groups), for viewing the
/// lines next to the mesh.
pub fn to_obj(model: &Model) -> String {
    use std::fmt::Write;
    let mut s = String::from("# highlight lines (meshwork smooth --method highlight)\n");
    let mut base = 1usize;
    for (m, pts) in polylines(model) {
        let _ = writeln!(s, "g light_{m}");
        for p in &pts {
            let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
        }
        s.push('l');
        for k in 0..pts.len() {
            let _ = write!(s, " {}", base + k);
        }
        s.push('\n');
        base += pts.len();
    }
    s
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::shapes::{grid, parallelogram_grid};

    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        }
    }

    fn flat_lights(origin: Point3, spacing: f64) -> Lights {
        Lights { normal: [0.0, 0.0, 1.0], direction: [1.0, 0.0, 0.0], origin, spacing }
    }

    #[test]
    fn distance_is_the_signed_offset_of_the_normal_lines_hit_point_and_eq1_has_the_other_sign() {
        let mut r = rng(3);
        for _ in 0..20 {
            let z = normalize([r(), r(), r() + 2.0]);
            let h = normalize(sub([r(), r(), r()], scale(z, 0.0)));
            let h = normalize(sub(h, scale(z, dot(h, z))));
            let l = Lights { normal: z, direction: h, origin: [r(), r(), r()], spacing: 1.0 };
            let p = [r(), r(), r()];
            let n = normalize([r(), r(), r() + 1.5]);
            // Explicit intersection of P + sN with the plane through A₀ with normal Z.
            let s = dot(sub(l.origin, p), z) / dot(n, z);
            let xp = add(p, scale(n, s));
            let d_geo = dot(sub(xp, l.origin), cross(z, h));
            let d = l.distance(p, n).unwrap();
            assert!((d - d_geo).abs() < 1e-9 * (1.0 + d_geo.abs()), "{d} vs {d_geo}");
            let eq1 = dot(cross(sub(p, l.origin), h), n) / dot(z, n);
            assert!((eq1 + d_geo).abs() < 1e-9 * (1.0 + d_geo.abs()), "printed eq. 1 is −D");
            // Any positive multiple of the normal gives the same value.
            assert!((l.distance(p, scale(n, 7.5)).unwrap() - d).abs() < 1e-9 * (1.0 + d.abs()));
        }
        // Normal in the plane: undefined.
        assert!(flat_lights([0.0; 3], 1.0).distance([0.0; 3], [1.0, 0.0, 0.0]).is_none());
    }

    #[test]
    fn plane_lines_are_straight_at_hand_computed_offsets() {
        // z = 0 plane, normals +z: the normal line hits the light plane above P, so d = P_y − A₀_y.
        // Lights every 0.25 from y = 0.33: lines at y = 0.08, 0.33, 0.58, 0.83 across x ∈ [0, 1].
        let m = grid(10, 10, 0.1, false);
        let adj = Adjacency::new(&m).unwrap();
        let l = flat_lights([0.0, 0.33, 5.0], 0.25);
        let md = model(&adj, &m.positions, &l);
        for (v, d) in md.d.iter().enumerate() {
            assert!((d.unwrap() - (m.positions[v][1] - 0.33)).abs() < 1e-12);
        }
        let mut ms: Vec<i64> = md.lines.iter().map(|l| l.m).collect();
        ms.sort();
        assert_eq!(ms, vec![-1, 0, 1, 2]);
        for line in &md.lines {
            assert!(!line.closed);
            let y = 0.33 + 0.25 * line.m as f64;
            let xs: Vec<f64> = line.nodes.iter().map(|&i| md.nodes[i as usize].pos[0]).collect();
            for &i in &line.nodes {
                assert!((md.nodes[i as usize].pos[1] - y).abs() < 1e-12);
            }
            let (lo, hi) = xs.iter().fold((f64::MAX, f64::MIN), |a, &x| (a.0.min(x), a.1.max(x)));
            assert!(lo.abs() < 1e-12 && (hi - 1.0).abs() < 1e-12, "line spans [{lo}, {hi}]");
            // Monotone along the line: a chain, not a zig-zag of unrelated nodes.
            let increasing = xs.windows(2).all(|w| w[1] >= w[0] - 1e-12);
            let decreasing = xs.windows(2).all(|w| w[1] <= w[0] + 1e-12);
            assert!(increasing || decreasing, "{xs:?}");
        }
    }

    #[test]
    fn lights_through_vertex_rows_give_one_line_each() {
        // Levels exactly on the vertex rows y = 0.25 j (exact binary fractions): the tie rule must
        // neither drop nor double a line.
        let m = grid(4, 4, 0.25, false);
        let adj = Adjacency::new(&m).unwrap();
        let md = model(&adj, &m.positions, &flat_lights([0.0, 0.0, 1.0], 0.25));
        let mut ms: Vec<i64> = md.lines.iter().map(|l| l.m).collect();
        ms.sort();
        assert_eq!(ms, vec![1, 2, 3, 4]);
        for line in &md.lines {
            for &i in &line.nodes {
                assert_eq!(md.nodes[i as usize].pos[1], 0.25 * line.m as f64);
            }
        }
    }

    /// Open cylinder patch of radius 1 about the x axis, φ from `phi1` down to `phi0` (outward
    /// normals), `nx × nphi` cells over x ∈ [0, len].
    pub(crate) fn cylinder(nx: usize, nphi: usize, len: f64, phi0: f64, phi1: f64) -> Mesh {
        let dphi = (phi1 - phi0) / nphi as f64;
        let mut m = parallelogram_grid(nx, nphi, [len / nx as f64, 0.0, 0.0], [0.0, dphi, 0.0], false);
        for p in &mut m.positions {
            let phi = phi1 - p[1];
            *p = [p[0], phi.cos(), phi.sin()];
        }
        m
    }

    #[test]
    fn cylinder_lines_parallel_to_the_axis_are_straight_at_hand_computed_angles() {
        // Lights in z = h along x: the normal line of (x, cos φ, sin φ) hits the plane at
        // y = h·cot φ, so d = h·cot φ and light m images at cot φ = m·s/h: straight lines parallel
        // to the axis. Nodes lie on the chords, at the linear interpolation of d.
        let (h, s) = (3.0, 0.5);
        let (phi0, phi1) = (20f64.to_radians(), 160f64.to_radians());
        let (nx, nphi) = (20, 28);
        let m = cylinder(nx, nphi, 2.0, phi0, phi1);
        let adj = Adjacency::new(&m).unwrap();
        let l = flat_lights([0.0, 0.0, h], s);
        let md = model(&adj, &m.positions, &l);
        let phi_of = |p: Point3| p[2].atan2(p[1]);
        for v in 0..m.vertex_count() {
            if !adj.border[v] {
                let want = h / phi_of(m.positions[v]).tan();
                assert!((md.d[v].unwrap() - want).abs() < 1e-12, "vertex {v}");
            }
        }
        for mm in -10i64..=10 {
            let lines: Vec<&Line> = md.lines.iter().filter(|l| l.m == mm).collect();
            assert_eq!(lines.len(), 1, "light {mm}");
            let line = lines[0];
            let phi_m = (h / (mm as f64 * s)).atan();
            let phi_m = if phi_m < 0.0 { phi_m + std::f64::consts::PI } else { phi_m };
            let mut checked = 0;
            for &i in &line.nodes {
                let nd = md.nodes[i as usize];
                let [a, b] = adj.edges[nd.edge as usize];
                let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
                if adj.border[a as usize] || adj.border[b as usize] {
                    continue;
                }
                let (fa, fb) = (phi_of(pa), phi_of(pb));
                assert!(
                    (fa.min(fb)) <= phi_m + 1e-12 && phi_m <= fa.max(fb) + 1e-12,
                    "node between its columns"
                );
                let (da, db) = (h / fa.tan(), h / fb.tan());
                let t = (mm as f64 * s - da) / (db - da);
                let want = add(pa, scale(sub(pb, pa), t));
                assert!(norm(sub(nd.pos, want)).abs() < 1e-12);
                checked += 1;
            }
            assert!(checked > nx, "light {mm}: {checked} interior nodes");
            // Straight: every node of the line has the same (y, z) (up to the border columns).
            let yz: Vec<[f64; 2]> = line
                .nodes
                .iter()
                .filter(|&&i| {
                    let [a, b] = adj.edges[md.nodes[i as usize].edge as usize];
                    !adj.border[a as usize] && !adj.border[b as usize]
                })
                .map(|&i| [md.nodes[i as usize].pos[1], md.nodes[i as usize].pos[2]])
                .collect();
            for p in &yz {
                assert!((p[0] - yz[0][0]).abs() < 1e-12 && (p[1] - yz[0][1]).abs() < 1e-12);
            }
        }
        assert!(md.invalid_vertices == 0 && md.skipped_edges == 0);
    }

    #[test]
    fn edges_where_the_normal_crosses_the_plane_carry_no_nodes() {
        // Full half-turn of the cylinder with a horizontal light plane: normals pass through
        // horizontal at φ = 0 and π: d is undefined there and the side flips; no line may join the
        // two sides (no node on a side-flipping edge).
        let m = cylinder(4, 36, 1.0, -40f64.to_radians(), 220f64.to_radians());
        let adj = Adjacency::new(&m).unwrap();
        let md = model(&adj, &m.positions, &flat_lights([0.0, 0.0, 3.0], 0.5));
        assert!(md.skipped_edges > 0);
        for nd in &md.nodes {
            let [a, b] = adj.edges[nd.edge as usize];
            let za = adj.normal_sum(&m.positions, a as usize)[2];
            let zb = adj.normal_sum(&m.positions, b as usize)[2];
            assert!(za * zb > 0.0);
        }
    }

    #[test]
    fn quads_are_refused_with_the_face_named() {
        let m = grid(2, 2, 1.0, true);
        match Adjacency::new(&m) {
            Err(Error::InvalidMesh { location: Location::Face(0), message }) => {
                assert!(message.contains("triangle"), "{message}")
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn obj_export_has_one_polyline_per_line() {
        let m = grid(10, 10, 0.1, false);
        let adj = Adjacency::new(&m).unwrap();
        let md = model(&adj, &m.positions, &flat_lights([0.0, 0.33, 5.0], 0.25));
        let obj = to_obj(&md);
        assert_eq!(obj.lines().filter(|l| l.starts_with("l ")).count(), 4);
        assert_eq!(
            obj.lines().filter(|l| l.starts_with("v ")).count(),
            md.lines.iter().map(|l| l.nodes.len()).sum::<usize>()
        );
    }
}
