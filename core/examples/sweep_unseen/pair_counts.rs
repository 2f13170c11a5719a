//! Valid correspondence pairs in small and large numbers (session 9): the fewest the coarse RBF
//! accepts (4, not coplanar) and 100, on a template turned by 90° and moved away so that only the
//! pairs can bring it onto the curves; each pair joins a curve vertex to the template vertex in the
//! same direction from the centre (the truth: the template is a sphere, the curves an ellipsoid's
//! sections about the same centre).

use meshwork_core::geometry::{dot, norm};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::icosphere;

use crate::support::{case, sphere_sections, Case, Expect};

/// Pairs for up to `n` curve vertices spread over the list: each to the unit sphere's vertex
/// nearest its direction (skipping a template vertex already used).
fn direction_pairs(sphere: &Mesh, curves: &Mesh, n: usize) -> serde_json::Value {
    let mut used = std::collections::HashSet::new();
    let mut pairs = Vec::new();
    let m = curves.positions.len();
    for k in 0..n.min(m) {
        let p = curves.positions[k * m / n.min(m)];
        let d = norm(p);
        let dir = [p[0] / d, p[1] / d, p[2] / d];
        let best = (0..sphere.positions.len())
            .max_by(|&a, &b| dot(sphere.positions[a], dir).total_cmp(&dot(sphere.positions[b], dir)))
            .unwrap_or(0);
        if used.insert(best) {
            pairs.push(serde_json::json!({"template_vertex": best, "curve_point": p}));
        }
    }
    serde_json::Value::Array(pairs)
}

/// The unit icosphere turned by 90° about z and moved by (3, −2, 1): vertex indices unchanged.
fn turned_away(m: &Mesh) -> Mesh {
    let mut m = m.clone();
    for p in &mut m.positions {
        *p = [-p[1] + 3.0, p[0] - 2.0, p[2] + 1.0];
    }
    m
}

pub fn pair_counts() -> Vec<Case> {
    use serde_json::json;
    let mut out = Vec::new();
    let axis_points: [Point3; 4] = [[1.4, 0.0, 0.0], [-1.4, 0.0, 0.0], [0.0, 1.15, 0.0], [0.0, 0.0, 0.9]];
    let four = {
        let s = icosphere(3, 1.0);
        let c = Mesh { positions: axis_points.to_vec(), ..Default::default() };
        direction_pairs(&s, &c, 4)
    };
    let f2 = four.clone();
    out.push(case(
        "4 pairs (axis points), template turned and moved",
        || Ok(vec![turned_away(&icosphere(3, 1.0)), sphere_sections(6)]),
        json!({"pairs": f2}),
        Expect::Fit(Some(8)),
    ));
    out.push(case(
        "4 pairs, alignment pca_icp",
        || Ok(vec![turned_away(&icosphere(3, 1.0)), sphere_sections(6)]),
        json!({"pairs": four, "alignment": "pca_icp"}),
        Expect::Fit(Some(8)),
    ));
    let hundred = direction_pairs(&icosphere(3, 1.0), &sphere_sections(12), 100);
    let count = hundred.as_array().map_or(0, |a| a.len());
    out.push(case(
        &format!("{count} pairs on 138 curve vertices, template turned and moved"),
        || Ok(vec![turned_away(&icosphere(3, 1.0)), sphere_sections(12)]),
        json!({"pairs": hundred}),
        Expect::Fit(Some(8)),
    ));
    let all = direction_pairs(&icosphere(2, 1.0), &sphere_sections(6), 66);
    let count = all.as_array().map_or(0, |a| a.len());
    out.push(case(
        &format!("{count} pairs on a coarse template (162 vertices)"),
        || Ok(vec![turned_away(&icosphere(2, 1.0)), sphere_sections(6)]),
        json!({"pairs": all}),
        Expect::Fit(Some(8)),
    ));
    out
}
