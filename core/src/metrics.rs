//! Quality measures reported by the jobs: triangle angles, flipped faces, displacement, relative
//! volume/area change, mean curvature.

use rayon::prelude::*;
use serde::Serialize;

use crate::error::Result;
use crate::geometry::{add, corner_angle, cross, dist, dot, norm, sub};
use crate::job::Progress;
use crate::laplacian::Operator;
use crate::mesh::{Faces, Point3};

/// Angle statistics over the (fan-triangulated) faces, in degrees.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq)]
pub struct AngleStats {
    /// Smallest angle of any triangle.
    pub min: f64,
    /// Mean over triangles of each triangle's smallest angle (the mean of *all* angles of a
    /// triangle is always 60°, so this is the informative mean).
    pub mean_min: f64,
    /// Largest angle of any triangle.
    pub max: f64,
}

pub fn angle_stats(positions: &[Point3], faces: &Faces) -> AngleStats {
    let tris = crate::shapes::fan_triangles(faces);
    if tris.is_empty() {
        return AngleStats::default();
    }
    let (mn, sum, mx) = tris
        .par_iter()
        .with_min_len(4096)
        .map(|t| {
            let p = [positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]];
            let a = [
                corner_angle(p[0], p[1], p[2]),
                corner_angle(p[1], p[2], p[0]),
                corner_angle(p[2], p[0], p[1]),
            ];
            let lo = a[0].min(a[1]).min(a[2]);
            let hi = a[0].max(a[1]).max(a[2]);
            (lo, lo, hi)
        })
        .reduce(|| (f64::INFINITY, 0.0, 0.0), |x, y| (x.0.min(y.0), x.1 + y.1, x.2.max(y.2)));
    AngleStats {
        min: mn.to_degrees(),
        mean_min: (sum / tris.len() as f64).to_degrees(),
        max: mx.to_degrees(),
    }
}

/// Newell normal of a polygon (twice its vector area).
pub fn face_normal(positions: &[Point3], face: &[u32]) -> Point3 {
    let mut n = [0.0; 3];
    for k in 0..face.len() {
        let a = positions[face[k] as usize];
        let b = positions[face[(k + 1) % face.len()] as usize];
        n = add(n, cross(a, b));
    }
    n
}

/// Faces whose normal turned by more than 90° between `before` and `after`.
pub fn flipped_faces(before: &[Point3], after: &[Point3], faces: &Faces) -> usize {
    (0..faces.len())
        .into_par_iter()
        .with_min_len(4096)
        .filter(|&f| dot(face_normal(before, faces.get(f)), face_normal(after, faces.get(f))) < 0.0)
        .count()
}

/// (max, mean) vertex displacement.
pub fn displacement(before: &[Point3], after: &[Point3]) -> (f64, f64) {
    if before.is_empty() {
        return (0.0, 0.0);
    }
    let (mx, sum) = before
        .par_iter()
        .zip(after)
        .with_min_len(8192)
        .map(|(a, b)| {
            let d = dist(*a, *b);
            (d, d)
        })
        .reduce(|| (0.0, 0.0), |x, y| (x.0.max(y.0), x.1 + y.1));
    (mx, sum / before.len() as f64)
}

/// Signed volume of the cone from `apex` over the faces (for a closed mesh: the enclosed volume,
/// independent of the apex; for an open one, the apex makes it translation-invariant).
pub fn volume_about(positions: &[Point3], faces: &Faces, apex: Point3) -> f64 {
    let v: f64 = (0..faces.len())
        .into_par_iter()
        .with_min_len(8192)
        .map(|fi| {
            let f = faces.get(fi);
            let a = sub(positions[f[0] as usize], apex);
            let mut s = 0.0;
            for k in 1..f.len().saturating_sub(1) {
                let b = sub(positions[f[k] as usize], apex);
                let c = sub(positions[f[k + 1] as usize], apex);
                s += dot(a, cross(b, c));
            }
            s
        })
        .sum();
    v / 6.0
}

pub fn area(positions: &[Point3], faces: &Faces) -> f64 {
    (0..faces.len())
        .into_par_iter()
        .with_min_len(8192)
        .map(|f| 0.5 * norm(face_normal(positions, faces.get(f))))
        .sum()
}

/// Relative signed change (after − before) / |before|, 0 when before is 0.
pub fn relative_change(before: f64, after: f64) -> f64 {
    if before == 0.0 {
        0.0
    } else {
        (after - before) / before.abs()
    }
}

/// Mass-weighted mean of |H| over the vertices not in `skip` (boundary vertices have no
/// meaningful curvature normal), with `|H| = |(M⁻¹ S x)_i| / 2` from a cotangent operator with
/// an area scale (`Operator::scale` = mass).
pub fn mean_curvature(op: &Operator, positions: &[Point3], skip: &[bool]) -> f64 {
    let x = positions.as_flattened();
    let mut y = vec![0.0; x.len()];
    op.stiffness.mul_vec(x, &mut y, 3);
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..positions.len() {
        if skip[i] || op.locked[i] {
            continue;
        }
        let m = op.scale[i];
        let h = norm([y[3 * i], y[3 * i + 1], y[3 * i + 2]]) / (2.0 * m);
        num += m * h;
        den += m;
    }
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

/// Quality measures of one state of a surface (see [`compare`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct SurfaceQuality {
    pub area: f64,
    /// Signed cone volume from the apex (see [`volume_about`]).
    pub volume: f64,
    pub angles: AngleStats,
    /// Mass-weighted mean |H| from the cotangent operator with Voronoi mass (see [`mean_curvature`]);
    /// `None` when it was not asked for (it needs per-vertex accumulators: the costly part).
    pub mean_curvature: Option<f64>,
}

/// A surface before and after a deformation of its vertices (same faces).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Comparison {
    pub before: SurfaceQuality,
    pub after: SurfaceQuality,
    /// See [`flipped_faces`].
    pub flipped_faces: usize,
}

/// Everything the smooth report measures on the surface, before and after, in one pass over the
/// triangles: area, cone volume from `apex`, angle statistics, flipped faces and the mean
/// curvature (boundary vertices in `skip` excluded). Equal, up to rounding, to [`area`],
/// [`volume_about`], [`angle_stats`], [`flipped_faces`] and [`mean_curvature`] on a cotangent
/// operator with Voronoi mass, which cost two stencil builds and six passes; those remain the
/// reference (and the path for polygon meshes).
pub fn compare(
    before: &[Point3],
    after: &[Point3],
    faces: &Faces,
    apex: Point3,
    skip: &[bool],
    curvature: bool,
    progress: &Progress,
) -> Result<Comparison> {
    let Some(tris) = faces.as_triangles() else {
        return compare_reference(before, after, faces, apex, skip, curvature, progress);
    };
    let n = before.len();
    let nt = tris.len() / 3;
    // One chunk of triangles per thread, each with its own per-vertex accumulators (scatter
    // without atomics); few chunks so the accumulators stay a small multiple of the mesh.
    let chunks = if nt >= 50_000 { rayon::current_num_threads().clamp(1, 4) } else { 1 };
    let per = nt.div_ceil(chunks).max(1);
    let parts: Vec<(TriAcc, TriAcc, usize)> = tris
        .par_chunks(3 * per)
        .map(|t| {
            let (mut a, mut b) = (TriAcc::new(n, curvature), TriAcc::new(n, curvature));
            let mut flipped = 0;
            // A chunk is a quarter of the mesh or more: poll within it.
            for block in t.chunks(3 * POLL_TRIANGLES) {
                progress.check()?;
                for t in block.chunks_exact(3) {
                    let c0 = a.add(before, t, apex);
                    let c1 = b.add(after, t, apex);
                    flipped += (dot(c0, c1) < 0.0) as usize;
                }
            }
            Ok((a, b, flipped))
        })
        .collect::<Result<_>>()?;
    let mut it = parts.into_iter();
    let Some((mut a, mut b, mut flipped)) = it.next() else {
        return Ok(Comparison::default());
    };
    for (pa, pb, f) in it {
        a.merge(pa);
        b.merge(pb);
        flipped += f;
    }
    progress.check()?;
    Ok(Comparison { before: a.finish(nt, skip), after: b.finish(nt, skip), flipped_faces: flipped })
}

/// Triangles [`compare`] measures between two polls of `progress.check()` (~1 ms).
const POLL_TRIANGLES: usize = 8192;

fn compare_reference(
    before: &[Point3],
    after: &[Point3],
    faces: &Faces,
    apex: Point3,
    skip: &[bool],
    curvature: bool,
    progress: &Progress,
) -> Result<Comparison> {
    let curvature_of = |x: &[Point3]| -> Option<f64> {
        curvature.then(|| {
            crate::laplacian::operator(
                x,
                faces,
                crate::laplacian::OperatorKind::Cotan,
                crate::laplacian::MassKind::Voronoi,
            )
            .map(|op| mean_curvature(&op, x, skip))
            .unwrap_or(f64::NAN)
        })
    };
    // One parallel pass per measure (each a few ms on 100k polygons): poll between them.
    let state = |x: &[Point3]| -> Result<SurfaceQuality> {
        let area = area(x, faces);
        progress.check()?;
        let volume = volume_about(x, faces, apex);
        progress.check()?;
        let angles = angle_stats(x, faces);
        progress.check()?;
        Ok(SurfaceQuality { area, volume, angles, mean_curvature: curvature_of(x) })
    };
    let (b, a) = rayon::join(|| state(before), || state(after));
    let (b, a) = (b?, a?);
    Ok(Comparison { before: b, after: a, flipped_faces: flipped_faces(before, after, faces) })
}

/// `atan(x)` for `x ≥ 0` (Cephes `atan`: range reduction to |x| ≤ 0.66 and a 4/5 rational
/// approximation, relative error ~2e-16), about three times cheaper than libm's correctly
/// rounded `atan2` in the report's one-per-triangle angle.
#[inline]
fn atan_nonneg(x: f64) -> f64 {
    const T3P8: f64 = 2.414_213_562_373_095; // tan(3π/8)
    const MOREBITS: f64 = 6.123_233_995_736_766e-17;
    let (base, t, extra) = if x > T3P8 {
        (std::f64::consts::FRAC_PI_2, -1.0 / x, MOREBITS)
    } else if x <= 0.66 {
        (0.0, x, 0.0)
    } else {
        (std::f64::consts::FRAC_PI_4, (x - 1.0) / (x + 1.0), 0.5 * MOREBITS)
    };
    let z = t * t;
    let p = (((-8.750_608_600_031_904e-1 * z - 1.615_753_718_733_365e1) * z - 7.500_855_792_314_705e1) * z
        - 1.228_866_684_490_136e2)
        * z
        - 6.485_021_904_942_025e1;
    let q = ((((z + 2.485_846_490_142_306e1) * z + 1.650_270_098_316_988_5e2) * z + 4.328_810_604_912_903e2)
        * z
        + 4.853_903_996_359_137e2)
        * z
        + 1.945_506_571_482_614e2;
    base + (t * (z * p / q) + t) + extra
}

/// Per-chunk sums of [`compare`] for one state.
struct TriAcc {
    twice_area: f64,
    volume6: f64,
    /// Largest / smallest cotangent key of any corner (smallest / largest angle), see `cot_key`.
    max_cot: f64,
    min_cot: f64,
    sum_min_angle: f64,
    /// Per vertex: (S x) and the Voronoi mass; empty when the curvature is not wanted.
    hm: Vec<[f64; 4]>,
    curvature: bool,
}

/// Monotone decreasing in the corner angle `atan2(t, d)` (t = |u×v| ≥ 0, d = u·v): its cotangent,
/// ±∞ for the flat angles of a degenerate triangle (0 when d ≥ 0, π when d < 0).
#[inline]
fn cot_key(d: f64, t: f64) -> f64 {
    if t > 0.0 {
        d / t
    } else if d < 0.0 {
        f64::NEG_INFINITY
    } else {
        f64::INFINITY
    }
}

impl TriAcc {
    fn new(n: usize, curvature: bool) -> TriAcc {
        TriAcc {
            twice_area: 0.0,
            volume6: 0.0,
            max_cot: f64::NEG_INFINITY,
            min_cot: f64::INFINITY,
            sum_min_angle: 0.0,
            hm: if curvature { vec![[0.0; 4]; n] } else { Vec::new() },
            curvature,
        }
    }

    /// Adds triangle `t` of state `x`; returns its (unnormalised) normal.
    #[inline]
    fn add(&mut self, x: &[Point3], t: &[u32], apex: Point3) -> Point3 {
        let (i, j, k) = (t[0] as usize, t[1] as usize, t[2] as usize);
        let p = [x[i], x[j], x[k]];
        let (e01, e02, e12) = (sub(p[1], p[0]), sub(p[2], p[0]), sub(p[2], p[1]));
        let c = cross(e01, e02);
        let tw = norm(c);
        self.twice_area += tw;
        self.volume6 += dot(sub(p[0], apex), cross(sub(p[1], apex), sub(p[2], apex)));
        // u·v at each corner; the common |u×v| is `tw`. The smallest angle has the largest dot.
        let d = [dot(e01, e02), -dot(e01, e12), dot(e02, e12)];
        let (dmax, dmin) = (d[0].max(d[1]).max(d[2]), d[0].min(d[1]).min(d[2]));
        // The smallest angle is at most 60°, so its dot is positive unless the triangle collapsed.
        self.sum_min_angle += if dmax > 0.0 { atan_nonneg(tw / dmax) } else { tw.atan2(dmax) };
        self.max_cot = self.max_cot.max(cot_key(dmax, tw));
        self.min_cot = self.min_cot.min(cot_key(dmin, tw));
        if !self.curvature {
            return c;
        }
        // Cotangent Laplacian (S x) and Voronoi mass: `laplacian::triangle_terms` from the dots
        // already at hand (cot_q = d_q / tw; same degeneracy rule and Voronoi split).
        let l2 = [dot(e12, e12), dot(e02, e02), dot(e01, e01)]; // edge opposite corner q
        let lmax2 = l2[0].max(l2[1]).max(l2[2]);
        let area = 0.5 * tw;
        let v = [i, j, k];
        if !(tw > crate::laplacian::DEGENERATE_SHAPE * lmax2) {
            for q in 0..3 {
                self.hm[v[q]][3] += area / 3.0;
            }
            return c;
        }
        let inv = 1.0 / tw;
        let cot = [d[0] * inv, d[1] * inv, d[2] * inv];
        let obtuse = dmin < 0.0;
        for q in 0..3 {
            let (a, b) = ((q + 1) % 3, (q + 2) % 3);
            // ½Σ cot(opposite)·(x_q − x_other) over the two edges at corner q.
            let (wa, wb) = (0.5 * cot[b], 0.5 * cot[a]);
            let (da, db) = (sub(p[q], p[a]), sub(p[q], p[b]));
            let vor = if obtuse {
                if cot[q] < 0.0 {
                    area / 2.0
                } else {
                    area / 4.0
                }
            } else {
                (l2[a] * cot[a] + l2[b] * cot[b]) / 8.0
            };
            let h = &mut self.hm[v[q]];
            h[0] += wa * da[0] + wb * db[0];
            h[1] += wa * da[1] + wb * db[1];
            h[2] += wa * da[2] + wb * db[2];
            h[3] += vor;
        }
        c
    }

    fn merge(&mut self, o: TriAcc) {
        self.twice_area += o.twice_area;
        self.volume6 += o.volume6;
        self.max_cot = self.max_cot.max(o.max_cot);
        self.min_cot = self.min_cot.min(o.min_cot);
        self.sum_min_angle += o.sum_min_angle;
        for (a, b) in self.hm.iter_mut().zip(&o.hm) {
            for r in 0..4 {
                a[r] += b[r];
            }
        }
    }

    fn finish(&self, triangles: usize, skip: &[bool]) -> SurfaceQuality {
        let angles = if triangles == 0 {
            AngleStats::default()
        } else {
            AngleStats {
                min: 1f64.atan2(self.max_cot).to_degrees(),
                mean_min: (self.sum_min_angle / triangles as f64).to_degrees(),
                max: 1f64.atan2(self.min_cot).to_degrees(),
            }
        };
        // Locking as the operator does (`laplacian::lock_degenerate`): mass ≤ 1e-12 × mean.
        let (sum, cnt) =
            self.hm.iter().filter(|h| h[3] > 0.0).fold((0.0, 0usize), |(s, c), h| (s + h[3], c + 1));
        let lock = if cnt > 0 { crate::laplacian::LOCK_RELATIVE * sum / cnt as f64 } else { 0.0 };
        let (mut num, mut den) = (0.0, 0.0);
        for (h, &s) in self.hm.iter().zip(skip) {
            if s || !(h[3] > lock) || !h[3].is_finite() {
                continue;
            }
            num += 0.5 * norm([h[0], h[1], h[2]]);
            den += h[3];
        }
        SurfaceQuality {
            area: 0.5 * self.twice_area,
            volume: self.volume6 / 6.0,
            angles,
            mean_curvature: self.curvature.then_some(if den > 0.0 { num / den } else { 0.0 }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laplacian::{operator, MassKind, OperatorKind};
    use crate::shapes::{grid, icosphere};

    #[test]
    fn equilateral_angles_and_no_flips() {
        let m = crate::shapes::triangle_grid(4, 4, 1.0);
        let a = angle_stats(&m.positions, &m.faces);
        assert!(
            (a.min - 60.0).abs() < 1e-9 && (a.mean_min - 60.0).abs() < 1e-9 && (a.max - 60.0).abs() < 1e-9
        );
        assert_eq!(flipped_faces(&m.positions, &m.positions, &m.faces), 0);
        let mut q = m.positions.clone();
        for p in &mut q {
            p[0] = -p[0]; // mirror: every face flips
        }
        assert_eq!(flipped_faces(&m.positions, &q, &m.faces), m.face_count());
    }

    #[test]
    fn sphere_mean_curvature_is_one_over_r() {
        let r = 2.0;
        let m = icosphere(4, r);
        let op = operator(&m.positions, &m.faces, OperatorKind::Cotan, MassKind::Voronoi).unwrap();
        let h = mean_curvature(&op, &m.positions, &vec![false; m.vertex_count()]);
        assert!((h - 1.0 / r).abs() < 0.01 / r, "{h}");
        let v = volume_about(&m.positions, &m.faces, [5.0, 1.0, 0.0]);
        let v0 = crate::geometry::signed_volume(&m.positions, &m.faces);
        assert!((v - v0).abs() < 1e-12 * v0);
        let g = grid(2, 2, 1.0, true);
        assert!((area(&g.positions, &g.faces) - 4.0).abs() < 1e-15);
        assert_eq!(displacement(&g.positions, &g.positions), (0.0, 0.0));
    }

    /// Hand-known values on the unit right-triangle grid: every triangle is 45-45-90.
    #[test]
    fn fused_comparison_on_a_right_triangle_grid() {
        for quads in [false, true] {
            let g = grid(3, 3, 1.0, quads);
            let mut mirrored = g.positions.clone();
            for p in &mut mirrored {
                p[0] = -p[0];
            }
            let skip = vec![false; g.vertex_count()];
            let q =
                compare(&g.positions, &mirrored, &g.faces, [0.0, 0.0, 1.0], &skip, true, &Progress::new())
                    .unwrap();
            for s in [q.before, q.after] {
                assert!((s.area - 9.0).abs() < 1e-12, "{s:?}");
                assert!((s.volume.abs() - 3.0).abs() < 1e-12, "cone of height 1 over area 9: {s:?}");
                assert!((s.angles.min - 45.0).abs() < 1e-12 && (s.angles.max - 90.0).abs() < 1e-12);
                assert!((s.angles.mean_min - 45.0).abs() < 1e-12);
            }
            assert_eq!(q.flipped_faces, g.face_count(), "mirroring flips every face");
            assert!((q.before.volume + q.after.volume).abs() < 1e-12, "mirroring flips the sign");
        }
    }

    #[test]
    fn fused_comparison_of_a_flat_sheet_has_zero_interior_curvature() {
        let g = crate::shapes::triangle_grid(6, 6, 0.5);
        let st =
            crate::laplacian::Stencil::new(&g.faces, g.vertex_count(), crate::laplacian::PairLayout::Edges)
                .unwrap();
        let boundary = st.boundary_vertices();
        assert_eq!(boundary.iter().filter(|b| **b).count(), 20, "the 6×6 sheet's rim");
        let q = compare(&g.positions, &g.positions, &g.faces, [0.0; 3], &boundary, true, &Progress::new())
            .unwrap();
        assert!(q.before.mean_curvature.unwrap().abs() < 1e-12, "{q:?}");
        assert!((q.before.angles.min - 60.0).abs() < 1e-12 && (q.before.angles.max - 60.0).abs() < 1e-12);
        assert_eq!(q.flipped_faces, 0);
    }

    /// The fused pass against the separate reference functions on a bumpy sphere large enough
    /// for the chunked (multi-accumulator) path, plus one collinear and one collapsed triangle.
    #[test]
    fn fused_comparison_equals_the_reference_measures() {
        let m = icosphere(6, 2.0);
        assert!(m.face_count() >= 50_000);
        let bump = |p: &Point3, s: f64| {
            let f = 1.0 + s * (3.0 * p[0]).sin() * (2.0 * p[1]).cos() + 0.02 * (17.0 * p[2]).sin();
            [p[0] * f, p[1] * f, p[2] * f]
        };
        let x0: Vec<Point3> = m.positions.iter().map(|p| bump(p, 0.1)).collect();
        let x1: Vec<Point3> = m.positions.iter().map(|p| bump(p, -0.05)).collect();
        let mut skip = vec![false; x0.len()];
        skip[3] = true;
        let apex = [0.3, -0.2, 0.1];
        let q = compare(&x0, &x1, &m.faces, apex, &skip, true, &Progress::new()).unwrap();
        // Without curvature: the same triangle measures, no curvature.
        let lean = compare(&x0, &x1, &m.faces, apex, &skip, false, &Progress::new()).unwrap();
        assert_eq!((lean.before.mean_curvature, lean.after.mean_curvature), (None, None));
        assert_eq!((lean.before.area, lean.after.volume), (q.before.area, q.after.volume));
        assert_eq!((lean.before.angles, lean.flipped_faces), (q.before.angles, q.flipped_faces));
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-11 * b.abs().max(1e-300);
        for (s, x) in [(q.before, &x0), (q.after, &x1)] {
            assert!(close(s.area, area(x, &m.faces)));
            assert!(close(s.volume, volume_about(x, &m.faces, apex)));
            let a = angle_stats(x, &m.faces);
            assert!(
                close(s.angles.min, a.min)
                    && close(s.angles.mean_min, a.mean_min)
                    && close(s.angles.max, a.max)
            );
            let op = operator(x, &m.faces, OperatorKind::Cotan, MassKind::Voronoi).unwrap();
            let h = s.mean_curvature.unwrap();
            assert!(close(h, mean_curvature(&op, x, &skip)), "{} {}", h, mean_curvature(&op, x, &skip));
        }
        assert_eq!(q.flipped_faces, flipped_faces(&x0, &x1, &m.faces));
        // Degenerate triangles: a collinear one (angles 0, 0, 180) and a collapsed one (all 0).
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mut f = Faces::new();
        f.push(&[0, 1, 2], 0);
        f.push(&[0, 1, 3], 0);
        let q = compare(&p, &p, &f, [0.0; 3], &[false; 4], true, &Progress::new()).unwrap();
        let a = angle_stats(&p, &f);
        assert_eq!((q.before.angles.min, q.before.angles.max), (0.0, 180.0));
        assert!(close(q.before.angles.mean_min, a.mean_min) && a.min == 0.0 && a.max == 180.0);
    }

    #[test]
    fn fast_atan_matches_libm() {
        let mut worst = 0.0f64;
        for k in 0..=200_000 {
            let x = k as f64 * 1e-4; // 0 … 20, across the three reduction ranges
            worst = worst.max((atan_nonneg(x) - x.atan()).abs());
        }
        for x in [1e-300, 1e-8, 0.66, 0.660_000_1, 2.414_213_562_373_095, 1e8, 1e300, f64::INFINITY] {
            worst = worst.max((atan_nonneg(x) - x.atan()).abs());
        }
        assert!(worst < 5e-16, "{worst}");
    }
}
