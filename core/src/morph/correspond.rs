//! Point location on a spherical triangulation and barycentric transfer (seed 002 eq. VI.13–VI.16,
//! seed 003 eq. 3.1–3.2): a point of the sphere is found in a face by walking across edges, then
//! expressed in barycentric coordinates of that face's chord triangle (the ray from the centre
//! through the point hits the chord plane), which carries it to the 3D surface.

use crate::geometry::{add, scale};
use crate::mesh::Point3;

use super::param::orient;

pub struct Locator<'a> {
    pub sphere: &'a [Point3],
    pub tris: &'a [[u32; 3]],
    nbr: Vec<[u32; 3]>,
    rng: u64,
}

impl<'a> Locator<'a> {
    pub fn new(sphere: &'a [Point3], tris: &'a [[u32; 3]], nbr: Vec<[u32; 3]>) -> Self {
        Locator { sphere, tris, nbr, rng: 0x9E37_79B9_7F4A_7C15 }
    }

    fn inside(&self, f: usize, p: Point3) -> Option<usize> {
        let t = self.tris[f];
        for k in 0..3 {
            if orient(self.sphere[t[k] as usize], self.sphere[t[(k + 1) % 3] as usize], p) < 0.0 {
                return Some(k);
            }
        }
        None
    }

    /// The face containing `p` (a unit vector), walking from `hint`. A randomised choice among
    /// the edges `p` lies beyond keeps the walk from cycling; after too many steps every face is
    /// tried (never expected on a valid embedding).
    pub fn locate(&mut self, p: Point3, hint: u32) -> u32 {
        let mut f = (hint as usize).min(self.tris.len().saturating_sub(1));
        let cap = 4 * (self.tris.len() as f64).sqrt() as usize + 64;
        for _ in 0..cap {
            let t = self.tris[f];
            let mut out = [usize::MAX; 3];
            let mut n = 0;
            for k in 0..3 {
                if orient(self.sphere[t[k] as usize], self.sphere[t[(k + 1) % 3] as usize], p) < 0.0 {
                    out[n] = k;
                    n += 1;
                }
            }
            if n == 0 {
                return f as u32;
            }
            self.rng ^= self.rng << 13;
            self.rng ^= self.rng >> 7;
            self.rng ^= self.rng << 17;
            let k = out[(self.rng % n as u64) as usize];
            let g = self.nbr[f][k];
            if g == u32::MAX {
                break;
            }
            f = g as usize;
        }
        // Fallback: the face that contains p, or else the one it is least outside of.
        let mut best = (f64::NEG_INFINITY, 0u32);
        for g in 0..self.tris.len() {
            if self.inside(g, p).is_none() {
                return g as u32;
            }
            let t = self.tris[g];
            let m = (0..3)
                .map(|k| orient(self.sphere[t[k] as usize], self.sphere[t[(k + 1) % 3] as usize], p))
                .fold(f64::INFINITY, f64::min);
            if m > best.0 {
                best = (m, g as u32);
            }
        }
        best.1
    }

    /// Barycentric coordinates of the central projection of `p` on face `f`'s chord plane.
    pub fn barycentric(&self, f: u32, p: Point3) -> [f64; 3] {
        let t = self.tris[f as usize];
        bary_on_chord(self.sphere[t[0] as usize], self.sphere[t[1] as usize], self.sphere[t[2] as usize], p)
    }
}

/// Barycentric coordinates (clamped to ≥ 0, summing to 1) of the point where the ray from the
/// origin through `p` meets the plane of (a, b, c): proportional to det(p, b, c), det(a, p, c),
/// det(a, b, p).
pub fn bary_on_chord(a: Point3, b: Point3, c: Point3, p: Point3) -> [f64; 3] {
    let w = [orient(p, b, c).max(0.0), orient(a, p, c).max(0.0), orient(a, b, p).max(0.0)];
    let s = w[0] + w[1] + w[2];
    if s <= 0.0 {
        return [1.0 / 3.0; 3];
    }
    [w[0] / s, w[1] / s, w[2] / s]
}

pub fn interpolate(pos: &[Point3], t: [u32; 3], w: [f64; 3]) -> Point3 {
    add(
        add(scale(pos[t[0] as usize], w[0]), scale(pos[t[1] as usize], w[1])),
        scale(pos[t[2] as usize], w[2]),
    )
}
