//! The `frames_zip` output: the morph's frames as separate files (GLB or OBJ) in one stored ZIP.

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::io::zip::ZipWriter;
use crate::job::{Artifact, Progress};
use crate::mesh::{Mesh, Point3};

use super::{glb, interpolate};

/// File format of each frame in the `frames_zip` output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum FrameFormat {
    Glb,
    Obj,
}

/// `frames` files `frame_0000.glb` … along the path through `shapes` (as the animation plays it).
pub fn frames_zip(
    tris: &[[u32; 3]],
    shapes: &[Vec<Point3>],
    frames: usize,
    format: FrameFormat,
    progress: &Progress,
) -> Result<Artifact> {
    let mut z = ZipWriter::new();
    let digits = frames.saturating_sub(1).to_string().len().max(4);
    for j in 0..frames {
        progress.fraction(j as f64 / frames as f64)?;
        let (leg, t) = interpolate::frame_position(j, frames, shapes.len());
        let pos = interpolate::frame(shapes, leg, t);
        let (bytes, ext) = match format {
            FrameFormat::Glb => (glb::write_static(tris, &pos, &format!("frame {j}"))?, "glb"),
            FrameFormat::Obj => (crate::io::obj::write(&Mesh::from_triangles(pos, tris))?, "obj"),
        };
        z.add(&format!("frame_{j:0digits$}.{ext}"), &bytes)?;
    }
    Ok(Artifact { name: "morph_frames.zip".into(), media_type: "application/zip".into(), bytes: z.finish()? })
}
