//! Feature alignment in the plane: the stepwise CTPS C²a warp (without an affine part) that
//! moves each feature's points to their mean, keeping boundary vertices on the circle, every
//! triangle positive and the boundary order intact.

use std::f64::consts::TAU;

use super::rotation::restart_at_min;
use super::{lift, DiskMap};
use crate::error::{Error, Result};
use crate::geometry::{add, dist};
use crate::job::Progress;
use crate::mesh::Point3;
use crate::morph::align::ctps_c2a;
use crate::morph::param::count_foldovers;

/// A plane warp s(x) = Σ αᵢ φ(|x − cᵢ|/r), interpolating displacements at the centres, with no
/// polynomial part. (With one: two features leave the affine part fully determined by them, so
/// the "warp" is a global affine map that drags the whole rim and folds triangles there; without
/// it the warp is local, which is what the planar domain needs. CTPS C²a is positive definite.)
struct PlaneWarp {
    centres: Vec<[f64; 2]>,
    alpha: Vec<[f64; 2]>,
    radius: f64,
}

impl PlaneWarp {
    fn fit(centres: &[[f64; 2]], disp: &[[f64; 2]], radius: f64) -> Result<PlaneWarp> {
        let n = centres.len();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let d = (centres[i][0] - centres[j][0]).hypot(centres[i][1] - centres[j][1]);
                a[i * n + j] = ctps_c2a(d / radius);
            }
        }
        let mut alpha = vec![[0.0; 2]; n];
        for c in 0..2 {
            let b: Vec<f64> = disp.iter().map(|d| d[c]).collect();
            let x = crate::register::solve_dense(&a, &b, n).ok_or_else(|| {
                Error::params("features", "feature points coincide in the plane; the warp is singular")
            })?;
            for i in 0..n {
                alpha[i][c] = x[i];
            }
        }
        Ok(PlaneWarp { centres: centres.to_vec(), alpha, radius })
    }

    fn displacement(&self, x: f64, y: f64) -> [f64; 2] {
        let mut d = [0.0; 2];
        for (c, a) in self.centres.iter().zip(&self.alpha) {
            let r = (x - c[0]).hypot(y - c[1]);
            if r < self.radius {
                let f = ctps_c2a(r / self.radius);
                d[0] += a[0] * f;
                d[1] += a[1] * f;
            }
        }
        d
    }
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct PlaneAlignReport {
    pub feature_points: usize,
    /// Rotation (radians) applied to each disk to match input 0's boundary.
    pub boundary_rotation: Vec<f64>,
    /// "boundary_shape" (least squares over the 3D boundary curves) or "features".
    pub rotation_rule: String,
    pub warp_steps: Vec<usize>,
    /// Largest plane distance between a feature point and its goal before and after the warp.
    pub max_feature_gap_before: f64,
    pub max_feature_gap_after: f64,
    pub foldovers: usize,
}

/// Whether the boundary loop still runs strictly counter-clockwise once around the circle.
fn boundary_is_monotone(plane: &[Point3], lp: &[u32]) -> bool {
    let n = lp.len();
    let mut turn = 0.0;
    for i in 0..n {
        let (p, q) = (plane[lp[i] as usize], plane[lp[(i + 1) % n] as usize]);
        let d = (p[0] * q[1] - p[1] * q[0]).atan2(p[0] * q[0] + p[1] * q[1]);
        if d <= 0.0 {
            return false;
        }
        turn += d;
    }
    (turn - TAU).abs() < 1e-6
}

/// Moves each feature's points (`features[i][k]`, vertex of feature i in disk k) to their mean by
/// the stepwise CTPS C²a warp of the plane; boundary points are projected back onto the circle
/// after each step; a step that flips a triangle or breaks the boundary order is halved.
pub fn align_features(
    maps: &mut [DiskMap],
    tris: &[&[[u32; 3]]],
    features: &[Vec<u32>],
    steps: usize,
    support_radius: f64,
    progress: &Progress,
) -> Result<(usize, Vec<usize>, f64, f64)> {
    let k_in = maps.len();
    let goals: Vec<Point3> = features
        .iter()
        .map(|f| {
            let s = (0..k_in).fold([0.0; 3], |s, k| add(s, maps[k].plane[f[k] as usize]));
            let mut g = crate::geometry::scale(s, 1.0 / k_in as f64);
            // The mean of points of the closed disk is in the disk; keep a boundary feature on it.
            let r = g[0].hypot(g[1]);
            if r > 1.0 {
                g = lift(g[0] / r, g[1] / r);
            }
            lift(g[0], g[1])
        })
        .collect();
    let gap = |maps: &[DiskMap]| -> f64 {
        features
            .iter()
            .zip(&goals)
            .flat_map(|(f, g)| (0..k_in).map(move |k| (k, f[k], *g)))
            .map(|(k, v, g)| dist(maps[k].plane[v as usize], g))
            .fold(0.0, f64::max)
    };
    let before = gap(maps);
    let mut steps_done = Vec::new();
    for k in 0..k_in {
        progress.fraction(k as f64 / k_in as f64)?;
        let idx: Vec<usize> = features.iter().map(|f| f[k] as usize).collect();
        let done = warp_disk(&mut maps[k], tris[k], &idx, &goals, steps, support_radius, progress)?;
        // Boundary angles follow the moved boundary vertices.
        let m = &mut maps[k];
        for (a, &v) in m.angles.iter_mut().zip(&m.boundary) {
            let p = m.plane[v as usize];
            *a = p[1].atan2(p[0]).rem_euclid(TAU);
        }
        restart_at_min(m);
        steps_done.push(done);
    }
    let after = gap(maps);
    let folds = (0..k_in).map(|k| count_foldovers(&maps[k].plane, tris[k])).sum();
    Ok((folds, steps_done, before, after))
}

/// Warps one disk in `steps` steps moving its feature vertices `idx` from where they are to
/// `goals`; a step that flips a triangle or breaks the boundary order is halved (up to 8 times).
/// Returns the number of steps taken.
fn warp_disk(
    map: &mut DiskMap,
    tris: &[[u32; 3]],
    idx: &[usize],
    goals: &[Point3],
    steps: usize,
    support_radius: f64,
    progress: &Progress,
) -> Result<usize> {
    let start: Vec<Point3> = idx.iter().map(|&v| map.plane[v]).collect();
    let mut on_bnd = vec![false; map.plane.len()];
    for &v in &map.boundary {
        on_bnd[v as usize] = true;
    }
    let mut done = 0;
    let mut todo: Vec<(f64, u32)> = (1..=steps).rev().map(|j| (j as f64 / steps as f64, 0)).collect();
    let mut reached = 0.0;
    while let Some((t, depth)) = todo.pop() {
        progress.check()?;
        let centres: Vec<[f64; 2]> = idx.iter().map(|&v| [map.plane[v][0], map.plane[v][1]]).collect();
        let disp: Vec<[f64; 2]> = start
            .iter()
            .zip(goals)
            .zip(&centres)
            .map(|((&a, &g), &c)| [a[0] + t * (g[0] - a[0]) - c[0], a[1] + t * (g[1] - a[1]) - c[1]])
            .collect();
        let warp = PlaneWarp::fit(&centres, &disp, support_radius)?;
        let moved: Vec<Point3> = map
            .plane
            .iter()
            .enumerate()
            .map(|(v, &p)| {
                let d = warp.displacement(p[0], p[1]);
                let (x, y) = (p[0] + d[0], p[1] + d[1]);
                if on_bnd[v] {
                    let r = x.hypot(y).max(1e-300);
                    lift(x / r, y / r)
                } else {
                    lift(x, y)
                }
            })
            .collect();
        if count_foldovers(&moved, tris) == 0 && boundary_is_monotone(&moved, &map.boundary) {
            map.plane = moved;
            reached = t;
            done += 1;
        } else if depth < 8 {
            todo.push((t, depth + 1));
            todo.push(((reached + t) / 2.0, depth + 1));
        } else {
            break;
        }
    }
    Ok(done)
}
