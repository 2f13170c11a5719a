//! Template and curve densities nobody tried (session 9): the 20-face icosahedron under 72 and
//! ~2,000 curve vertices, an 80k-face template under 12 curve vertices, templates of slivers
//! (every face a fan of needles; a UV sphere of 512 × 6 long thin triangles), curves sampled very
//! unevenly (1 % of the segments 100× longer; lengths growing geometrically ×1000 along each
//! arc) and dangling curves that end inside a region.

use std::f64::consts::{FRAC_PI_2, PI};

use meshwork_core::fit::testdata::{arc, ellipsoid_sections, loxodrome, needle_sphere, polylines};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::icosphere;

use crate::support::{case, lines_of, sphere_sections, Case, Expect, AXES, O, X, Y, Z};

/// `m` with every triangle split into a fan of `3k` needles from its centroid to `k - 1` points
/// on each edge (shared with the neighbour, so the mesh stays closed and manifold).
pub fn centroid_needles(m: &Mesh, k: usize) -> Mesh {
    let mut pos = m.positions.clone();
    let mut edge_pts: std::collections::HashMap<(u32, u32), Vec<u32>> = std::collections::HashMap::new();
    let mut tris = Vec::new();
    for t in m.faces.triangles() {
        let p = |v: u32| m.positions[v as usize];
        let c = [
            (p(t[0])[0] + p(t[1])[0] + p(t[2])[0]) / 3.0,
            (p(t[0])[1] + p(t[1])[1] + p(t[2])[1]) / 3.0,
            (p(t[0])[2] + p(t[1])[2] + p(t[2])[2]) / 3.0,
        ];
        pos.push(c);
        let centre = (pos.len() - 1) as u32;
        let mut ring = Vec::new();
        for e in 0..3 {
            let (u, v) = (t[e], t[(e + 1) % 3]);
            let key = (u.min(v), u.max(v));
            let inner = edge_pts
                .entry(key)
                .or_insert_with(|| {
                    let (a, b) = (pos[key.0 as usize], pos[key.1 as usize]);
                    (1..k)
                        .map(|i| {
                            let s = i as f64 / k as f64;
                            pos.push([
                                a[0] + s * (b[0] - a[0]),
                                a[1] + s * (b[1] - a[1]),
                                a[2] + s * (b[2] - a[2]),
                            ]);
                            (pos.len() - 1) as u32
                        })
                        .collect()
                })
                .clone();
            ring.push(u);
            if key.0 == u {
                ring.extend(inner);
            } else {
                ring.extend(inner.into_iter().rev());
            }
        }
        for i in 0..ring.len() {
            tris.push([centre, ring[i], ring[(i + 1) % ring.len()]]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}

/// The octant network of the ellipsoid with every quarter arc resampled at parameters `ts`
/// (0 = one axis point, 1 = the next; increasing), the six axis points shared.
pub fn octants_sampled(ts: &[f64]) -> Mesh {
    let mut lines = Vec::new();
    for (i, j) in [(0usize, 1usize), (1, 2), (2, 0)] {
        for q in 0..4 {
            let line: Vec<Point3> = ts
                .iter()
                .map(|&t| {
                    let th = FRAC_PI_2 * (q as f64 + t);
                    let (c, s) = match t {
                        t if t == 0.0 => [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][q],
                        t if t == 1.0 => [(0.0, 1.0), (-1.0, 0.0), (0.0, -1.0), (1.0, 0.0)][q],
                        _ => (th.cos(), th.sin()),
                    };
                    let mut p = [0.0; 3];
                    p[i] = AXES[i] * c;
                    p[j] = AXES[j] * s;
                    p
                })
                .collect();
            lines.push(line);
        }
    }
    polylines(&lines)
}

pub fn densities() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();
    out.push(case(
        "icosahedron (20 faces), 72 curve vertices",
        || Ok(vec![icosphere(0, 1.0), sphere_sections(6)]),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "icosahedron (20 faces), 2040 curve vertices",
        || Ok(vec![icosphere(0, 1.0), sphere_sections(170)]),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "fine template (80k faces), 12 curve vertices",
        || Ok(vec![icosphere(6, 1.0), ellipsoid_sections(AXES, 2)]),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "needle template (every face a fan of 24 needles)",
        || Ok(vec![centroid_needles(&icosphere(2, 1.0), 8), sphere_sections(6)]),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "long thin triangles (UV sphere 512 × 6)",
        || Ok(vec![needle_sphere(512, 6, 1.0), sphere_sections(6)]),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "long thin triangles (UV sphere 16 × 96)",
        || Ok(vec![needle_sphere(16, 96, 1.0), sphere_sections(6)]),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    // 1 % of the segments 100× longer: per quarter arc 99 short steps and one long one (at a place
    // that moves from arc to arc through the parameter offsets).
    out.push(case(
        "1% of segments 100× longer",
        || {
            let h = 1.0 / 199.0;
            let mut ts: Vec<f64> = vec![0.0];
            for k in 0..100 {
                let step = if k == 37 { 100.0 * h } else { h };
                ts.push((ts[k] + step).min(1.0));
            }
            *ts.last_mut().expect("100 steps") = 1.0;
            Ok(vec![icosphere(3, 1.0), octants_sampled(&ts)])
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "segment lengths growing ×1000 along each arc",
        || {
            // 30 steps growing geometrically by 1000^(1/29).
            let g = 1000f64.powf(1.0 / 29.0);
            let lens: Vec<f64> = (0..30).map(|k| g.powi(k)).collect();
            let total: f64 = lens.iter().sum();
            let mut ts: Vec<f64> = vec![0.0];
            for l in &lens {
                ts.push(ts[ts.len() - 1] + l / total);
            }
            *ts.last_mut().expect("30 steps") = 1.0;
            Ok(vec![icosphere(3, 1.0), octants_sampled(&ts)])
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "octants + a dangling arc ending mid-region",
        || {
            let mut l = lines_of(&sphere_sections(6));
            // From the +z pole down the 45° meridian of the first octant, stopping halfway.
            let d = [AXES[0] * 0.5f64.sqrt(), AXES[1] * 0.5f64.sqrt(), 0.0];
            let dangling: Vec<Point3> = arc(O, [0.0, 0.0, AXES[2]], d, 1.0, 0.0, 0.5, 12);
            l.push(dangling);
            Ok(vec![icosphere(3, 1.0), polylines(&l)])
        },
        json!({}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "equator + a loxodrome dangling at both ends",
        || {
            let mut l = vec![meshwork_core::fit::testdata::circle(O, X, Y, 1.0, 64, 0.0)];
            l.push(loxodrome(1.0, 1.0, 1.2, 64));
            Ok(vec![icosphere(3, 1.0), polylines(&l)])
        },
        json!({}),
        Expect::Fit(Some(2)),
    ));
    out.push(case(
        "meridian circle + 3 dangling spokes from one pole",
        || {
            let mut l = vec![meshwork_core::fit::testdata::circle(O, X, Z, 1.0, 64, 0.0)];
            for k in 0..3 {
                let t = 0.4 + 2.0 * PI / 3.0 * k as f64;
                l.push(arc(O, Z, [t.cos(), t.sin(), 0.0], 1.0, 0.0, 1.0, 16));
            }
            Ok(vec![icosphere(3, 1.0), polylines(&l)])
        },
        json!({}),
        Expect::Fit(Some(2)),
    ));
    out
}
