//! Curve networks with a known truth, for the fit tests and the benchmark: they are built from
//! analytic surfaces or exact plane sections, never from the code under test.

use std::collections::HashMap;

use crate::geometry::{add, dot, norm, scale, sub, Aabb};
use crate::mesh::{Faces, Mesh, Point3};
use crate::shapes::{fan_triangles, icosphere, subdivide_midpoint};

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
/// nearest to the crossing on the *undeformed* surface ↔ the crossing moved by `map`.
pub fn crossing_pairs(
    curves: &Mesh,
    template: &Mesh,
    count: usize,
    map: impl Fn(Point3) -> Point3,
) -> Vec<super::FitPair> {
    let mut degree: HashMap<u32, usize> = HashMap::new();
    for c in &curves.curves {
        for &v in c {
            *degree.entry(v).or_default() += 1;
        }
    }
    let mut crossings: Vec<u32> = degree.iter().filter(|(_, &d)| d >= 4).map(|(&v, _)| v).collect();
    crossings.sort();
    let step = (crossings.len() / count.max(1)).max(1);
    let tree = super::kdtree::KdTree::new(&template.positions);
    crossings
        .iter()
        .step_by(step)
        .take(count)
        .filter_map(|&c| {
            let p = curves.positions[c as usize];
            let (v, _) = tree.nearest(p)?;
            Some(super::FitPair { template_vertex: v, curve_point: map(p) })
        })
        .collect()
}

/// Regions a set of planes cuts a surface into (the truth for section networks), counted on a
/// 4×-subdivided copy (see [`plane_regions`]).
pub fn section_regions(m: &Mesh, planes: &[(Point3, f64)]) -> usize {
    plane_regions(&subdivide_midpoint(m, 2), planes)
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

// ---------------------------------------------------------------------------------------------
// Analytic curve networks beyond plane sections (the networks sweep and `tests/fit_networks*.rs`).
// Each curve is sampled from a closed-form curve on a closed-form surface; the truths (region
// counts, distances) come from the geometry, not from the fit.

/// A curves mesh from polylines given by their points. Every point gets its own index (nothing
/// is shared), so joining shared endpoints is left to the fit, as with a real curve file.
pub fn polylines(lines: &[Vec<Point3>]) -> Mesh {
    let mut positions = Vec::new();
    let mut curves = Vec::new();
    for line in lines {
        let start = positions.len() as u32;
        positions.extend_from_slice(line);
        curves.push((start..positions.len() as u32).collect());
    }
    Mesh { positions, curves, ..Default::default() }
}

/// The closed circle `c + r (cos t · u + sin t · v)` sampled at `n` points from angle `phase`,
/// with the first point repeated at the end (so the polyline closes). `u`, `v` orthonormal.
pub fn circle(c: Point3, u: Point3, v: Point3, r: f64, n: usize, phase: f64) -> Vec<Point3> {
    let mut pts: Vec<Point3> = (0..n)
        .map(|k| {
            let t = phase + std::f64::consts::TAU * k as f64 / n as f64;
            add(c, add(scale(u, r * t.cos()), scale(v, r * t.sin())))
        })
        .collect();
    pts.push(pts[0]);
    pts
}

/// The open arc of the same circle from angle `t0` to `t1`, `n` segments.
pub fn arc(c: Point3, u: Point3, v: Point3, r: f64, t0: f64, t1: f64, n: usize) -> Vec<Point3> {
    (0..=n)
        .map(|k| {
            let t = t0 + (t1 - t0) * k as f64 / n as f64;
            add(c, add(scale(u, r * t.cos()), scale(v, r * t.sin())))
        })
        .collect()
}

/// A loxodrome (rhumb line) on the sphere of radius `r` about the origin: latitude from `-lat` to
/// `lat`, longitude = `k` · atanh(sin latitude), `n` segments. It crosses the equator once, at
/// longitude 0, at parameter `n / 2` (a vertex when `n` is even).
pub fn loxodrome(r: f64, lat: f64, k: f64, n: usize) -> Vec<Point3> {
    (0..=n)
        .map(|i| {
            let phi = -lat + 2.0 * lat * i as f64 / n as f64;
            let lon = k * phi.sin().atanh();
            [r * phi.cos() * lon.cos(), r * phi.cos() * lon.sin(), r * phi.sin()]
        })
        .collect()
}

/// The helix `(r cos t, r sin t, z0 + (z1 − z0) t / (2π turns))`, `n` segments.
pub fn helix(r: f64, z0: f64, z1: f64, turns: f64, n: usize) -> Vec<Point3> {
    (0..=n)
        .map(|i| {
            let s = i as f64 / n as f64;
            let t = std::f64::consts::TAU * turns * s;
            [r * t.cos(), r * t.sin(), z0 + (z1 - z0) * s]
        })
        .collect()
}

/// An open cylinder (no caps) of radius `r` about the z axis from z = 0 to z = `h`, `nu` vertices
/// around and `nv` rings, triangulated, outward-oriented, two boundary loops.
pub fn open_cylinder(nu: usize, nv: usize, r: f64, h: f64) -> Mesh {
    let mut pos = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let t = std::f64::consts::TAU * i as f64 / nu as f64;
            pos.push([r * t.cos(), r * t.sin(), h * j as f64 / (nv - 1) as f64]);
        }
    }
    let id = |i: usize, j: usize| (j * nu + i % nu) as u32;
    let mut tris = Vec::new();
    for j in 0..nv - 1 {
        for i in 0..nu {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}

/// The paraboloid z = a (x² + y²) over [−1, 1]², an `n × n` grid of cells with the cells whose
/// centre has max(|x|, |y|) < `hole` removed (a square hole), triangulated, normals +z-ish.
pub fn paraboloid_with_hole(n: usize, a: f64, hole: f64) -> Mesh {
    let h = 2.0 / n as f64;
    let mut pos = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (-1.0 + i as f64 * h, -1.0 + j as f64 * h);
            pos.push([x, y, a * (x * x + y * y)]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (cx, cy) = (-1.0 + (i as f64 + 0.5) * h, -1.0 + (j as f64 + 0.5) * h);
            if cx.abs().max(cy.abs()) < hole {
                continue;
            }
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}

/// Moves every point of `curves` by a pseudo-random offset of length ≤ `amplitude` (a fixed LCG
/// from `seed`, so cases are reproducible). Points listed in `keep` stay put.
pub fn jitter(curves: &mut Mesh, amplitude: f64, seed: u64, keep: &[u32]) {
    let mut s = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    for (i, p) in curves.positions.iter_mut().enumerate() {
        let d = [next(), next(), next()];
        if keep.contains(&(i as u32)) {
            continue;
        }
        *p = add(*p, scale(d, amplitude / 3f64.sqrt()));
    }
}

/// The three great circles of the sphere of radius `r` about the origin in the coordinate planes
/// (xy, xz, yz), each sampled independently with `n` points from its own phase. They cross
/// pairwise at the six axis points ±r·e_k, which are polyline vertices only when the phase is a
/// multiple of 2π/n (the phase 0 case shares them exactly); they cut the sphere into 8 octants.
pub fn great_circles(r: f64, n: usize, phases: [f64; 3]) -> Vec<Vec<Point3>> {
    let (o, x, y, z) = ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    vec![circle(o, x, y, r, n, phases[0]), circle(o, x, z, r, n, phases[1]), circle(o, y, z, r, n, phases[2])]
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

// ---------------------------------------------------------------------------------------------
// Inputs nobody tried before (the `sweep_unseen` example and `tests/fit_unseen*.rs`): templates
// with n-gons, holes, several components or a zero-area face, and curve files written the way
// other programs write them (glTF LINES / LINE_LOOP, OBJ negative indices, ends that miss).

/// A closed UV sphere of radius `r` with `nu` segments and `nv` rings whose poles are single
/// `nu`-gons (cut at latitude ±(90° − 90°/nv)) and whose sides are quads: an n-gon template.
pub fn ngon_sphere(nu: usize, nv: usize, r: f64) -> Mesh {
    let mut pos = Vec::new();
    for j in 0..nv {
        let lat = -std::f64::consts::PI / 2.0 + std::f64::consts::PI * (j as f64 + 0.5) / nv as f64;
        for i in 0..nu {
            let t = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
            pos.push([r * lat.cos() * t.cos(), r * lat.cos() * t.sin(), r * lat.sin()]);
        }
    }
    let id = |i: usize, j: usize| (j * nu + i % nu) as u32;
    let mut faces = Faces::new();
    let bottom: Vec<u32> = (0..nu).rev().map(|i| id(i, 0)).collect();
    faces.push(&bottom, 0);
    for j in 0..nv - 1 {
        for i in 0..nu {
            faces.push(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)], 0);
        }
    }
    let top: Vec<u32> = (0..nu).map(|i| id(i, nv - 1)).collect();
    faces.push(&top, 0);
    Mesh::new(pos, faces)
}

/// `m` without the faces whose centroid is within `radius` of one of `centres`.
pub fn with_holes(m: &Mesh, centres: &[Point3], radius: f64) -> Mesh {
    let mut out = m.clone();
    let pos = m.positions.clone();
    let faces = m.faces.clone();
    out.faces.retain(|i| {
        let f = faces.get(i);
        let c = f.iter().fold([0.0; 3], |a, &v| {
            let p = pos[v as usize];
            [a[0] + p[0], a[1] + p[1], a[2] + p[2]]
        });
        let c = [c[0] / f.len() as f64, c[1] / f.len() as f64, c[2] / f.len() as f64];
        centres.iter().all(|&q| norm(sub(c, q)) > radius)
    });
    out
}

/// Two meshes as one (the second's indices shifted).
pub fn disjoint_union(a: &Mesh, b: &Mesh) -> Mesh {
    let mut pos = a.positions.clone();
    pos.extend_from_slice(&b.positions);
    let n = a.positions.len() as u32;
    let mut faces = a.faces.clone();
    for f in b.faces.iter() {
        let g: Vec<u32> = f.iter().map(|&v| v + n).collect();
        faces.push(&g, 0);
    }
    Mesh::new(pos, faces)
}

/// The icosphere with one edge split by a vertex on it and a zero-area face filling the split
/// on one side, plus an unreferenced duplicate of vertex 0: closed, manifold, consistently
/// oriented, but with a degenerate face.
pub fn with_zero_area_face(levels: u32) -> Mesh {
    let m = icosphere(levels, 1.0);
    let tris = m.faces.triangles();
    let (a, b, c) = (tris[0][0], tris[0][1], tris[0][2]);
    // The face across a-b (holding b→a) is untouched: the new face (mid, a, b) takes its place
    // along that edge, and (a, mid, c), (mid, b, c) replace face 0.
    let mut pos = m.positions.clone();
    let pa = pos[a as usize];
    let pb = pos[b as usize];
    pos.push([(pa[0] + pb[0]) / 2.0, (pa[1] + pb[1]) / 2.0, (pa[2] + pb[2]) / 2.0]);
    let mid = (pos.len() - 1) as u32;
    pos.push(pos[0]);
    let mut out = vec![[a, mid, c], [mid, b, c], [mid, a, b]];
    out.extend_from_slice(&tris[1..]);
    Mesh::from_triangles(pos, &out)
}

/// A glTF (JSON with an embedded base64 buffer) holding `points` and one primitive of `mode` with
/// `indices`.
pub fn gltf_lines(points: &[Point3], indices: &[u32], mode: u32) -> Vec<u8> {
    let mut buf = Vec::new();
    for p in points {
        for &x in p {
            buf.extend_from_slice(&(x as f32).to_le_bytes());
        }
    }
    let pos_len = buf.len();
    for &i in indices {
        buf.extend_from_slice(&i.to_le_bytes());
    }
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] as f32);
            hi[k] = hi[k].max(p[k] as f32);
        }
    }
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": buf.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&buf))}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": pos_len},
            {"buffer": 0, "byteOffset": pos_len, "byteLength": buf.len() - pos_len}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": points.len(), "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": mode}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    serde_json::to_vec(&doc).unwrap_or_default()
}

/// glTF with one mesh per polyline (LINE_STRIP, no indices), each under its own node with a
/// translation, a 90° rotation about z and a scale, all children of a node scaling by 2: the stored
/// points are the world points `lines` mapped back by hand (f32), so a reader that applies the
/// node transforms gets `lines` back to f32 rounding.
pub fn gltf_strips_with_nodes(lines: &[Vec<Point3>]) -> Vec<u8> {
    use serde_json::json;
    let mut buf: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut meshes, mut nodes) = (vec![], vec![], vec![], vec![]);
    let mut children = vec![];
    for (k, line) in lines.iter().enumerate() {
        // Node k: translation t_k, rotation 90° about z (x→y, y→-x), scale s; parent scale 2.
        // world = 2 · (t + s · Rz(p_local)) ⇒ p_local = Rz⁻¹((world / 2 − t) / s).
        let t = [0.3 * k as f64, -0.2, 0.1 * k as f64];
        let s = 0.5 + 0.25 * k as f64;
        let local: Vec<[f32; 3]> = line
            .iter()
            .map(|w| {
                let q = [(w[0] / 2.0 - t[0]) / s, (w[1] / 2.0 - t[1]) / s, (w[2] / 2.0 - t[2]) / s];
                // Rz⁻¹ (x, y) = (y, -x)
                [q[1] as f32, -q[0] as f32, q[2] as f32]
            })
            .collect();
        let off = buf.len();
        for p in &local {
            for x in p {
                buf.extend_from_slice(&x.to_le_bytes());
            }
        }
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in &local {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        views.push(json!({"buffer": 0, "byteOffset": off, "byteLength": buf.len() - off}));
        accessors.push(json!({"bufferView": k, "componentType": 5126, "count": local.len(), "type": "VEC3", "min": lo, "max": hi}));
        meshes.push(json!({"primitives": [{"attributes": {"POSITION": k}, "mode": 3}]}));
        let h = std::f64::consts::FRAC_1_SQRT_2;
        nodes.push(json!({"mesh": k, "translation": t, "rotation": [0.0, 0.0, h, h], "scale": [s, s, s]}));
        children.push(k);
    }
    nodes.push(json!({"children": children, "scale": [2.0, 2.0, 2.0]}));
    let root = nodes.len() - 1;
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": buf.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&buf))}],
        "bufferViews": views, "accessors": accessors, "meshes": meshes, "nodes": nodes,
        "scenes": [{"nodes": [root]}], "scene": 0
    });
    serde_json::to_vec(&doc).unwrap_or_default()
}

pub fn base64(b: &[u8]) -> String {
    const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in b.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// `curves` (e.g. the ellipsoid sections) as OBJ text with negative (relative) indices.
pub fn obj_negative_indices(curves: &Mesh) -> Vec<u8> {
    let mut s = String::new();
    for c in &curves.curves {
        for &v in c {
            let p = curves.positions[v as usize];
            s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        s += "l";
        for k in 0..c.len() {
            s += &format!(" {}", k as i64 - c.len() as i64);
        }
        s += "\n";
    }
    s.into_bytes()
}

/// The principal sections of the ellipsoid with semi-axes `axes` as 12 separate quarter arcs (6 segments each) whose shared ends are moved apart by `gap`
/// (absolute), so joining them is left to the network's tolerances.
pub fn quarter_arcs_with_gap(axes: [f64; 3], gap: f64) -> Mesh {
    let mut lines = Vec::new();
    for (i, j) in [(0usize, 1usize), (1, 2), (2, 0)] {
        for q in 0..4 {
            let mut line = Vec::new();
            for k in 0..=6 {
                let t = (q as f64 + k as f64 / 6.0) * std::f64::consts::PI / 2.0;
                let mut p = [0.0; 3];
                p[i] = axes[i] * t.cos();
                p[j] = axes[j] * t.sin();
                line.push(p);
            }
            // Each arc's start is pushed along the third axis by ±gap/2.
            let third = 3 - i - j;
            let s = if q % 2 == 0 { 0.5 } else { -0.5 };
            line[0][third] += s * gap;
            lines.push(line);
        }
    }
    polylines(&lines)
}

/// A closed wave on the unit sphere: z = 0.3 sin 3t at longitude t, `samples` points at
/// t = 2πk/samples for k in 0..samples, plus the point at t = 2π (equal to the first up to
/// rounding) when `repeat_start` (a polyline closed by its end point rather than by LINE_LOOP).
pub fn tilted_wave(samples: usize, repeat_start: bool) -> Vec<Point3> {
    (0..samples + usize::from(repeat_start))
        .map(|k| {
            let t = 2.0 * std::f64::consts::PI * k as f64 / samples as f64;
            let z = 0.3 * (3.0 * t).sin();
            let r = (1.0 - z * z).sqrt();
            [r * t.cos(), r * t.sin(), z]
        })
        .collect()
}

/// A closed UV sphere of radius `r` about the origin: `nu` segments, `nv` rings (every other ring
/// turned by half a segment), triangle fans at the poles; 2·nu·(nv − 1) faces. With many segments
/// and few rings every face is a needle (nu = 512, nv = 6: ~0.012 wide, ~0.52 tall): a template
/// of long thin triangles, like a CAD tessellation.
pub fn needle_sphere(nu: usize, nv: usize, r: f64) -> Mesh {
    use std::f64::consts::{FRAC_PI_2, PI};
    let mut pos = vec![[0.0, 0.0, -r]];
    for j in 1..nv {
        let lat = -FRAC_PI_2 + PI * j as f64 / nv as f64;
        for i in 0..nu {
            let t = 2.0 * PI * (i as f64 + 0.5 * (j % 2) as f64) / nu as f64;
            pos.push([r * lat.cos() * t.cos(), r * lat.cos() * t.sin(), r * lat.sin()]);
        }
    }
    pos.push([0.0, 0.0, r]);
    let top = (pos.len() - 1) as u32;
    let id = |i: usize, j: usize| (1 + (j - 1) * nu + i % nu) as u32;
    let mut tris = Vec::new();
    for i in 0..nu {
        tris.push([0, id(i + 1, 1), id(i, 1)]);
        tris.push([top, id(i, nv - 1), id(i + 1, nv - 1)]);
    }
    for j in 1..nv.saturating_sub(1) {
        for i in 0..nu {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}
