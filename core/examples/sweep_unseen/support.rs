//! What a case is and the inputs the case families share (shared meshes and their plane
//! sections, the flattened ellipsoid, the sphere's sections, small mesh edits).

pub use meshwork_core::fit::testdata::to_unit_box;
use std::f64::consts::PI;

use meshwork_core::fit::testdata::{
    arc, circle, disjoint_union, ellipsoid_sections, sections_of_repaired, sweep_planes,
};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::repair::{self, RepairParams};
use meshwork_core::shapes::icosphere;
use meshwork_core::{Error, Progress};

pub const AXES: [f64; 3] = [1.4, 1.15, 0.9];
pub const X: Point3 = [1.0, 0.0, 0.0];
pub const Y: Point3 = [0.0, 1.0, 0.0];
pub const Z: Point3 = [0.0, 0.0, 1.0];
pub const O: Point3 = [0.0, 0.0, 0.0];

/// What a case expects.
#[derive(Debug)]
pub enum Expect {
    /// A fit with this many regions (None: no hand count).
    Fit(Option<usize>),
    /// An error whose text contains all these words.
    Error(&'static [&'static str]),
}

pub struct Case {
    pub name: String,
    /// Produces the inputs (reading files can fail: that is part of the case).
    pub inputs: Box<dyn Fn() -> Result<Vec<Mesh>, Error>>,
    pub params: serde_json::Value,
    pub expect: Expect,
}

pub fn case(
    name: &str,
    inputs: impl Fn() -> Result<Vec<Mesh>, Error> + 'static,
    params: serde_json::Value,
    expect: Expect,
) -> Case {
    Case { name: name.into(), inputs: Box::new(inputs), params, expect }
}

/// The inputs of a case: `template` and `curves` as they are.
pub fn fit_inputs(template: Mesh, curves: Mesh) -> Result<Vec<Mesh>, Error> {
    Ok(vec![template, curves])
}

/// The level-3 unit icosphere and `curves`, the most common pair of inputs.
pub fn on_icosphere(curves: Mesh) -> Result<Vec<Mesh>, Error> {
    fit_inputs(icosphere(3, 1.0), curves)
}

/// `template` and the sphere's octant sections (6 points a quarter): 8 regions when the fit
/// follows them.
pub fn vs_octants(template: Mesh) -> Result<Vec<Mesh>, Error> {
    fit_inputs(template, sphere_sections(6))
}

/// A case with correspondence pairs on the icosphere and the octant sections that must fail
/// with an error naming `words`.
pub fn pairs_case(name: &str, pairs: serde_json::Value, words: &'static [&'static str]) -> Case {
    case(
        name,
        || on_icosphere(sphere_sections(6)),
        serde_json::json!({ "pairs": pairs }),
        Expect::Error(words),
    )
}

pub fn shared(name: &str) -> Vec<u8> {
    std::fs::read(format!("../shared/meshes/{name}.obj")).unwrap_or_default()
}

pub fn read_as(bytes: &[u8], hint: &str) -> Result<Mesh, Error> {
    let opts = ReadOptions { name_hint: Some(hint.into()), ..Default::default() };
    Ok(read(bytes, &opts)?.mesh)
}

pub fn repaired(m: Mesh) -> Mesh {
    let params = RepairParams { fill_holes: false, ..Default::default() };
    repair::run(m, &params, &Progress::new()).map(|mut o| o.meshes.remove(0)).unwrap_or_default()
}

/// Shared mesh `name` repaired (holes left open) and moved to the unit box.
pub fn unit_repaired(name: &str) -> Result<Mesh, Error> {
    let mut t = repaired(read_as(&shared(name), "x.obj")?);
    to_unit_box(&mut t);
    Ok(t)
}

/// Shared mesh `name` as read (in the frame of its repaired copy) and its own sections.
pub fn raw_vs_own_sections(name: &str) -> Result<Vec<Mesh>, Error> {
    let (c, raw, _) = sections_of(name);
    fit_inputs(raw, c)
}

/// Shared mesh `name` repaired from the raw mesh in the sections' frame, and its own sections.
pub fn repaired_vs_own_sections(name: &str) -> Result<Vec<Mesh>, Error> {
    let (c, raw, _) = sections_of(name);
    let mut t = repaired(raw);
    to_unit_box(&mut t);
    fit_inputs(t, c)
}

/// An icosphere of radius 0.5 in the unit box (the sweep's frame) and the sections of shared
/// mesh `name`: a template of another shape, aligned automatically.
pub fn icosphere_vs_sections_of(name: &str) -> Result<Vec<Mesh>, Error> {
    icosphere_level_vs_sections_of(3, name)
}

/// An icosphere of `level` (radius 0.5 in the unit box) and the sections of shared mesh `name`.
pub fn icosphere_level_vs_sections_of(level: u32, name: &str) -> Result<Vec<Mesh>, Error> {
    let (c, _, _) = sections_of(name);
    fit_inputs(shifted(&icosphere(level, 0.5), [0.5, 0.5, 0.5]), c)
}

/// Plane sections of the repaired, unit-box copy of shared mesh `name`, and the unit-box raw mesh.
pub fn sections_of(name: &str) -> (Mesh, Mesh, usize) {
    let raw = read_as(&shared(name), "x.obj").unwrap_or_default();
    sections_of_repaired(raw).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// An icosphere of radius 0.5 centred at (0.5, 0.5, 0.5) squashed to 1 × 0.6 × `thick`.
pub fn flatten(m: &mut Mesh, thick: f64) {
    for p in &mut m.positions {
        *p = [p[0] + 0.5, 0.5 + 0.6 * p[1], 0.5 + thick * p[2]];
    }
}

/// The flattened ellipsoid 1 × 0.6 × `thick` (a fine icosphere) and the sweep's planes on it.
pub fn flat_ellipsoid(thick: f64) -> (Mesh, Vec<(Point3, f64)>) {
    let mut s = icosphere(5, 0.5);
    flatten(&mut s, thick);
    let planes = sweep_planes(&s);
    (s, planes)
}

pub fn sphere_sections(per_quadrant: usize) -> Mesh {
    ellipsoid_sections(AXES, per_quadrant)
}

/// The unit circle in the xy plane (48 points from angle `equator_phase`) and `n` half
/// meridians from pole to pole (24 segments each) at longitudes `phase + 2πk / n`: 2n regions.
pub fn equator_and_meridians(n: usize, phase: f64, equator_phase: f64) -> Vec<Vec<Point3>> {
    let mut l = vec![circle(O, X, Y, 1.0, 48, equator_phase)];
    for k in 0..n {
        let t = phase + 2.0 * PI / n as f64 * k as f64;
        l.push(arc(O, [t.cos(), t.sin(), 0.0], Z, 1.0, -PI / 2.0, PI / 2.0, 24));
    }
    l
}

/// `m` moved by `by`.
pub fn shifted(m: &Mesh, by: Point3) -> Mesh {
    let mut m = m.clone();
    for p in &mut m.positions {
        *p = [p[0] + by[0], p[1] + by[1], p[2] + by[2]];
    }
    m
}

/// The level-3 unit icosphere and `far` moved 6 along x, as one template.
pub fn icosphere_and_far(far: &Mesh) -> Mesh {
    let mut far = far.clone();
    for p in &mut far.positions {
        p[0] += 6.0;
    }
    disjoint_union(&icosphere(3, 1.0), &far)
}

/// The two-point segments of every polyline of `c`, in order.
pub fn segments(c: &Mesh) -> Vec<[u32; 2]> {
    c.curves.iter().flat_map(|l| l.windows(2).map(|w| [w[0], w[1]])).collect()
}

/// The polylines of `m` as point lists.
pub fn lines_of(m: &Mesh) -> Vec<Vec<Point3>> {
    m.curves.iter().map(|l| l.iter().map(|&v| m.positions[v as usize]).collect()).collect()
}

/// `m` with every face turned over.
pub fn reversed(m: &Mesh) -> Mesh {
    let tris: Vec<[u32; 3]> = m.faces.triangles().iter().map(|t| [t[0], t[2], t[1]]).collect();
    Mesh::from_triangles(m.positions.clone(), &tris)
}

/// Radius of the bumpy sphere at direction `d` (unit): 1 + 0.02·sin(3x + 2y + z) (the hand-drawn
/// curves' surface; 2 % of the radius).
pub fn bumpy(d: Point3) -> Point3 {
    let r = 1.0 + 0.02 * (3.0 * d[0] + 2.0 * d[1] + d[2]).sin();
    [d[0] * r, d[1] * r, d[2] * r]
}
