//! Templates whose layout the curves meet in new ways (session 8): a hole where curves cross or
//! under a curve, two components each with its own curves, quads only, poles of valence 32, and
//! repaired shared meshes in pieces as templates. Truths: the octants (8), two sets of octants
//! (16), the cube's 6 faces, the UV sphere's 8 octants, each counted by hand.

use meshwork_core::fit::testdata::{disjoint_union, ellipsoid_sections, polylines, uv_sphere, with_holes};
use meshwork_core::geometry::norm;
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::icosphere;
use meshwork_core::Error;

use crate::support::{
    case, equator_and_meridians, fit_inputs, lines_of, repaired_vs_own_sections, shifted, sphere_sections,
    vs_octants, Case, Expect, X,
};

/// A cube sphere of radius `r`: 6 faces of n×n quads, welded, projected on the sphere.
fn cube_sphere(n: usize, r: f64) -> Mesh {
    let mut pos: Vec<Point3> = Vec::new();
    let mut index: std::collections::HashMap<[i64; 3], u32> = std::collections::HashMap::new();
    let mut faces = meshwork_core::mesh::Faces::new();
    // Each cube face: normal axis a, sign s; u, v the other axes oriented so u × v = s·e_a.
    for a in 0..3 {
        for s in [1.0f64, -1.0] {
            let (u, v) = ((a + 1) % 3, (a + 2) % 3);
            let mut id = |i: usize, j: usize| -> u32 {
                let mut c = [0.0; 3];
                c[a] = s;
                c[u] = -1.0 + 2.0 * i as f64 / n as f64;
                c[v] = (-1.0 + 2.0 * j as f64 / n as f64) * s;
                let key = c.map(|x| (x * 1e6).round() as i64);
                *index.entry(key).or_insert_with(|| {
                    let l = norm(c);
                    pos.push([r * c[0] / l, r * c[1] / l, r * c[2] / l]);
                    (pos.len() - 1) as u32
                })
            };
            for i in 0..n {
                for j in 0..n {
                    let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                    faces.push(&q, 0);
                }
            }
        }
    }
    Mesh::new(pos, faces)
}

/// Two unit icospheres `dx` apart along x, each with its own copy of `curves`.
fn two_spheres(dx: f64, curves: &Mesh) -> Result<Vec<Mesh>, Error> {
    let by = [dx, 0.0, 0.0];
    let t = disjoint_union(&icosphere(3, 1.0), &shifted(&icosphere(3, 1.0), by));
    let mut l = lines_of(curves);
    l.extend(lines_of(&shifted(curves, by)));
    fit_inputs(t, polylines(&l))
}

pub fn layouts() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();

    out.push(case(
        "hole where two curves cross (auto)",
        || vs_octants(with_holes(&icosphere(3, 1.0), &[X], 0.2)),
        json!({}),
        Expect::Fit(Some(8)),
    ));

    out.push(case(
        "hole where two curves cross (none)",
        || vs_octants(with_holes(&icosphere(3, 1.0), &[X], 0.2)),
        json!({"alignment": "none"}),
        Expect::Fit(Some(8)),
    ));

    out.push(case(
        "big hole under a curve (none)",
        || vs_octants(with_holes(&icosphere(3, 1.0), &[[0.0, 0.7071, 0.7071]], 0.35)),
        json!({"alignment": "none"}),
        Expect::Fit(Some(8)),
    ));

    out.push(case(
        "two components, curves on both (none)",
        || two_spheres(5.0, &sphere_sections(6)),
        json!({"alignment": "none"}),
        Expect::Fit(Some(16)),
    ));

    out.push(case(
        "two components, curves on both (auto)",
        || two_spheres(5.0, &sphere_sections(6)),
        json!({}),
        Expect::Fit(Some(16)),
    ));

    out.push(case(
        "two components, curves on both, touching nets",
        || two_spheres(2.2, &ellipsoid_sections([1.05, 1.0, 1.0], 6)),
        json!({"alignment": "none"}),
        Expect::Fit(Some(16)),
    ));

    out.push(case(
        "cube sphere (quads only)",
        || vs_octants(cube_sphere(8, 1.0)),
        json!({}),
        Expect::Fit(Some(8)),
    ));

    out.push(case(
        "cube sphere (quads only), curves along its seams",
        || {
            // The cube's edges projected: 12 arcs, 8 corners of degree 3, 6 regions.
            let c = 1.0 / 3f64.sqrt();
            let mut l = Vec::new();
            let corners: Vec<Point3> = (0..8)
                .map(|k| {
                    let s = |b: usize| if k >> b & 1 == 1 { c } else { -c };
                    [s(0), s(1), s(2)]
                })
                .collect();
            for a in 0..8usize {
                for b in a + 1..8 {
                    if (a ^ b).count_ones() == 1 {
                        let (p, q) = (corners[a], corners[b]);
                        l.push(
                            (0..=16)
                                .map(|k| {
                                    let t = k as f64 / 16.0;
                                    let m = [
                                        p[0] + t * (q[0] - p[0]),
                                        p[1] + t * (q[1] - p[1]),
                                        p[2] + t * (q[2] - p[2]),
                                    ];
                                    let r = norm(m) / 1.1;
                                    [m[0] / r, m[1] / r, m[2] / r]
                                })
                                .collect(),
                        );
                    }
                }
            }
            fit_inputs(cube_sphere(8, 1.0), polylines(&l))
        },
        json!({}),
        Expect::Fit(Some(6)),
    ));

    out.push(case(
        "UV sphere (pole valence 32), 4 meridians + equator",
        || fit_inputs(uv_sphere(32, 16, 1.0, false), polylines(&equator_and_meridians(4, 0.3, 0.1))),
        json!({}),
        Expect::Fit(Some(8)),
    ));
    // Repaired shared meshes in pieces (the raw ones are in `templates`); the flat ones (woody,
    // alligator) need `coplanar_centres = "augment"` and are in sweep_fit.
    for name in ["beetle", "teapot", "suzanne"] {
        out.push(case(
            &format!("{name}-repaired vs own sections"),
            move || repaired_vs_own_sections(name),
            json!({"alignment": "none"}),
            Expect::Fit(None),
        ));
    }
    out
}
