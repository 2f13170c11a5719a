//! Curve networks and templates with a known truth, for the fit tests, the sweeps and the
//! benchmarks: they are built from analytic surfaces or exact plane sections, never from the code
//! under test. One file per family:
//! - [`sections`]: plane sections of meshes and of the ellipsoid, the regions they cut, the sweep's
//!   frame and planes, a known smooth map, a coarser network, pairs at crossings;
//! - [`curves`]: closed-form curves (circles, arcs, loxodromes, helices, great circles, waves) as
//!   polylines, jitter, arcs whose ends miss;
//! - [`templates`]: templates beyond the icosphere (cylinder, paraboloid with a hole, n-gon sphere)
//!   and mesh edits (holes, two meshes as one, a zero-area face);
//! - [`features`]: a mesh's sharp edges as a feature-line network, and the regions they cut;
//! - [`checks`]: checks of an output against the truth (faces turned against its normal);
//! - [`heldout`]: other smooth maps and oblique planes, the held-out family of the deformed sweep;
//! - [`files`]: curve files as other programs write them (glTF lines with and without node
//!   transforms, OBJ negative indices).
//!
//! Everything is re-exported here, so `fit::testdata::circle` names it whatever its family.

pub mod checks;
pub mod curves;
pub mod features;
pub mod files;
pub mod heldout;
pub mod regions;
pub mod sections;
pub mod templates;

pub use checks::*;
pub use curves::*;
pub use features::*;
pub use files::*;
pub use heldout::*;
pub use regions::*;
pub use sections::*;
pub use templates::*;
