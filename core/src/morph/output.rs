//! The `frames_zip` output: the morph's frames as separate files (GLB or OBJ) in one stored ZIP.

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::io::zip::ZipWriter;
use crate::job::{Artifact, Progress, Stages};
use crate::mesh::{Mesh, Point3};

use super::{glb, interpolate, MorphParams};

/// The stages every domain ends with, on the common connectivity `tris` and the per-input shapes
/// (already in input 0's coordinates): the output meshes (`interpolate`: blend, frames or the end
/// shapes, as the params ask), the animated GLB (`glb`) and, on request, the frames ZIP
/// (`frames_zip`, then first among the artifacts: it is the result file).
pub fn write_outputs(
    stages: &mut Stages,
    progress: &Progress,
    params: &MorphParams,
    tris: &[[u32; 3]],
    shapes: &[Vec<Point3>],
) -> Result<(Vec<Mesh>, Vec<Artifact>)> {
    let k_in = shapes.len();
    let meshes = stages.run(progress, "interpolate", || {
        let mk = |pos: Vec<Point3>| Mesh::from_triangles(pos, tris);
        Ok(if let Some(w) = &params.blend_weights {
            vec![mk(interpolate::blend(shapes, w))]
        } else if params.output_frames {
            (0..params.frames)
                .map(|j| {
                    let (leg, t) = interpolate::frame_position(j, params.frames, k_in);
                    mk(interpolate::frame(shapes, leg, t))
                })
                .collect()
        } else {
            shapes.iter().map(|s| mk(s.clone())).collect()
        })
    })?;
    let glb_bytes = stages.run(progress, "glb", || {
        let keys = interpolate::keyframes(params.frames, k_in, params.duration_seconds);
        glb::write(tris, shapes, &keys)
    })?;
    let mut artifacts =
        vec![Artifact { name: "morph.glb".into(), media_type: "model/gltf-binary".into(), bytes: glb_bytes }];
    if let Some(fmt) = params.frames_zip {
        let z =
            stages.run(progress, "frames_zip", || frames_zip(tris, shapes, params.frames, fmt, progress))?;
        artifacts.insert(0, z);
    }
    Ok((meshes, artifacts))
}

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
