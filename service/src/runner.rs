//! The one job runner the CLI and the server share: bytes in → `core::io::read` (with limits) →
//! `core::job::run` (panics caught) → bytes out. Limits are enforced before any work starts.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::{Duration, Instant};

use meshwork_core::error::Error;
use meshwork_core::io::{self, Format, ReadOptions};
use meshwork_core::job::{self, JobKind, Output, Progress};
use meshwork_core::Mesh;
use serde_json::{json, Map, Value};

/// A job the binary can run: a core job, or (only with `--debug-jobs`) a test job used to exercise
/// admission, time limits and panics deterministically.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Core(JobKind),
    /// Sleeps `ms` milliseconds in 10 ms steps, checking progress; returns its input.
    Sleep,
    /// Panics (to test that a panic fails only its own job).
    Panic,
}

impl Kind {
    pub fn parse(s: &str, debug_jobs: bool) -> Option<Kind> {
        match s {
            "sleep" if debug_jobs => Some(Kind::Sleep),
            "panic" if debug_jobs => Some(Kind::Panic),
            _ => JobKind::parse(s).map(Kind::Core),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Kind::Core(k) => k.name(),
            Kind::Sleep => "sleep",
            Kind::Panic => "panic",
        }
    }

    pub fn inputs(self) -> (usize, usize) {
        match self {
            Kind::Core(k) => k.inputs(),
            _ => (1, 1),
        }
    }

    pub fn returns_mesh(self) -> bool {
        match self {
            Kind::Core(k) => k.returns_mesh(),
            _ => true,
        }
    }
}

/// Limits checked before work starts (configurable in the server; generous defaults in the CLI).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Limits {
    pub max_body_bytes: u64,
    pub max_vertices: u64,
    pub max_faces: u64,
    /// Applies to any parameter named `iterations` or ending in `_iterations`.
    pub max_iterations: u64,
    /// Applies to the `frames` parameter (morph).
    pub max_frames: u64,
    /// Total polyline points of the curve input (fit).
    pub max_curve_points: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_body_bytes: 256 << 20,
            max_vertices: 5_000_000,
            max_faces: 10_000_000,
            max_iterations: 10_000,
            max_frames: 1_000,
            max_curve_points: 1_000_000,
        }
    }
}

/// One input file.
pub struct Input {
    pub bytes: Vec<u8>,
    /// File name (or extension) used only to break ties in format detection.
    pub name_hint: Option<String>,
}

/// A finished job: the output and what the service needs to encode it.
pub struct Done {
    pub output: Output,
}

/// Checks the parameter limits that can be checked without reading the meshes.
pub fn check_param_limits(params: &Map<String, Value>, limits: &Limits) -> Result<(), Error> {
    for (k, v) in params {
        let limit = if k == "iterations" || k.ends_with("_iterations") {
            limits.max_iterations
        } else if k == "frames" {
            limits.max_frames
        } else {
            continue;
        };
        if let Some(n) = v.as_f64() {
            if n > limit as f64 {
                return Err(Error::TooLarge { what: format!("parameter `{k}`"), limit, actual: n as u64 });
            }
        }
    }
    Ok(())
}

/// Reads, runs and reports. Panics inside the job become `Error::Internal`.
pub fn execute(
    kind: Kind,
    inputs: Vec<Input>,
    params: Map<String, Value>,
    limits: &Limits,
    progress: &Progress,
) -> Result<Done, Error> {
    let (lo, hi) = kind.inputs();
    if inputs.len() < lo || inputs.len() > hi {
        return Err(Error::params(
            "inputs",
            format!("{} takes {lo}..={hi} mesh files, got {}", kind.name(), inputs.len()),
        ));
    }
    check_param_limits(&params, limits)?;
    progress.check()?;
    let t_read = Instant::now();
    let mut meshes = Vec::with_capacity(inputs.len());
    let mut input_info = Vec::with_capacity(inputs.len());
    for (i, input) in inputs.into_iter().enumerate() {
        progress.check()?;
        let is_fit_curves = kind == Kind::Core(JobKind::Fit) && i == 1;
        // Fit's curve network may also come as JSON `{"polylines": …}` (issue 5); meshes never do.
        let json_curves =
            if is_fit_curves { meshwork_core::fit::curves::polylines_from_json(&input.bytes) } else { None };
        let (loaded, format) = match json_curves {
            Some(mesh) => {
                let mesh = mesh?;
                (io::Loaded { mesh, format: io::Format::Obj, warnings: Vec::new() }, json!("polylines-json"))
            }
            None => {
                let l = read_one(&input, limits)?;
                let f = json!(l.format);
                (l, f)
            }
        };
        if is_fit_curves {
            let points: usize = loaded.mesh.curves.iter().map(Vec::len).sum();
            if points as u64 > limits.max_curve_points {
                return Err(Error::TooLarge {
                    what: "curve points".into(),
                    limit: limits.max_curve_points,
                    actual: points as u64,
                });
            }
        }
        input_info.push(json!({
            "format": format,
            "bytes": input.bytes.len(),
            "vertices": loaded.mesh.vertex_count(),
            "faces": loaded.mesh.face_count(),
            "warnings": loaded.warnings,
        }));
        meshes.push(loaded.mesh);
    }
    let read_ms = t_read.elapsed().as_secs_f64() * 1e3;

    let mut output = run_caught(kind, meshes, params, progress)?;
    // The job's report says what the job did; add what the runner saw of the files.
    if let Value::Object(m) = &mut output.report {
        m.entry("inputs").or_insert(Value::Array(input_info));
        m.entry("read_ms").or_insert(json!((read_ms * 1e3).round() / 1e3));
    }
    Ok(Done { output })
}

fn read_one(input: &Input, limits: &Limits) -> Result<io::Loaded, Error> {
    let opts = ReadOptions {
        name_hint: input.name_hint.clone(),
        max_vertices: limits.max_vertices.min(usize::MAX as u64) as usize,
        max_faces: limits.max_faces.min(usize::MAX as u64) as usize,
    };
    let loaded = io::read(&input.bytes, &opts)?;
    // Readers enforce the limits while reading; check again in case one only counts at the end.
    let (v, f) = (loaded.mesh.vertex_count() as u64, loaded.mesh.face_count() as u64);
    if v > limits.max_vertices {
        return Err(Error::TooLarge { what: "vertices".into(), limit: limits.max_vertices, actual: v });
    }
    if f > limits.max_faces {
        return Err(Error::TooLarge { what: "faces".into(), limit: limits.max_faces, actual: f });
    }
    Ok(loaded)
}

/// Runs the job, turning a panic into an internal error for this job only.
fn run_caught(
    kind: Kind,
    meshes: Vec<Mesh>,
    params: Map<String, Value>,
    progress: &Progress,
) -> Result<Output, Error> {
    let result = catch_unwind(AssertUnwindSafe(|| match kind {
        Kind::Core(k) => job::run(k, meshes, Value::Object(params), progress),
        Kind::Sleep => sleep_job(meshes, params, progress),
        Kind::Panic => panic!("debug panic job"),
    }));
    match result {
        Ok(r) => r,
        Err(payload) => {
            let msg = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(Error::Internal(format!("the {} job panicked: {msg}", kind.name())))
        }
    }
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SleepParams {
    ms: u64,
}

impl Default for SleepParams {
    fn default() -> Self {
        SleepParams { ms: 1000 }
    }
}

fn sleep_job(
    mut meshes: Vec<Mesh>,
    params: Map<String, Value>,
    progress: &Progress,
) -> Result<Output, Error> {
    let p: SleepParams = job::parse_params(Value::Object(params))?;
    let t = Instant::now();
    progress.stage("sleep")?;
    let total = Duration::from_millis(p.ms);
    while t.elapsed() < total {
        std::thread::sleep(Duration::from_millis(10).min(total));
        progress.fraction(t.elapsed().as_secs_f64() / total.as_secs_f64().max(1e-9))?;
    }
    let mesh = meshes.swap_remove(0);
    let report = json!({"slept_ms": t.elapsed().as_secs_f64() * 1e3, "vertices": mesh.vertex_count()});
    Ok(Output { meshes: vec![mesh], report, ..Default::default() })
}

/// The result file of a job: the first artifact when the job made one (morph's animated GLB),
/// else `meshes[0]` encoded in `format`. Returns (bytes, media type, file extension).
pub fn encode(output: &Output, format: Format) -> Result<(Vec<u8>, String, String), Error> {
    if let Some(a) = output.artifacts.first() {
        let ext = a.name.rsplit('.').next().unwrap_or("bin").to_string();
        return Ok((a.bytes.clone(), a.media_type.clone(), ext));
    }
    let mesh = output.meshes.first().ok_or_else(|| Error::Internal("the job returned no mesh".into()))?;
    Ok((io::write(mesh, format)?, format.mime().to_string(), format.extension().to_string()))
}

/// Whether the failure is the caller's (bad input, bad params, limits) rather than ours.
pub fn is_user_error(e: &Error) -> bool {
    matches!(
        e,
        Error::UnsupportedFormat(_)
            | Error::Malformed { .. }
            | Error::ExternalReference { .. }
            | Error::InvalidMesh { .. }
            | Error::InvalidParams { .. }
            | Error::TooLarge { .. }
            | Error::Topology(_)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iteration_and_frame_limits_name_the_parameter() {
        let limits = Limits { max_iterations: 10, max_frames: 5, ..Default::default() };
        let mut p = Map::new();
        p.insert("iterations".into(), json!(10));
        assert!(check_param_limits(&p, &limits).is_ok());
        p.insert("inner_iterations".into(), json!(11));
        let e = check_param_limits(&p, &limits).unwrap_err();
        assert!(e.to_string().contains("inner_iterations"), "{e}");
        let mut p = Map::new();
        p.insert("frames".into(), json!(6));
        assert!(matches!(check_param_limits(&p, &limits), Err(Error::TooLarge { limit: 5, actual: 6, .. })));
    }

    #[test]
    fn panic_in_job_is_an_internal_error() {
        let e = run_caught(Kind::Panic, vec![], Map::new(), &Progress::new()).unwrap_err();
        assert!(matches!(e, Error::Internal(ref m) if m.contains("panicked")), "{e}");
    }

    #[test]
    fn sleep_job_stops_when_cancelled() {
        let p = Progress::new();
        p.cancel();
        let mesh = meshwork_core::shapes::icosphere(0, 1.0);
        let mut params = Map::new();
        params.insert("ms".into(), json!(5000));
        let t = Instant::now();
        let e = run_caught(Kind::Sleep, vec![mesh], params, &p).unwrap_err();
        assert!(matches!(e, Error::Cancelled));
        assert!(t.elapsed() < Duration::from_secs(1));
    }
}
