//! Repair of damaged meshes (seed 003 §4.2): weld, drop degenerate/duplicate faces, resolve
//! non-manifold parts, orient, remove small components, fill holes.

use crate::error::Result;
use crate::job::{Output, Progress};
use crate::mesh::Mesh;

#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
pub struct RepairParams {}

pub fn run(_mesh: Mesh, _params: &RepairParams, _progress: &Progress) -> Result<Output> {
    Err(crate::Error::Internal("repair not implemented yet".into()))
}
