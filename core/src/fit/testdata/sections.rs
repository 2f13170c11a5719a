//! Plane sections of meshes and of the ellipsoid, with the truths that go with them: the regions the
//! planes cut a surface into, the sweep's frame (unit box) and planes, a known smooth map (`bend`),
//! a coarser copy of a network and user-like pairs at its crossings.

use std::collections::HashMap;

use crate::geometry::{add, dot, scale, sub, Aabb};
use crate::mesh::{Mesh, Point3};
use crate::shapes::fan_triangles;

/// The three principal-plane sections of the ellipsoid x²/a² + y²/b² + z²/c² = 1, each sampled at
/// `per_quadrant` points per quarter so that the six axis points are shared: 6 feature points of
/// degree 4, 12 arcs, 8 regions (the octants).
pub fn ellipsoid_sections(axes: [f64; 3], per_quadrant: usize) -> Mesh {
    let mut positions: Vec<Point3> = Vec::new();
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut id = |p: Point3, positions: &mut Vec<Point3>| -> u32 {
        let key = [(p[0] * 1e9).round() as i64, (p[1] * 1e9).round() as i64, (p[2] * 1e9).round() as i64];
        *index.entry(key).or_insert_with(|| {
            positions.push(p);
            (positions.len() - 1) as u32
        })
    };
    let mut curves = Vec::new();
    for (i, j) in [(0usize, 1usize), (1, 2), (2, 0)] {
        let n = 4 * per_quadrant;
        let mut line = Vec::with_capacity(n + 1);
        for k in 0..=n {
            let th = std::f64::consts::TAU * k as f64 / n as f64;
            // Exact zeros at the quadrant points so the shared vertices coincide.
            let (c, s) = match k % per_quadrant {
                0 => [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][(k / per_quadrant) % 4],
                _ => (th.cos(), th.sin()),
            };
            let mut p = [0.0; 3];
            p[i] = axes[i] * c;
            p[j] = axes[j] * s;
            line.push(id(p, &mut positions));
        }
        curves.push(line);
    }
    Mesh { positions, curves, ..Default::default() }
}

/// Approximate distance of `p` to the ellipsoid (first-order: |F| / |∇F| with
/// F = Σ (x_k / a_k)² − 1), accurate for points near the surface.
pub fn ellipsoid_distance(p: Point3, axes: [f64; 3]) -> f64 {
    let f: f64 = (0..3).map(|k| (p[k] / axes[k]).powi(2)).sum::<f64>() - 1.0;
    let g = [2.0 * p[0] / axes[0].powi(2), 2.0 * p[1] / axes[1].powi(2), 2.0 * p[2] / axes[2].powi(2)];
    f.abs() / dot(g, g).sqrt().max(1e-300)
}

/// Sections of a triangle mesh by planes `dot(normal, x) = offset`, returned as a curve network of
/// two-point lines whose vertices are shared where polylines meet: each section point lies on a
/// mesh edge; where two sections cross inside a triangle, the crossing point is inserted in both.
/// Apply a map to the positions afterwards (e.g. a known deformation) to move the curves with it.
pub fn plane_sections(mesh: &Mesh, planes: &[(Point3, f64)]) -> Mesh {
    let tris = crate::shapes::fan_triangles(&mesh.faces);
    let pos = &mesh.positions;
    let mut positions: Vec<Point3> = Vec::new();
    let mut edge_point: HashMap<(usize, u32, u32), u32> = HashMap::new();
    let mut curves: Vec<Vec<u32>> = Vec::new();
    let side = |pl: usize, v: u32| dot(planes[pl].0, pos[v as usize]) - planes[pl].1;
    for t in &tris {
        // The section segment of each plane through this triangle.
        let mut segs: Vec<(usize, [u32; 2], [Point3; 2])> = Vec::new();
        for pl in 0..planes.len() {
            let mut ends = Vec::new();
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (sa, sb) = (side(pl, a), side(pl, b));
                if (sa >= 0.0) != (sb >= 0.0) {
                    let key = (pl, a.min(b), a.max(b));
                    let lam = sa / (sa - sb);
                    let p = add(pos[a as usize], scale(sub(pos[b as usize], pos[a as usize]), lam));
                    let id = *edge_point.entry(key).or_insert_with(|| {
                        positions.push(p);
                        (positions.len() - 1) as u32
                    });
                    ends.push((id, p));
                }
            }
            if ends.len() == 2 {
                segs.push((pl, [ends[0].0, ends[1].0], [ends[0].1, ends[1].1]));
            }
        }
        // Crossings of two sections inside this triangle split both segments.
        let mut splits: Vec<Vec<(f64, u32)>> = vec![Vec::new(); segs.len()];
        for i in 0..segs.len() {
            for j in i + 1..segs.len() {
                let (pi, pj) = (segs[i].2, segs[j].2);
                let (pl_j, pl_i) = (segs[j].0, segs[i].0);
                let s0 = dot(planes[pl_j].0, pi[0]) - planes[pl_j].1;
                let s1 = dot(planes[pl_j].0, pi[1]) - planes[pl_j].1;
                if (s0 >= 0.0) == (s1 >= 0.0) {
                    continue;
                }
                let lam = s0 / (s0 - s1);
                let x = add(pi[0], scale(sub(pi[1], pi[0]), lam));
                let r0 = dot(planes[pl_i].0, pj[0]) - planes[pl_i].1;
                let r1 = dot(planes[pl_i].0, pj[1]) - planes[pl_i].1;
                if (r0 >= 0.0) == (r1 >= 0.0) {
                    continue;
                }
                let mu = r0 / (r0 - r1);
                positions.push(x);
                let id = (positions.len() - 1) as u32;
                splits[i].push((lam, id));
                splits[j].push((mu, id));
            }
        }
        for (k, (_, ends, _)) in segs.iter().enumerate() {
            let mut pts = vec![(0.0, ends[0])];
            pts.extend(splits[k].iter().copied());
            pts.push((1.0, ends[1]));
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            for w in pts.windows(2) {
                curves.push(vec![w[0].1, w[1].1]);
            }
        }
    }
    Mesh { positions, curves, ..Default::default() }
}

/// A smooth, non-affine, orientation-preserving deformation used to make targets with a known
/// truth: an anisotropic scale, a bend about the y axis and a shift.
pub fn bend(p: Point3, size: f64) -> Point3 {
    let (x, y, z) = (p[0] / size, p[1] / size, p[2] / size);
    [
        size * (1.1 * x + 0.08 * y * y),
        size * (0.95 * y + 0.05 * (2.0 * x).sin()),
        size * (1.05 * z + 0.06 * x * x),
    ]
}

/// A smooth, orientation-preserving twist for targets with a known truth (the unit box's centre
/// fixed): 0.7 rad per unit length about the x axis, with the scale 1.2 × 0.85 × 0.85. Unlike
/// [`bend`] it turns the ends of a unit-box shape 0.35 rad each way, so closest points of an
/// aligned template fall beside their true place.
pub fn twist(p: Point3) -> Point3 {
    let (x, y, z) = (p[0] - 0.5, p[1] - 0.5, p[2] - 0.5);
    let a = 0.7 * x;
    let (c, s) = (a.cos(), a.sin());
    [0.5 + 1.2 * x, 0.5 + 0.85 * (c * y - s * z), 0.5 + 0.85 * (s * y + c * z)]
}

/// Keeps every `k`-th vertex along the runs between network nodes (vertices whose degree is not
/// 2, kept always), returning polylines node to node. Used to make a section network coarser than
/// the template it is fitted with.
pub fn thin_network(curves: &Mesh, k: usize) -> Mesh {
    let k = k.max(1);
    let mut adj: HashMap<u32, Vec<u32>> = HashMap::new();
    for c in &curves.curves {
        for w in c.windows(2) {
            if w[0] != w[1] {
                adj.entry(w[0]).or_default().push(w[1]);
                adj.entry(w[1]).or_default().push(w[0]);
            }
        }
    }
    let is_node = |v: u32| adj.get(&v).map_or(true, |n| n.len() != 2);
    let mut used: std::collections::HashSet<(u32, u32)> = std::collections::HashSet::new();
    let mut lines: Vec<Vec<u32>> = Vec::new();
    let mut starts: Vec<u32> = adj.keys().copied().filter(|&v| is_node(v)).collect();
    starts.sort();
    // Closed loops without any node: start anywhere on them afterwards.
    let mut rest: Vec<u32> = adj.keys().copied().filter(|&v| !is_node(v)).collect();
    rest.sort();
    for s in starts.into_iter().chain(rest) {
        for &first in adj[&s].clone().iter() {
            if used.contains(&(s.min(first), s.max(first))) {
                continue;
            }
            let mut run = vec![s];
            let (mut prev, mut cur) = (s, first);
            used.insert((s.min(first), s.max(first)));
            loop {
                run.push(cur);
                if is_node(cur) || cur == s {
                    break;
                }
                let Some(&next) =
                    adj[&cur].iter().find(|&&n| n != prev && !used.contains(&(cur.min(n), cur.max(n))))
                else {
                    break;
                };
                used.insert((cur.min(next), cur.max(next)));
                (prev, cur) = (cur, next);
            }
            let last = run.len() - 1;
            let kept: Vec<u32> =
                run.iter().enumerate().filter(|(i, _)| i % k == 0 || *i == last).map(|(_, &v)| v).collect();
            lines.push(kept);
        }
    }
    Mesh { positions: curves.positions.clone(), curves: lines, ..Default::default() }
}

/// Pairs as a user would pick them on a section network: at up to `count` crossing points
/// (curve vertices used by ≥ 4 two-point lines, i.e. where sections meet), the template vertex
/// nearest to the crossing on the *undeformed* surface ↔ the crossing moved by `map`. The vertex is
/// taken on the piece of the template under the crossing (the piece of its closest face): a user
/// clicks the surface the crossing lies on, not a vertex of another piece that happens to be nearer
/// (suzanne's eyes under crossings on its head; the nearest vertex overall sent them there). A
/// crossing whose vertex another crossing already took is skipped: a user does not pin one vertex to
/// two points (the fit rejects that), so two crossings inside one coarse face give one pair.
pub fn crossing_pairs(
    curves: &Mesh,
    template: &Mesh,
    count: usize,
    map: impl Fn(Point3) -> Point3,
) -> Vec<crate::fit::FitPair> {
    let mut degree: HashMap<u32, usize> = HashMap::new();
    for c in &curves.curves {
        for &v in c {
            *degree.entry(v).or_default() += 1;
        }
    }
    let mut crossings: Vec<u32> = degree.iter().filter(|(_, &d)| d >= 4).map(|(&v, _)| v).collect();
    crossings.sort();
    let step = (crossings.len() / count.max(1)).max(1);
    let tris = fan_triangles(&template.faces);
    let piece = crate::fit::insert::walk::face_components(template.positions.len(), &tris);
    let mut vertex_piece = vec![None; template.positions.len()];
    for (t, p) in tris.iter().zip(&piece) {
        for &v in t {
            vertex_piece[v as usize] = Some(*p);
        }
    }
    let bvh = crate::spatial::Bvh::new(&template.positions, &crate::mesh::Faces::from_triangles(&tris));
    let d2 = |v: usize, p: Point3| {
        let d = sub(template.positions[v], p);
        dot(d, d)
    };
    let mut used = std::collections::HashSet::new();
    crossings
        .iter()
        .step_by(step)
        .take(count)
        .filter_map(|&c| {
            let p = curves.positions[c as usize];
            let on = bvh.closest(p).map(|c| piece[c.face as usize]);
            let v = (0..template.positions.len())
                .filter(|&v| on.is_none_or(|k| vertex_piece[v] == Some(k)))
                .min_by(|&a, &b| d2(a, p).total_cmp(&d2(b, p)))?;
            used.insert(v).then(|| crate::fit::FitPair { template_vertex: v as u32, curve_point: map(p) })
        })
        .collect()
}

/// Regions a set of planes cuts a surface into (the truth for section networks), counted exactly
/// ([`super::exact_plane_regions`]; until session 18 it was [`plane_regions`] on a 4×-subdivided
/// copy, which moved by up to 7 with the subdivision level on the shared meshes).
pub fn section_regions(m: &Mesh, planes: &[(Point3, f64)]) -> usize {
    super::exact_plane_regions(m, planes)
}

/// Regions of `fine` minus the planes: faces grouped by the side of every plane, connected through
/// shared edges; faces cut by a plane are left out (so `fine` must be much finer than the regions).
pub fn plane_regions(fine: &Mesh, planes: &[(Point3, f64)]) -> usize {
    let tris = fan_triangles(&fine.faces);
    let side = |p: Point3| {
        planes.iter().enumerate().fold(0u32, |c, (k, (n, o))| c | (((dot(*n, p) - o) > 0.0) as u32) << k)
    };
    let code: Vec<Option<u32>> = tris
        .iter()
        .map(|t| {
            let c: Vec<u32> = t.iter().map(|&v| side(fine.positions[v as usize])).collect();
            (c[0] == c[1] && c[1] == c[2]).then_some(c[0])
        })
        .collect();
    let mut edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edge.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut seen = vec![false; tris.len()];
    let mut count = 0;
    for s in 0..tris.len() {
        if seen[s] || code[s].is_none() {
            continue;
        }
        count += 1;
        let mut stack = vec![s];
        seen[s] = true;
        while let Some(f) = stack.pop() {
            let t = tris[f];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                for &g in &edge[&(a.min(b), a.max(b))] {
                    if !seen[g] && code[g] == code[f] {
                        seen[g] = true;
                        stack.push(g);
                    }
                }
            }
        }
    }
    count
}

/// Vertices on the boundary of `m` (on an edge used by one face).
pub fn boundary_vertices(m: &Mesh) -> Vec<bool> {
    let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
    for f in m.faces.iter() {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut on = vec![false; m.positions.len()];
    for (&(a, b), &n) in &uses {
        if n == 1 {
            on[a as usize] = true;
            on[b as usize] = true;
        }
    }
    on
}

/// Moves and scales `m` so its bounding box has its min corner at 0 and its longest side 1 (the fit
/// sweep's frame, so plane offsets and tolerances mean the same on every mesh).
pub fn to_unit_box(m: &mut Mesh) {
    let Some(bb) = Aabb::of(&m.positions) else { return };
    let side = (0..3).map(|k| bb.max[k] - bb.min[k]).fold(0.0, f64::max);
    if side <= 0.0 {
        return;
    }
    for p in &mut m.positions {
        for k in 0..3 {
            p[k] = (p[k] - bb.min[k]) / side;
        }
    }
}

/// The fit sweep's planes: four sections across the longest axis and one along each other axis, at
/// offsets off round fractions so no plane passes through a vertex of a scaled mesh by accident.
/// Empty for a mesh without vertices.
pub fn sweep_planes(m: &Mesh) -> Vec<(Point3, f64)> {
    let Some(bb) = Aabb::of(&m.positions) else { return Vec::new() };
    let ext: Vec<f64> = (0..3).map(|k| bb.max[k] - bb.min[k]).collect();
    let long = (0..3).max_by(|&a, &b| ext[a].total_cmp(&ext[b])).unwrap_or(0);
    let axis = |k: usize| {
        let mut n = [0.0; 3];
        n[k] = 1.0;
        n
    };
    let mut p: Vec<(Point3, f64)> =
        [0.2513, 0.4017, 0.5521, 0.7019].iter().map(|f| (axis(long), bb.min[long] + f * ext[long])).collect();
    for k in (0..3).filter(|&k| k != long) {
        p.push((axis(k), bb.min[k] + 0.4987 * ext[k]));
    }
    p
}

/// A real mesh as the sweeps cut it: `raw` repaired (holes left open) and moved into the unit box,
/// the sweep's planes cut through the repaired mesh, and the raw mesh carried into the same frame
/// (scaled and shifted like the repaired one, its own defects kept). Returns (the sections, the
/// raw mesh in that frame, the regions the planes cut the repaired surface into).
pub fn sections_of_repaired(raw: Mesh) -> crate::error::Result<(Mesh, Mesh, usize)> {
    let params = crate::repair::RepairParams { fill_holes: false, ..Default::default() };
    let mut fixed = crate::repair::run(raw.clone(), &params, &crate::Progress::new())?.meshes.remove(0);
    let bb = Aabb::of(&fixed.positions)
        .ok_or_else(|| crate::error::Error::params("mesh", "the repaired mesh has no vertices"))?;
    let side = (0..3).map(|k| bb.max[k] - bb.min[k]).fold(0.0, f64::max);
    let mut raw_unit = raw;
    for p in &mut raw_unit.positions {
        for k in 0..3 {
            p[k] = (p[k] - bb.min[k]) / side;
        }
    }
    to_unit_box(&mut fixed);
    let planes = sweep_planes(&fixed);
    let expected = section_regions(&fixed, &planes);
    Ok((plane_sections(&fixed, &planes), raw_unit, expected))
}

#[cfg(test)]
mod crossing_pair_tests {
    use super::*;
    use crate::shapes::icosphere;

    /// A coarse unit icosahedron and, just under the middle of one of its faces, a small fine
    /// sphere (a second piece). The crossing sits at that face's centre, far from the face's own
    /// corners but 0.02 from the small sphere: its pair must take a corner of the face it lies on.
    #[test]
    fn a_crossing_is_paired_with_a_vertex_of_the_piece_it_lies_on() {
        let mut t = icosphere(0, 1.0);
        let f: Vec<u32> = t.faces.get(0).to_vec();
        let k: [Point3; 3] = [0, 1, 2].map(|i| t.positions[f[i] as usize]);
        let c = scale(add(add(k[0], k[1]), k[2]), 1.0 / 3.0);
        let n = scale(c, 1.0 / dot(c, c).sqrt());
        let small = icosphere(3, 0.05);
        let base = t.positions.len() as u32;
        // The small sphere's top is 0.02 under the crossing, on the inside.
        let centre = sub(c, scale(n, 0.07));
        t.positions.extend(small.positions.iter().map(|&p| add(centre, p)));
        for i in 0..small.faces.len() {
            let g: Vec<u32> = small.faces.get(i).iter().map(|&v| v + base).collect();
            t.faces.push(&g, 0);
        }
        let (u, w) = (sub(k[1], k[0]), sub(k[2], k[0]));
        let curves = Mesh {
            positions: vec![
                c,
                add(c, scale(u, 0.1)),
                sub(c, scale(u, 0.1)),
                add(c, scale(w, 0.1)),
                sub(c, scale(w, 0.1)),
            ],
            curves: vec![vec![0, 1], vec![0, 2], vec![0, 3], vec![0, 4]],
            ..Default::default()
        };
        let pairs = crossing_pairs(&curves, &t, 12, |p| p);
        assert_eq!(pairs.len(), 1);
        let v = pairs[0].template_vertex;
        // The nearest vertex overall is on the small sphere (≤ 0.03 away, the corners ~0.5).
        let d2 = |v: u32| crate::geometry::dist(t.positions[v as usize], c);
        let nearest = (0..t.positions.len() as u32).min_by(|&a, &b| d2(a).total_cmp(&d2(b))).unwrap();
        assert!(nearest >= base, "the set-up must put another piece nearest");
        assert!(f.contains(&v), "paired with vertex {v}, not a corner {f:?} of the face under the crossing");
    }

    /// Two crossings close together on a coarse icosahedron's face share their nearest corner: the
    /// second is skipped (one pair, not two pairs on one vertex, which the fit rejects).
    #[test]
    fn two_crossings_nearest_one_vertex_give_one_pair() {
        let t = icosphere(0, 1.0);
        let f: Vec<u32> = t.faces.get(0).to_vec();
        let corner = t.positions[f[0] as usize];
        let towards = t.positions[f[1] as usize];
        // Two crossings 5 % and 10 % of the way from corner 0 to corner 1: both nearest corner 0.
        let a = add(corner, scale(sub(towards, corner), 0.05));
        let b = add(corner, scale(sub(towards, corner), 0.10));
        let arm = scale(sub(t.positions[f[2] as usize], corner), 0.01);
        let mut positions = vec![a, b];
        let mut curves = Vec::new();
        for (c, p) in [(0u32, a), (1u32, b)] {
            for s in [1.0, -1.0, 2.0, -2.0] {
                positions.push(add(p, scale(arm, s)));
                curves.push(vec![c, positions.len() as u32 - 1]);
            }
        }
        let net = Mesh { positions, curves, ..Default::default() };
        let pairs = crossing_pairs(&net, &t, 12, |p| p);
        assert_eq!(pairs.len(), 1, "{:?}", pairs.iter().map(|p| p.template_vertex).collect::<Vec<_>>());
        assert_eq!(pairs[0].template_vertex, f[0]);
    }
}
