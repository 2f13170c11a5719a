//! Helpers shared by the `fit_*` integration tests on the shared meshes.
// Each test crate uses a different subset.
#![allow(dead_code)]

use meshwork_core::fit::testdata::to_unit_box;
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::mesh::Mesh;
use meshwork_core::repair::{self, RepairParams};
use meshwork_core::Progress;

/// A shared mesh (`shared/meshes/NAME.obj`), repaired without filling holes (the fit wants an
/// oriented manifold; open templates stay open) and scaled into the unit box.
pub fn load_repaired(name: &str) -> Mesh {
    let path = format!("{}/../../shared/meshes/{name}.obj", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let raw = read(&bytes, &ReadOptions::default()).expect("read").mesh;
    let params = RepairParams { fill_holes: false, ..Default::default() };
    let mut m = repair::run(raw, &params, &Progress::new()).expect("repair").meshes.remove(0);
    to_unit_box(&mut m);
    m
}
