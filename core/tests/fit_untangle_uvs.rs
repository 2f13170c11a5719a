//! Texture coordinates of vertices the fit slides over the surface (re-triangulation snaps,
//! untangling, smoothing) are read where the vertex now is, not kept from where it was.
//!
//! Truth: a plane template whose UVs are an affine function of position. Curves in the same
//! plane make the deformation the identity (every curve point is inserted at itself), so every
//! later move is a slide within the plane, and barycentric interpolation of an affine function is
//! exact: every output vertex must carry exactly the UV of its output position.

use meshwork_core::fit::{run, Alignment, CoplanarCentres, FitParams};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::grid;
use meshwork_core::Progress;

/// The analytic UV of a point of the plane z = 0 (an arbitrary affine map).
fn uv_of(p: Point3) -> [f64; 2] {
    [0.3 + 2.0 * p[0] - 0.5 * p[1], -0.1 + 0.7 * p[0] + 1.3 * p[1]]
}

/// A zigzag line across the square and a closed polygon, all their vertices on grid vertices (so
/// each curve point is a template vertex already: zero RBF data, the identity deformation) and
/// their segments a few cells long at odd slopes (so the re-triangulation must cut and snap).
fn curves() -> Mesh {
    let h = 1.0 / 24.0;
    let at = |i: i32, j: i32| [i as f64 * h, j as f64 * h, 0.0];
    let line_ij = [(0, 5), (4, 6), (8, 4), (12, 5), (16, 7), (20, 5), (24, 6)];
    let loop_ij =
        [(18, 15), (17, 18), (15, 20), (12, 20), (9, 18), (8, 15), (9, 12), (12, 10), (15, 10), (17, 12)];
    let mut positions: Vec<Point3> = line_ij.iter().map(|&(i, j)| at(i, j)).collect();
    let line: Vec<u32> = (0..line_ij.len() as u32).collect();
    let first = positions.len() as u32;
    positions.extend(loop_ij.iter().map(|&(i, j)| at(i, j)));
    let mut circle: Vec<u32> = (first..positions.len() as u32).collect();
    circle.push(first);
    Mesh { positions, curves: vec![line, circle], ..Default::default() }
}

fn template() -> Mesh {
    let mut g = grid(24, 24, 1.0 / 24.0, false);
    g.uvs = Some(g.positions.iter().map(|&p| uv_of(p)).collect());
    g
}

fn check(smooth: bool, min_off_grid: usize) {
    let params = FitParams {
        alignment: Alignment::None,
        coplanar_centres: CoplanarCentres::Augment,
        smooth,
        ..Default::default()
    };
    let out = run(vec![template(), curves()], &params, &Progress::new()).expect("fit");
    let m = &out.meshes[0];
    assert!(m.positions.iter().all(|p| p[2].abs() < 1e-12), "the plane stays the plane");
    let uvs = m.uvs.as_ref().expect("the template's UVs are carried");
    assert_eq!(uvs.len(), m.positions.len());
    let mut worst = (0.0f64, 0usize);
    for (v, (&p, uv)) in m.positions.iter().zip(uvs).enumerate() {
        let t = uv_of(p);
        let e = (uv[0] - t[0]).abs().max((uv[1] - t[1]).abs());
        if e > worst.0 {
            worst = (e, v);
        }
    }
    // Vertices did slide (otherwise the test shows nothing): some are off the template grid.
    let h = 1.0 / 24.0;
    let off_grid = m
        .positions
        .iter()
        .filter(|p| {
            ((p[0] / h) - (p[0] / h).round()).abs() > 1e-6 || ((p[1] / h) - (p[1] / h).round()).abs() > 1e-6
        })
        .count();
    assert!(off_grid >= min_off_grid, "only {off_grid} vertices off the grid");
    assert!(worst.0 < 1e-9, "vertex {} at {:?}: UV off by {:.3e}", worst.1, m.positions[worst.1], worst.0);
}

#[test]
fn smoothed_vertices_carry_the_uv_of_where_they_are() {
    check(true, 100);
}

#[test]
fn unsmoothed_vertices_carry_the_uv_of_where_they_are() {
    check(false, 1);
}
