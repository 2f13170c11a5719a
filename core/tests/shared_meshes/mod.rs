//! The shared real meshes (`../shared/meshes` beside the repository, or the folder named by
//! `MESHWORK_MESHES`). They are not part of the repository: on a machine without them the real-mesh
//! tests print `SKIP` and return early, so the rest of the suite still runs.
#![allow(dead_code)]

use std::path::PathBuf;

use meshwork_core::io::{self, ReadOptions};
use meshwork_core::mesh::Mesh;

/// The folder the shared meshes are read from.
pub fn dir() -> PathBuf {
    std::env::var_os("MESHWORK_MESHES")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes"))
}

/// The bytes of one shared mesh file, or `None` (with a `SKIP` line) when it is not there.
pub fn bytes(name: &str) -> Option<Vec<u8>> {
    match std::fs::read(dir().join(name)) {
        Ok(b) => Some(b),
        Err(e) => {
            eprintln!("SKIP {name}: {e} (set MESHWORK_MESHES to the shared meshes folder)");
            None
        }
    }
}

/// One shared mesh read with the default options; a file that is there but unreadable fails the test.
pub fn load(name: &str) -> Option<Mesh> {
    let b = bytes(name)?;
    Some(io::read(&b, &ReadOptions::default()).unwrap_or_else(|e| panic!("{name} is readable: {e}")).mesh)
}
