//! An open template whose curves run to its rim: the curve ends must become boundary vertices,
//! or the cuts stop short and regions merge.
//!
//! Truth by construction: the template is the flat unit square; the curves are the lines x = 0.3,
//! x = 0.7 and y = 0.5 (rim to rim) moved by a known map that shrinks the square by 5 % and lifts
//! it into a bump. Three lines rim to rim cut the square into 3 × 2 = 6 regions.

use meshwork_core::fit::testdata::boundary_vertices;
use meshwork_core::fit::{run, Alignment, CoplanarCentres, FitParams};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::grid;
use meshwork_core::Progress;

fn map(p: Point3) -> Point3 {
    let pi = std::f64::consts::PI;
    [0.95 * p[0] + 0.025, 0.95 * p[1] + 0.025, 0.1 * (pi * p[0]).sin() * (pi * p[1]).sin()]
}

fn curves() -> Mesh {
    let mut m = Mesh::default();
    let mut line = |f: &dyn Fn(f64) -> Point3| {
        let base = m.positions.len() as u32;
        m.positions.extend((0..=20).map(|k| map(f(k as f64 / 20.0))));
        m.curves.push((base..m.positions.len() as u32).collect());
    };
    line(&|t| [0.3, t, 0.0]);
    line(&|t| [0.7, t, 0.0]);
    line(&|t| [t, 0.5, 0.0]);
    m
}

fn fit(end_snap: f64) -> (serde_json::Value, Mesh) {
    let params = FitParams {
        alignment: Alignment::None,
        coplanar_centres: CoplanarCentres::Augment,
        end_snap,
        ..Default::default()
    };
    let mut out = run(vec![grid(20, 20, 0.05, false), curves()], &params, &Progress::new()).expect("fit");
    (out.report, out.meshes.remove(0))
}

#[test]
fn curve_ends_become_rim_vertices_and_cut_all_regions() {
    let (r, m) = fit(FitParams::default().end_snap);
    eprintln!("{}", serde_json::to_string_pretty(&r).unwrap());
    assert_eq!(r["regions"], 6, "three rim-to-rim lines cut 6 regions");
    assert_eq!(r["segments_as_edges"], 1.0);
    assert_eq!(r["flipped_faces"], 0);
    // Every curve end (6 of them) is an output vertex on the rim, at its mapped position.
    let on_rim = boundary_vertices(&m);
    let ends: Vec<Point3> = [[0.3, 0.0], [0.3, 1.0], [0.7, 0.0], [0.7, 1.0], [0.0, 0.5], [1.0, 0.5]]
        .iter()
        .map(|&[x, y]| map([x, y, 0.0]))
        .collect();
    for e in ends {
        let hit = m.positions.iter().position(|&p| (0..3).all(|k| (p[k] - e[k]).abs() < 1e-9));
        let v = hit.unwrap_or_else(|| panic!("curve end {e:?} is not an output vertex"));
        assert!(on_rim[v], "curve end {e:?} is output vertex {v}, not on the boundary");
    }
    assert!(r["curve_residual_max"].as_f64().unwrap() < 1e-9);
}

#[test]
fn without_the_end_snap_the_cuts_stop_short() {
    // The check above can fail: with the snap off, the ends land inside the square and the
    // regions on both sides of each cut stay joined.
    let (r, _) = fit(0.0);
    assert!(r["regions"].as_u64().unwrap() < 6, "regions {}", r["regions"]);
}
