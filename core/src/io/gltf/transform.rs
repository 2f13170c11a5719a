//! Node transforms: 4×4 column-major matrices (glTF's layout), from `matrix` or TRS.

use super::json::{bad, numbers, Obj};
use crate::error::Result;

/// Column-major: element (row r, column c) is `m[c * 4 + r]`.
pub(super) type Mat4 = [f64; 16];

pub(super) const IDENTITY: Mat4 =
    [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];

pub(super) fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = [0.0; 16];
    for c in 0..4 {
        for r in 0..4 {
            m[c * 4 + r] = (0..4).map(|k| a[k * 4 + r] * b[c * 4 + k]).sum();
        }
    }
    m
}

/// The node's local transform: `matrix` if present, else T·R·S.
pub(super) fn local(node: &Obj, path: &str) -> Result<Mat4> {
    if let Some(m) = numbers::<16>(node, "matrix", path)? {
        return Ok(m);
    }
    let t = numbers::<3>(node, "translation", path)?.unwrap_or([0.0; 3]);
    let q = numbers::<4>(node, "rotation", path)?.unwrap_or([0.0, 0.0, 0.0, 1.0]);
    let s = numbers::<3>(node, "scale", path)?.unwrap_or([1.0; 3]);
    let len = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if len < 1e-12 {
        return Err(bad(format!("{path}.rotation"), "the zero quaternion is not a rotation"));
    }
    let [x, y, z, w] = q.map(|c| c / len);
    // Rotation matrix of the unit quaternion (x, y, z, w), columns scaled by s.
    let r = [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + z * w), 2.0 * (x * z - y * w)],
        [2.0 * (x * y - z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + x * w)],
        [2.0 * (x * z + y * w), 2.0 * (y * z - x * w), 1.0 - 2.0 * (x * x + y * y)],
    ];
    let mut m = IDENTITY;
    for c in 0..3 {
        for row in 0..3 {
            m[c * 4 + row] = r[c][row] * s[c];
        }
    }
    m[12] = t[0];
    m[13] = t[1];
    m[14] = t[2];
    Ok(m)
}

pub(super) fn apply_point(m: &Mat4, p: [f64; 3]) -> [f64; 3] {
    [
        m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12],
        m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13],
        m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14],
    ]
}

/// The upper 3×3 divided by its largest magnitude (a positive factor: same determinant sign,
/// same normal directions). Cofactors and the determinant multiply two or three entries, which
/// overflow to NaN for a finite transform with entries near 1e300 (its normals came out NaN).
fn upper3_scaled(m: &Mat4) -> Mat4 {
    let big = [0, 1, 2, 4, 5, 6, 8, 9, 10].iter().map(|&i| m[i].abs()).fold(0.0f64, f64::max);
    let s = if big > 0.0 && big.is_finite() { 1.0 / big } else { 1.0 };
    m.map(|v| v * s)
}

/// Sign of the determinant of the upper 3×3 (negative: the transform mirrors, so winding must
/// flip), from the scaled matrix so that it does not overflow.
pub(super) fn det3(m: &Mat4) -> f64 {
    let m = upper3_scaled(m);
    m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2])
        + m[8] * (m[1] * m[6] - m[5] * m[2])
}

/// Matrix that maps normals: the cofactor matrix of the upper 3×3 (= det · inverse-transpose),
/// sign-corrected so mirrored transforms keep normals pointing the right way, up to a positive
/// factor (the matrix is scaled first, see [`upper3_scaled`]). Callers normalise.
pub(super) fn normal_matrix(m: &Mat4) -> [[f64; 3]; 3] {
    let sign = if det3(m) < 0.0 { -1.0 } else { 1.0 };
    let m = upper3_scaled(m);
    let a = |r: usize, c: usize| m[c * 4 + r];
    let mut n = [[0.0; 3]; 3];
    for (r, row) in n.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
            *v = sign * (a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1));
        }
    }
    n
}

pub(super) fn apply_normal(n: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    let out = [
        n[0][0] * v[0] + n[0][1] * v[1] + n[0][2] * v[2],
        n[1][0] * v[0] + n[1][1] * v[1] + n[1][2] * v[2],
        n[2][0] * v[0] + n[2][1] * v[1] + n[2][2] * v[2],
    ];
    let len = (out[0] * out[0] + out[1] * out[1] + out[2] * out[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        out.map(|c| c / len)
    } else {
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn trs_rotates_about_z_then_translates() {
        // 90° about +z: quaternion (0, 0, sin 45°, cos 45°). (1, 0, 0) scaled by 2 → (2, 0, 0),
        // rotated → (0, 2, 0), translated by (10, 0, 0) → (10, 2, 0).
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let node = json!({ "translation": [10.0, 0.0, 0.0], "rotation": [0.0, 0.0, h, h], "scale": [2.0, 2.0, 2.0] });
        let m = local(node.as_object().unwrap(), "nodes[0]").unwrap();
        let p = apply_point(&m, [1.0, 0.0, 0.0]);
        for (a, b) in p.iter().zip([10.0, 2.0, 0.0]) {
            assert!((a - b).abs() < 1e-12, "{p:?}");
        }
    }

    #[test]
    fn cofactor_is_inverse_transpose_up_to_scale() {
        // Non-uniform scale (1, 2, 1): a normal (1, 1, 0) maps to direction (1, 1/2, 0).
        let mut m = IDENTITY;
        m[5] = 2.0;
        let n = apply_normal(&normal_matrix(&m), [1.0, 1.0, 0.0]);
        let e = 1.0 / 1.25f64.sqrt();
        assert!((n[0] - e).abs() < 1e-12 && (n[1] - e / 2.0).abs() < 1e-12 && n[2].abs() < 1e-12, "{n:?}");
        // A mirror keeps the normal of the mirrored plane pointing along the mirrored direction.
        let mut mirror = IDENTITY;
        mirror[0] = -1.0;
        assert!(det3(&mirror) < 0.0);
        assert_eq!(apply_normal(&normal_matrix(&mirror), [1.0, 0.0, 0.0]), [-1.0, 0.0, 0.0]);
    }
}
