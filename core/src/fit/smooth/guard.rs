//! The flows' guard ([`super`]'s module doc): a step is kept where it turns no face over (against
//! its normal before the step, or before smoothing) and makes no face worse below the angle floor;
//! a failing step is halved, and given up after [`MAX_HALVINGS`] halvings.

use rayon::prelude::*;

use crate::geometry::{add, cross, dot, norm2, scale, sub};
use crate::mesh::Point3;

use super::{longer_edges_product, Rings, SmoothStats, MAX_HALVINGS};

/// Normal (unnormalised) and [`min_angle_quality`] of a face, sharing the edge vectors.
pub(super) fn face_shape(pos: &[Point3], t: [u32; 3]) -> (Point3, f64) {
    let (a, b, c) = (pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
    let (ab, ac) = (sub(b, a), sub(c, a));
    let n = cross(ab, ac);
    let (la, lb, lc) = (norm2(sub(c, b)), norm2(ac), norm2(ab));
    let prod = longer_edges_product(la, lb, lc);
    (n, if prod > 0.0 { norm2(n) / prod } else { 0.0 })
}

/// The flows' guard: what it tests a step against, and what it did.
pub(super) struct Guard<'a> {
    pub tris: &'a [[u32; 3]],
    pub r: &'a Rings,
    /// The smallest-angle quality a worsening face may reach (module doc).
    pub q_floor: f64,
    /// Each face's normal before smoothing.
    pub start: Vec<Point3>,
    /// Each face's normal and quality at the current positions.
    pub shape: Vec<(Point3, f64)>,
    /// The same at the candidate positions (swapped with `shape` after each step).
    pub scratch: Vec<(Point3, f64)>,
    pub stats: SmoothStats,
}

impl Guard<'_> {
    /// The positions reached from `old` towards `proposed` where that is safe (see the module
    /// doc); `reproject` puts a halved step back on the surface. Also returns the vertices whose
    /// step was halved and kept (their reference face may need updating).
    pub(super) fn commit(
        &mut self,
        old: &[Point3],
        proposed: Vec<Point3>,
        reproject: impl Fn(usize, Point3) -> Point3 + Sync,
    ) -> (Vec<Point3>, Vec<u32>) {
        let (tris, r, q_floor, start) = (self.tris, self.r, self.q_floor, &self.start);
        let (shape, new_shape, stats) = (&mut self.shape, &mut self.scratch, &mut self.stats);
        let nv = old.len();
        let mut cand = proposed;
        let moves = cand.par_iter().zip(old).with_min_len(4096).filter(|(a, b)| a != b).count();
        stats.moves += moves;
        if moves == 0 {
            return (cand, Vec::new());
        }
        // A relative margin so that the reported angle, computed differently, cannot come out lower.
        let floor = q_floor * (1.0 + 1e-9);
        // Turned over (or degenerate) against its normal before the step or before smoothing (unless
        // it already was before the step), or worse and below the floor.
        let acceptable = |f: usize, (n, q): (Point3, f64), (n_old, q_old): (Point3, f64)| {
            dot(n, n_old) > 0.0
                && (q >= q_old || q >= floor)
                && (dot(n, start[f]) > 0.0 || dot(n_old, start[f]) <= 0.0)
        };
        // One pass over the faces (`shape` holds the old normal and quality of each; a face no corner
        // of which moved comes out the same), listing the failing ones in face order (rayon's collect
        // keeps it, so the halvings below run as after a serial scan).
        let mut bad: Vec<u32> = new_shape
            .par_iter_mut()
            .zip(tris.par_iter().zip(shape.par_iter()))
            .enumerate()
            .with_min_len(4096)
            .filter_map(|(f, (ns, (&t, &before)))| {
                *ns = face_shape(&cand, t);
                (!acceptable(f, *ns, before)).then_some(f as u32)
            })
            .collect();
        let mut halvings = vec![0u8; nv];
        let mut vmark = vec![false; nv];
        let mut fmark = vec![false; tris.len()];
        while !bad.is_empty() {
            // Halve (or give up) the step of every moving corner of a failing face.
            let mut changed: Vec<u32> = Vec::new();
            for &f in &bad {
                for &v in &tris[f as usize] {
                    if cand[v as usize] != old[v as usize] && !vmark[v as usize] {
                        vmark[v as usize] = true;
                        changed.push(v);
                    }
                }
            }
            let mut faces: Vec<u32> = Vec::new();
            for &v in &changed {
                let v = v as usize;
                vmark[v] = false;
                halvings[v] += 1;
                cand[v] = if halvings[v] as u32 > MAX_HALVINGS {
                    old[v]
                } else {
                    reproject(v, scale(add(old[v], cand[v]), 0.5))
                };
                for &f in r.vf.row(v) {
                    if !fmark[f as usize] {
                        fmark[f as usize] = true;
                        faces.push(f);
                    }
                }
            }
            for &f in &faces {
                fmark[f as usize] = false;
            }
            // Re-check the faces around the changed vertices.
            bad = faces
                .into_iter()
                .filter(|&f| {
                    let now = face_shape(&cand, tris[f as usize]);
                    new_shape[f as usize] = now;
                    !acceptable(f as usize, now, shape[f as usize])
                })
                .collect();
        }
        // Every face's last evaluation is at the final positions (a face is re-evaluated whenever a
        // corner changes): the next step's old shapes.
        std::mem::swap(shape, new_shape);
        let mut halved = Vec::new();
        for (v, &h) in halvings.iter().enumerate() {
            if h as u32 > MAX_HALVINGS {
                stats.moves_rejected += 1;
            } else if h > 0 {
                stats.moves_halved += 1;
                halved.push(v as u32);
            }
        }
        (cand, halved)
    }
}
