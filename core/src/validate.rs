//! The validation report (seed 003 §4.2): counts of everything that can be wrong with a mesh.

use crate::error::Result;
use crate::job::{Output, Progress};
use crate::mesh::Mesh;

#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ValidateParams {}

pub fn run(_mesh: &Mesh, _params: &ValidateParams, _progress: &Progress) -> Result<Output> {
    Err(crate::Error::Internal("validate not implemented yet".into()))
}
