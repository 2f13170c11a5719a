//! Analytic curve networks beyond plane sections (the networks sweep and `tests/fit_networks*.rs`,
//! `tests/fit_unseen*.rs`). Each curve is sampled from a closed-form curve on a closed-form surface;
//! the truths (region counts, distances) come from the geometry, not from the fit.

use crate::geometry::{add, scale};
use crate::mesh::{Mesh, Point3};

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
