//! The morph job (seeds 002/003): parameterisation, feature alignment, metamesh, interpolation,
//! multi-morphing.

use crate::error::Result;
use crate::job::{Output, Progress};
use crate::mesh::Mesh;

#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct MorphParams {}

/// Inputs: two or more meshes.
pub fn run(_inputs: Vec<Mesh>, _params: &MorphParams, _progress: &Progress) -> Result<Output> {
    Err(crate::Error::Internal("morph not implemented yet".into()))
}
