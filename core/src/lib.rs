//! meshwork-core: geometry only. No async, no HTTP, no global state.
//!
//! The modules read like the pipeline: bytes come in through [`io`], become a [`mesh::Mesh`],
//! are checked by [`validate`] and mended by [`repair`] (both on top of [`topology`]), and are then
//! handed to a job ([`smooth`], [`fit`], [`morph`]). Every job has the shape
//! `run(input, &Params, &Progress) -> Result<Output, Error>` (see [`job`]).

pub mod error;
pub mod fit;
pub mod geometry;
pub mod hash;
pub mod io;
pub mod job;
pub mod laplacian;
pub mod mesh;
pub mod metrics;
pub mod morph;
pub mod register;
pub mod repair;
pub mod shapes;
pub mod smooth;
pub mod solve;
pub mod spatial;
pub mod topology;
pub mod validate;

pub use error::{Error, Result};
pub use job::{Output, Progress};
pub use mesh::Mesh;
