//! What a case is and the inputs the case families share (shared meshes and their plane
//! sections, the flattened ellipsoid, the sphere's sections, small mesh edits).

pub use meshwork_core::fit::testdata::to_unit_box;
use meshwork_core::fit::testdata::{ellipsoid_sections, plane_sections, section_regions, sweep_planes};
use meshwork_core::geometry::Aabb;
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

/// Plane sections of the repaired, unit-box copy of shared mesh `name`, and the unit-box raw mesh.
pub fn sections_of(name: &str) -> (Mesh, Mesh, usize) {
    let raw = read_as(&shared(name), "x.obj").unwrap_or_default();
    let mut fixed = repaired(raw.clone());
    // The raw mesh in the same frame as the repaired one.
    let bb = Aabb::of(&fixed.positions).expect("mesh has vertices");
    let side = (0..3).map(|k| bb.max[k] - bb.min[k]).fold(0.0, f64::max);
    let mut raw_unit = raw;
    for p in &mut raw_unit.positions {
        for k in 0..3 {
            p[k] = (p[k] - bb.min[k]) / side;
        }
    }
    to_unit_box(&mut fixed);
    let planes = sweep_planes(&fixed);
    let expected = section_regions(&fixed, &planes);
    (plane_sections(&fixed, &planes), raw_unit, expected)
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
