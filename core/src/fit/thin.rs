//! Feet of curve points that lie inside a thin part of the template, between its two sheets near
//! a rim (a flattened ellipsoid's edge, a leaf, an ear).
//!
//! Why: where the template's rim lies *outside* the curves' rim (an automatic alignment a little
//! too large, a warp that overshoots), the curve points at the curves' rim are inside the template,
//! about as far from its upper sheet as from its lower one. Their closest points land on either
//! sheet, neighbouring points on different ones, and each approach level then pulls one sheet down
//! here and the other up there: nothing pulls the rim in, and the fine fit folds it (measured on a
//! flattened ellipsoid 1 × 0.6 × 0.04: the exact template scaled by 1.005 ends with 39 flipped
//! faces, by 0.995 with 1). The point's counterpart on the template is on the rim, in the
//! direction the two sheets open towards: the foot is moved there, so the level pulls the rim in.
//!
//! Rule, for a point `p` whose closest foot `q` (face normal `n`) has `p` on its inner side:
//! - the opposite sheet is the nearest face around `q` facing the other way (normal `n₂`,
//!   `n·n₂ < −1/2`) with `p` on its inner side too, at distance `t`;
//! - `p` is *between the sheets* when `t ≤ 1.5·|p − q|` (a point just under one sheet of a thick
//!   part is not, and keeps its closest point);
//! - the rim is where the sheets open: the ray from `p` along `n + n₂` (if the sheets are not
//!   parallel there) exits the template on the rim; its exit point is the new foot, when it is
//!   within twice the two sheets' distances.

use crate::geometry::{add, cross, dist, dot, norm, normalize, scale, sub, triangle_cross};
use crate::mesh::Point3;
use crate::spatial::closest_on_triangle;

/// `p` is between the sheets when the opposite sheet is at most this × the closest distance.
const BETWEEN_SHEETS: f64 = 1.5;
/// Vertex rings around the foot's face searched for the opposite sheet and the rim.
const RINGS: usize = 3;
/// Below this |n + n₂| the sheets are parallel there: no rim direction.
const MIN_OPENING: f64 = 0.1;
/// The rim is taken when it is at most this × (closest + opposite distance) away.
const MAX_RIM_DISTANCE: f64 = 2.0;

/// A foot: (face, point, distance), as the approach's searches return them.
pub type Foot = (u32, Point3, f64);

fn unit_normal(pos: &[Point3], t: [u32; 3]) -> Point3 {
    normalize(triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]))
}

/// Distance along the ray `o + s·u` (s > 0) to triangle `t`, if it crosses it (Möller–Trumbore).
fn ray_hit(o: Point3, u: Point3, t: [Point3; 3]) -> Option<f64> {
    let (e1, e2) = (sub(t[1], t[0]), sub(t[2], t[0]));
    let h = cross(u, e2);
    let a = dot(e1, h);
    if a.abs() < 1e-300 {
        return None;
    }
    let s = sub(o, t[0]);
    let b1 = dot(s, h) / a;
    if !(-1e-12..=1.0 + 1e-12).contains(&b1) {
        return None;
    }
    let qv = cross(s, e1);
    let b2 = dot(u, qv) / a;
    if b2 < -1e-12 || b1 + b2 > 1.0 + 1e-12 {
        return None;
    }
    let r = dot(e2, qv) / a;
    (r > 0.0).then_some(r)
}

/// Faces within `RINGS` vertex rings of face `f` (into `out`); `stamp` is scratch per vertex.
fn faces_around(
    tris: &[[u32; 3]],
    vf: &[Vec<u32>],
    f: u32,
    stamp: &mut [u32],
    mark: u32,
    out: &mut Vec<u32>,
) {
    out.clear();
    let mut ring: Vec<u32> = tris[f as usize].to_vec();
    for &v in &ring {
        stamp[v as usize] = mark;
    }
    for _ in 0..RINGS {
        let mut next = Vec::new();
        for &v in &ring {
            for &g in &vf[v as usize] {
                out.push(g);
                for &w in &tris[g as usize] {
                    if stamp[w as usize] != mark {
                        stamp[w as usize] = mark;
                        next.push(w);
                    }
                }
            }
        }
        ring = next;
    }
    out.sort_unstable();
    out.dedup();
}

/// Replaces the feet of points between two sheets near a rim by the rim point in the direction
/// the sheets open towards (module doc); `feet[k]` belongs to `points[which[k]]`. Returns how many
/// feet were moved.
pub fn rim_feet(
    pos: &[Point3],
    tris: &[[u32; 3]],
    vf: &[Vec<u32>],
    points: &[Point3],
    which: &[u32],
    feet: &mut [Foot],
) -> usize {
    let mut stamp = vec![u32::MAX; pos.len()];
    let mut faces = Vec::new();
    let mut moved = 0;
    for (k, &i) in which.iter().enumerate() {
        let p = points[i as usize];
        let (f, q, d) = feet[k];
        if !(d > 0.0) {
            continue;
        }
        let n = unit_normal(pos, tris[f as usize]);
        if dot(sub(p, q), n) >= 0.0 {
            continue; // outside: the closest point is right
        }
        faces_around(tris, vf, f, &mut stamp, k as u32, &mut faces);
        let tri = |g: u32| {
            let t = tris[g as usize];
            [pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]]
        };
        let mut opposite: Option<(f64, Point3)> = None;
        for &g in &faces {
            let ng = unit_normal(pos, tris[g as usize]);
            if dot(ng, n) >= -0.5 {
                continue;
            }
            let c = closest_on_triangle(p, &tri(g));
            if dot(sub(p, c), ng) > 0.0 {
                continue;
            }
            let e = dist(p, c);
            if opposite.is_none_or(|o| e < o.0) {
                opposite = Some((e, ng));
            }
        }
        let Some((t, n2)) = opposite else { continue };
        if t > BETWEEN_SHEETS * d {
            continue;
        }
        let opening = add(n, n2);
        if norm(opening) < MIN_OPENING {
            continue;
        }
        let u = normalize(opening);
        let mut exit: Option<(u32, f64)> = None;
        for &g in &faces {
            if dot(unit_normal(pos, tris[g as usize]), u) <= 0.0 {
                continue;
            }
            if let Some(r) = ray_hit(p, u, tri(g)) {
                if exit.is_none_or(|e| r < e.1) {
                    exit = Some((g, r));
                }
            }
        }
        if let Some((g, r)) = exit {
            if r <= MAX_RIM_DISTANCE * (d + t) {
                feet[k] = (g, add(p, scale(u, r)), r);
                moved += 1;
            }
        }
    }
    moved
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A level-4 icosphere squashed to the ellipsoid with semi-axes 0.5 × 0.3 × 0.02 about the origin.
    fn flat() -> (Vec<Point3>, Vec<[u32; 3]>, Vec<Vec<u32>>) {
        let m = crate::shapes::icosphere(4, 0.5);
        let pos: Vec<Point3> = m.positions.iter().map(|p| [p[0], 0.6 * p[1], 0.04 * p[2]]).collect();
        let tris = crate::shapes::fan_triangles(&m.faces);
        let mut vf = vec![Vec::new(); pos.len()];
        for (f, t) in tris.iter().enumerate() {
            for &v in t {
                vf[v as usize].push(f as u32);
            }
        }
        (pos, tris, vf)
    }

    fn closest(pos: &[Point3], tris: &[[u32; 3]], p: Point3) -> Foot {
        let mut best: Option<Foot> = None;
        for (f, t) in tris.iter().enumerate() {
            let q = closest_on_triangle(p, &[pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]]);
            let d = dist(p, q);
            if best.is_none_or(|b| d < b.2) {
                best = Some((f as u32, q, d));
            }
        }
        best.unwrap()
    }

    /// The largest x of the template's surface in the plane y = 0, z = 0 (its rim there), by
    /// intersecting every edge with that line's plane: independent of the code under test.
    fn rim_x(pos: &[Point3], tris: &[[u32; 3]]) -> f64 {
        let mut best = f64::MIN;
        for t in tris {
            for k in 0..3 {
                let (a, b) = (pos[t[k] as usize], pos[t[(k + 1) % 3] as usize]);
                // Where the edge crosses z = 0, if it does near y = 0.
                if (a[2] > 0.0) != (b[2] > 0.0) {
                    let s = a[2] / (a[2] - b[2]);
                    let x = add(a, scale(sub(b, a), s));
                    if x[1].abs() < 0.02 && x[0] > best {
                        best = x[0];
                    }
                }
            }
        }
        best
    }

    #[test]
    fn a_point_inside_the_rim_gets_its_foot_on_the_rim() {
        let (pos, tris, vf) = flat();
        let rim = rim_x(&pos, &tris);
        assert!(rim > 0.45 && rim <= 0.5 + 1e-12, "the case: rim at {rim}");
        // 0.003 inside the rim, a hair above the middle plane: the closest point is on the upper
        // sheet (the case), the rim is 0.003 away along +x.
        let p = [rim - 0.003, 0.0, 1e-4];
        let mut feet = vec![closest(&pos, &tris, p)];
        assert!(feet[0].1[2] > 0.0 && feet[0].2 < 0.003, "the case: closest {:?}", feet[0]);
        let moved = rim_feet(&pos, &tris, &vf, &[p], &[0], &mut feet);
        assert_eq!(moved, 1);
        let (_, q, r) = feet[0];
        // On the rim: ahead of p along +x, on the middle plane's side of the sheets, within the
        // rim's polygon spacing of the rim line found above.
        assert!(q[0] > p[0] && (q[0] - rim).abs() < 0.002, "foot {q:?}, rim at x = {rim}");
        assert!(q[2].abs() < 0.004 && q[1].abs() < 0.01, "foot {q:?}");
        assert!((r - dist(p, q)).abs() < 1e-12);
    }

    #[test]
    fn points_outside_or_under_one_sheet_keep_their_closest_point() {
        let (pos, tris, vf) = flat();
        let rim = rim_x(&pos, &tris);
        let pts = [
            // Outside, beyond the rim.
            [rim + 0.003, 0.0, 0.0],
            // Outside, above the upper sheet.
            [0.0, 0.0, 0.03],
            // Inside, just under the upper sheet in the middle (the lower one 10× farther).
            [0.0, 0.0, 0.018],
        ];
        let mut feet: Vec<Foot> = pts.iter().map(|&p| closest(&pos, &tris, p)).collect();
        let before = feet.clone();
        assert_eq!(rim_feet(&pos, &tris, &vf, &pts, &[0, 1, 2], &mut feet), 0);
        assert_eq!(
            feet.iter().map(|f| f.1).collect::<Vec<_>>(),
            before.iter().map(|f| f.1).collect::<Vec<_>>()
        );
    }
}
