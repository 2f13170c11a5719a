//! The fit job (seed 000): deform a template so that it passes through a curve network, flip
//! prevention, re-triangulation along the curves, partition, constrained smoothing.

use crate::error::Result;
use crate::job::{Output, Progress};
use crate::mesh::Mesh;

#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FitParams {}

/// Inputs: template and curve network.
pub fn run(_inputs: Vec<Mesh>, _params: &FitParams, _progress: &Progress) -> Result<Output> {
    Err(crate::Error::Internal("fit not implemented yet".into()))
}
