//! The smooth job: Laplacian, Taubin, implicit, MCF, fairing, inflation, tangential flows.

use crate::error::Result;
use crate::job::{Output, Progress};
use crate::mesh::Mesh;

#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SmoothParams {}

pub fn run(_mesh: Mesh, _params: &SmoothParams, _progress: &Progress) -> Result<Output> {
    Err(crate::Error::Internal("smooth not implemented yet".into()))
}
