//! Which vertices move and how much: selection, pinned vertices and groups, feature edges,
//! soft weights, boundary mode, locked degenerate vertices; and volume preservation.

use std::collections::HashMap;

use super::params::{BoundaryMode, SmoothParams};
use crate::error::{Error, Result};
use crate::geometry::{dot, norm, scale, sub};
use crate::mesh::{Mesh, Point3};
use crate::metrics::{face_normal, volume_about};

/// Per-vertex freedom, all of length n.
#[derive(Debug, Clone)]
pub struct Freedom {
    /// Vertex may move (selected, not pinned, not locked, weight > 0, not a fixed boundary).
    pub moving: Vec<bool>,
    /// Soft weight in (0, 1] for moving vertices, 0 otherwise.
    pub weight: Vec<f64>,
    pub pinned_count: usize,
    pub feature_vertices: usize,
}

fn check_index(field: &str, i: u32, n: usize) -> Result<usize> {
    if (i as usize) < n {
        Ok(i as usize)
    } else {
        Err(Error::params(field, format!("vertex {i} out of range (mesh has {n} vertices)")))
    }
}

fn group_vertices(mesh: &Mesh, field: &str, names: &[String], mark: &mut [bool]) -> Result<()> {
    for name in names {
        let id = mesh.groups.iter().position(|g| g == name).ok_or_else(|| {
            Error::params(field, format!("no face group named {name:?} (groups: {:?})", mesh.groups))
        })?;
        for (f, face) in mesh.faces.iter().enumerate() {
            if mesh.faces.group(f) as usize == id {
                for &v in face {
                    mark[v as usize] = true;
                }
            }
        }
    }
    Ok(())
}

/// Vertices on edges whose dihedral angle exceeds `degrees` (edges with exactly two faces).
pub fn feature_vertices(mesh: &Mesh, degrees: f64) -> Vec<bool> {
    let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(mesh.faces.indices().len());
    for (f, face) in mesh.faces.iter().enumerate() {
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let e = edges.entry((a.min(b), a.max(b))).or_insert((u32::MAX, u32::MAX));
            if e.0 == u32::MAX {
                e.0 = f as u32;
            } else {
                e.1 = f as u32;
            }
        }
    }
    let cos_limit = degrees.to_radians().cos();
    let mut mark = vec![false; mesh.vertex_count()];
    for ((a, b), (f, g)) in edges {
        if f == u32::MAX || g == u32::MAX {
            continue;
        }
        let nf = face_normal(&mesh.positions, mesh.faces.get(f as usize));
        let ng = face_normal(&mesh.positions, mesh.faces.get(g as usize));
        let (lf, lg) = (norm(nf), norm(ng));
        if lf == 0.0 || lg == 0.0 {
            continue;
        }
        // Dihedral (normal-turn) angle above the limit ⇔ cos below cos_limit.
        if dot(nf, ng) / (lf * lg) < cos_limit {
            mark[a as usize] = true;
            mark[b as usize] = true;
        }
    }
    mark
}

/// Resolves the selection and constraints. `boundary` marks open-boundary vertices, `locked`
/// the operator's degenerate vertices.
pub fn freedom(
    mesh: &Mesh,
    p: &SmoothParams,
    mode: BoundaryMode,
    boundary: &[bool],
    locked: &[bool],
    require_selection: bool,
) -> Result<Freedom> {
    let n = mesh.vertex_count();
    let mut selected = vec![p.region.is_empty() && p.groups.is_empty() && !require_selection; n];
    if require_selection && p.region.is_empty() && p.groups.is_empty() {
        return Err(Error::params(
            "region",
            "fair needs the region to fair: `region` (vertices) or `groups`",
        ));
    }
    for &i in &p.region {
        selected[check_index("region", i, n)?] = true;
    }
    group_vertices(mesh, "groups", &p.groups, &mut selected)?;
    let mut pinned = vec![false; n];
    for &i in &p.pinned {
        pinned[check_index("pinned", i, n)?] = true;
    }
    group_vertices(mesh, "pinned_groups", &p.pinned_groups, &mut pinned)?;
    let pinned_count = pinned.iter().filter(|x| **x).count();
    let mut feature_count = 0;
    if let Some(a) = p.feature_angle {
        let f = feature_vertices(mesh, a);
        feature_count = f.iter().filter(|x| **x).count();
        for (p, f) in pinned.iter_mut().zip(f) {
            *p |= f;
        }
    }
    let weights = match &p.weights {
        None => vec![1.0; n],
        Some(w) => {
            if w.len() != n {
                return Err(Error::params("weights", format!("{} weights for {n} vertices", w.len())));
            }
            if let Some(i) = w.iter().position(|x| !(x.is_finite() && (0.0..=1.0).contains(x))) {
                return Err(Error::params(
                    "weights",
                    format!("weight of vertex {i} is {}, not in [0, 1]", w[i]),
                ));
            }
            w.clone()
        }
    };
    let mut moving = vec![false; n];
    let mut weight = vec![0.0; n];
    for i in 0..n {
        let fixed_boundary = mode == BoundaryMode::Fixed && boundary[i];
        moving[i] = selected[i] && !pinned[i] && !locked[i] && weights[i] > 0.0 && !fixed_boundary;
        if moving[i] {
            weight[i] = weights[i];
        }
    }
    Ok(Freedom { moving, weight, pinned_count, feature_vertices: feature_count })
}

/// Keeps the coordinates not in `axes` at their `before` values.
pub fn apply_axes(x: &mut [Point3], before: &[Point3], axes: [bool; 3]) {
    if axes == [true; 3] {
        return;
    }
    for (p, q) in x.iter_mut().zip(before) {
        for k in 0..3 {
            if !axes[k] {
                p[k] = q[k];
            }
        }
    }
}

/// Rescales the moving vertices about `center` so that the cone volume from `center` equals
/// `target`. With every vertex moving the factor is exact, `(target/V)^(1/3)`; with some fixed
/// the volume is a cubic in the factor, solved by Newton/secant steps. Returns the final
/// relative volume error (0 when nothing could be done, e.g. a zero-volume mesh).
pub fn preserve_volume(mesh: &Mesh, x: &mut [Point3], moving: &[bool], center: Point3, target: f64) -> f64 {
    let vol = |x: &[Point3]| volume_about(x, &mesh.faces, center);
    let v = vol(x);
    if target == 0.0 || v == 0.0 || !v.is_finite() || (v > 0.0) != (target > 0.0) {
        return relative(v, target);
    }
    let base: Vec<Point3> = x.to_vec();
    let apply = |x: &mut [Point3], beta: f64| {
        for i in 0..x.len() {
            if moving[i] {
                x[i] = crate::geometry::add(center, scale(sub(base[i], center), beta));
            }
        }
    };
    let all = moving.iter().all(|m| *m);
    let mut beta = (target / v).cbrt();
    apply(x, beta);
    if all {
        return relative(vol(x), target);
    }
    // Secant iterations on f(β) = V(β) − target, starting from β₀ = 1 and the uniform guess.
    let (mut b0, mut f0) = (1.0, v - target);
    let mut f1 = vol(x) - target;
    for _ in 0..30 {
        if f1.abs() <= 1e-14 * target.abs() || f1 == f0 {
            break;
        }
        let next = beta - f1 * (beta - b0) / (f1 - f0);
        if !next.is_finite() || next <= 0.0 {
            break;
        }
        b0 = beta;
        f0 = f1;
        beta = next;
        apply(x, beta);
        f1 = vol(x) - target;
    }
    relative(vol(x), target)
}

fn relative(v: f64, target: f64) -> f64 {
    if target == 0.0 {
        0.0
    } else {
        (v - target) / target.abs()
    }
}
