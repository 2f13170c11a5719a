//! Untangling a planar patch by minimising a barrier energy (Garanzha, Kaporin, Kudryavtseva,
//! Protais, Ray, Sokolov, "Foldover-free maps in 50 lines of code", 2021), for the patches a
//! convex-combination map cannot untangle: fixed vertices inside (curve and chain vertices) and a
//! boundary that is not convex.
//!
//! Each triangle t has a reference shape (its own 3D shape laid flat, or an equilateral triangle
//! of the same area when that shape is a sliver); J_t maps the reference to the current 2D
//! triangle. The energy Σ (1−θ)·tr(JᵀJ)/χ(det J) + θ·(det²J + 1)/χ(det J), with
//! χ(D, ε) = (D + √(ε² + D²))/2, is finite for folded triangles while ε > 0 and becomes a barrier
//! as ε → 0; ε is lowered by the paper's rule after each round of minimisation. The minimisation
//! here is vertex by vertex (block Gauss–Seidel: a damped Newton step per free vertex, derivatives
//! by central differences), which for the few hundred vertices of a patch is simple and fast
//! enough; a round is a few sweeps.

use crate::geometry::dot;

/// Weight of the area term.
const THETA: f64 = 1.0 / 128.0;

/// A triangle of the patch: its corners (patch indices) and the inverse of its reference edge
/// matrix (columns: reference edges 0→1, 0→2 in 2D).
pub(super) struct RefTri {
    pub c: [usize; 3],
    pub inv: [[f64; 2]; 2],
}

impl RefTri {
    /// Reference from 3D corner positions: the triangle laid flat, or an equilateral one of the same
    /// area (`min_area` at least) when its smallest angle is below ~10°.
    pub fn new(c: [usize; 3], p: [[f64; 3]; 3], min_area: f64) -> RefTri {
        let e1 = sub3(p[1], p[0]);
        let e2 = sub3(p[2], p[0]);
        let l1 = dot(e1, e1).sqrt();
        let cr = crate::geometry::cross(e1, e2);
        let area2 = dot(cr, cr).sqrt();
        let q = super::super::smooth::min_angle_quality(p[0], p[1], p[2]);
        let (a, b) = if l1 > 0.0 && q > 0.03 && area2 > 2.0 * min_area {
            // Flat: e1 along x, e2 at (e1·e2/l1, |e1×e2|/l1).
            ([l1, 0.0], [dot(e1, e2) / l1, area2 / l1])
        } else {
            let area = (0.5 * area2).max(min_area);
            let s = (4.0 * area / 3f64.sqrt()).sqrt();
            ([s, 0.0], [0.5 * s, 0.5 * 3f64.sqrt() * s])
        };
        // Inverse of [[a0, b0], [a1, b1]].
        let det = a[0] * b[1] - b[0] * a[1];
        RefTri { c, inv: [[b[1] / det, -b[0] / det], [-a[1] / det, a[0] / det]] }
    }

    /// det J and tr(JᵀJ) for 2D corner positions.
    fn jac(&self, x: &[[f64; 2]]) -> (f64, f64) {
        let (p0, p1, p2) = (x[self.c[0]], x[self.c[1]], x[self.c[2]]);
        let d = [[p1[0] - p0[0], p2[0] - p0[0]], [p1[1] - p0[1], p2[1] - p0[1]]];
        let m = self.inv;
        let j = [
            [d[0][0] * m[0][0] + d[0][1] * m[1][0], d[0][0] * m[0][1] + d[0][1] * m[1][1]],
            [d[1][0] * m[0][0] + d[1][1] * m[1][0], d[1][0] * m[0][1] + d[1][1] * m[1][1]],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let tr = j[0][0] * j[0][0] + j[0][1] * j[0][1] + j[1][0] * j[1][0] + j[1][1] * j[1][1];
        (det, tr)
    }

    fn energy(&self, x: &[[f64; 2]], eps: f64) -> f64 {
        let (det, tr) = self.jac(x);
        let chi = 0.5 * (det + (eps * eps + det * det).sqrt());
        ((1.0 - THETA) * tr + THETA * (det * det + 1.0)) / chi
    }
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn chi(d: f64, eps: f64) -> f64 {
    0.5 * (d + (eps * eps + d * d).sqrt())
}

/// Minimises the energy over the `free` vertices of `x` (2D positions) in place; `tris_of[v]`:
/// the triangles at patch vertex v. Returns the smallest det J at the end (> 0: no fold in 2D).
pub(super) fn untangle_2d(
    x: &mut [[f64; 2]],
    free: &[bool],
    tris: &[RefTri],
    tris_of: &[Vec<usize>],
    scale: f64,
    rounds: usize,
) -> f64 {
    let total = |x: &[[f64; 2]], eps: f64| tris.iter().map(|t| t.energy(x, eps)).sum::<f64>();
    let det_min = |x: &[[f64; 2]]| tris.iter().map(|t| t.jac(x).0).fold(f64::INFINITY, f64::min);
    let mut dmin = det_min(x);
    let mut eps = if dmin > 0.0 { 1e-10 } else { 1.0f64.max(-2.0 * dmin) };
    let mut e_prev = total(x, eps);
    let h = 1e-6 * scale;
    for _ in 0..rounds {
        for _sweep in 0..4 {
            for v in 0..x.len() {
                if free[v] {
                    newton_vertex(x, v, &tris_of[v], tris, eps, h);
                }
            }
        }
        dmin = det_min(x);
        let e = total(x, eps);
        if dmin > 0.0 && eps <= 1e-9 {
            break;
        }
        let sigma = (1.0 - e / e_prev).max(0.1);
        let mu = (1.0 - sigma) * chi(dmin, eps);
        eps = if dmin < mu { (2.0 * (mu * (mu - dmin)).sqrt()).max(1e-10) } else { 1e-10 };
        e_prev = total(x, eps);
    }
    dmin
}

/// One damped Newton step for vertex `v` on the energy of its triangles (derivatives by central
/// differences with step `h`), backtracking until the energy decreases.
fn newton_vertex(x: &mut [[f64; 2]], v: usize, own: &[usize], tris: &[RefTri], eps: f64, h: f64) {
    let e_at = |x: &mut [[f64; 2]], p: [f64; 2]| {
        let keep = x[v];
        x[v] = p;
        let e = own.iter().map(|&t| tris[t].energy(x, eps)).sum::<f64>();
        x[v] = keep;
        e
    };
    let p = x[v];
    let e0 = e_at(x, p);
    if !e0.is_finite() {
        return;
    }
    let ex = [e_at(x, [p[0] + h, p[1]]), e_at(x, [p[0] - h, p[1]])];
    let ey = [e_at(x, [p[0], p[1] + h]), e_at(x, [p[0], p[1] - h])];
    let exy = [
        e_at(x, [p[0] + h, p[1] + h]),
        e_at(x, [p[0] + h, p[1] - h]),
        e_at(x, [p[0] - h, p[1] + h]),
        e_at(x, [p[0] - h, p[1] - h]),
    ];
    let g = [(ex[0] - ex[1]) / (2.0 * h), (ey[0] - ey[1]) / (2.0 * h)];
    let hxx = (ex[0] - 2.0 * e0 + ex[1]) / (h * h);
    let hyy = (ey[0] - 2.0 * e0 + ey[1]) / (h * h);
    let hxy = (exy[0] - exy[1] - exy[2] + exy[3]) / (4.0 * h * h);
    let det = hxx * hyy - hxy * hxy;
    let gn = (g[0] * g[0] + g[1] * g[1]).sqrt();
    if gn == 0.0 || !gn.is_finite() {
        return;
    }
    let mut d = if hxx > 0.0 && det > 0.0 {
        [-(hyy * g[0] - hxy * g[1]) / det, -(hxx * g[1] - hxy * g[0]) / det]
    } else {
        // Not convex here: a gradient step of a size the diagonal suggests.
        let s = 1.0 / hxx.abs().max(hyy.abs()).max(gn / (1e3 * h));
        [-g[0] * s, -g[1] * s]
    };
    for _ in 0..30 {
        let q = [p[0] + d[0], p[1] + d[1]];
        if e_at(x, q) < e0 {
            x[v] = q;
            return;
        }
        d = [0.5 * d[0], 0.5 * d[1]];
    }
}
