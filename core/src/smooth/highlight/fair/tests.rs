//! Tests of the fairing: derivatives against finite differences, the Willmore energy of a
//! sphere, the Gauss–Newton model against the true target, the movable set.

use super::*;
use crate::shapes::{grid, icosphere};

fn lights() -> Lights {
    Lights { normal: [0.0, 0.0, 1.0], direction: [1.0, 0.0, 0.0], origin: [0.0, 0.31, 2.0], spacing: 0.05 }
}

/// A bumpy height field z = f(x, y) on the unit square, every vertex in R.
fn bumpy() -> (Adjacency, Vec<Point3>, Setup) {
    let mut m = grid(12, 12, 1.0 / 12.0, false);
    for p in &mut m.positions {
        p[2] = 0.3 * (2.0 * p[0]).sin() * (1.5 * p[1]).cos() + 0.02 * (17.0 * p[0] * p[1]).sin();
    }
    let adj = Adjacency::new(&m).unwrap();
    let n = m.vertex_count();
    let setup = Setup::new(&adj, &m.positions, vec![true; n], &vec![false; n], lights(), 1.0, 1.0, 0.5);
    (adj, m.positions, setup)
}

fn moved_along(x: &[Point3], nrm: &[Point3], v: usize, h: f64) -> Vec<Point3> {
    let mut y = x.to_vec();
    y[v] = add(y[v], scale(nrm[v], h));
    y
}

#[test]
fn movable_vertices_are_three_rings_inside() {
    // 12×12 cells: border vertices are outside; the movable ones are ≥ 3 edges from it, i.e.
    // grid indices 3..=9 in both directions: 7 × 7.
    let (_, _, setup) = bumpy();
    assert_eq!(setup.vars.len(), 49);
    for &v in &setup.vars {
        let (i, j) = (v as usize % 13, v as usize / 13);
        assert!((3..=9).contains(&i) && (3..=9).contains(&j));
    }
}

#[test]
fn analytic_derivatives_match_finite_differences() {
    let (adj, x, setup) = bumpy();
    let nrm = adj.normals(&x);
    let md = lines::model(&adj, &x, &setup.lights);
    let h = 1e-6;
    // ∂d/∂x for vertices around the movable set.
    let mut checked = 0;
    for v in (0..x.len()).filter(|&v| setup.affected[v]) {
        let g = distance_gradient(&adj, &x, &nrm, &setup, v);
        for &(k, gk) in &g {
            let u = setup.vars[k as usize] as usize;
            let dp = setup
                .lights
                .distance(moved_along(&x, &nrm, u, h)[v], adj.normal_sum(&moved_along(&x, &nrm, u, h), v))
                .unwrap();
            let dm = setup
                .lights
                .distance(moved_along(&x, &nrm, u, -h)[v], adj.normal_sum(&moved_along(&x, &nrm, u, -h), v))
                .unwrap();
            let fd = (dp - dm) / (2.0 * h);
            assert!((fd - gk).abs() < 1e-6 * (1.0 + gk.abs()), "d_{v} wrt {u}: {gk} vs {fd}");
            checked += 1;
        }
    }
    assert!(checked > 100);
    // ∂Q/∂x of nodes (eq. 13) on edges near the movable set.
    let moving = setup.moving_nodes(&adj, &md);
    let mut nodes_checked = 0;
    for (id, nd) in md.nodes.iter().enumerate() {
        if !moving[id] || nd.t < 0.05 || nd.t > 0.95 {
            continue;
        }
        let jac = node_jacobian(&adj, &x, &nrm, &setup, &md, id as u32);
        for &(k, _) in &jac[0] {
            let u = setup.vars[k as usize] as usize;
            let at = |hh: f64| {
                let y = moved_along(&x, &nrm, u, hh);
                let m2 = lines::model(&adj, &y, &setup.lights);
                m2.nodes.iter().find(|n2| n2.edge == nd.edge && n2.m == nd.m).map(|n2| n2.pos).unwrap()
            };
            let (p, q) = (at(h), at(-h));
            for c in 0..3 {
                let fd = (p[c] - q[c]) / (2.0 * h);
                let an = jac[c].iter().find(|e| e.0 == k).map(|e| e.1).unwrap_or(0.0);
                assert!(
                    (fd - an).abs() < 1e-5 * (1.0 + an.abs()),
                    "node {id} coord {c} wrt {u}: {an} vs {fd}"
                );
            }
        }
        nodes_checked += 1;
    }
    assert!(nodes_checked > 20, "{nodes_checked}");
}

#[test]
fn willmore_energy_of_a_sphere_is_64_pi_in_the_printed_convention() {
    // ∫H² dA = 4π for any round sphere; eq. 8's 1/Aᵢ makes ‖K‖² = 16H², so E = 64π.
    for r in [1.0, 1e-3] {
        let m = icosphere(4, r);
        let adj = Adjacency::new(&m).unwrap();
        let n = m.vertex_count();
        let setup = Setup::new(&adj, &m.positions, vec![true; n], &vec![false; n], lights(), 1.0, 1.0, 0.5);
        let (e, h_sd) = willmore(&adj, &m.positions, &setup);
        let want = 64.0 * std::f64::consts::PI;
        assert!((e - want).abs() < 0.02 * want, "E = {e}, want {want}");
        assert!(h_sd < 0.02 / r, "H sd {h_sd}");
    }
}

#[test]
fn gauss_newton_model_matches_the_true_target_for_small_steps() {
    // Eq. 15's model, with eq. 12's targets and eq. 14's weights frozen at the current line
    // (as the paper forms them), against the exact energies after a small step along the
    // model's steepest descent: equal to first order (signs and scales of both terms).
    let (adj, x, setup) = bumpy();
    let nrm = adj.normals(&x);
    let st = State::new(&adj, &x, &setup);
    let quad = quadratic(&adj, &x, &nrm, &setup, &st, &Progress::new()).unwrap();
    let frozen = |y: &[Point3]| -> f64 {
        let m2 = lines::model(&adj, y, &setup.lights);
        let mut f = 0.0;
        for run in &st.runs.runs {
            for (node, tgt, l) in target::targets(&st.model, run) {
                let nd = st.model.nodes[node as usize];
                let q = m2.nodes.iter().find(|n2| n2.edge == nd.edge && n2.m == nd.m).unwrap().pos;
                f += l * crate::geometry::norm2(sub(q, tgt));
            }
        }
        setup.w_fair * willmore(&adj, y, &setup).0 + setup.w_diff * f / setup.e.powi(3)
    };
    let g2: f64 = quad.c.iter().map(|g| g * g).sum();
    assert!(g2 > 0.0);
    for eps in [1e-6, 1e-7] {
        let step: Vec<f64> = quad.c.iter().map(|g| -eps * g / g2.sqrt()).collect();
        let y = moved(&x, &nrm, &setup, &step, 1.0);
        let predicted: f64 = 2.0 * quad.c.iter().zip(&step).map(|(g, s)| g * s).sum::<f64>();
        let actual = frozen(&y) - frozen(&x);
        assert!(predicted < 0.0);
        assert!((actual - predicted).abs() < 0.01 * predicted.abs(), "actual {actual} predicted {predicted}");
    }
}
