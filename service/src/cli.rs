//! The command-line twin of the HTTP API: `meshwork info|convert|repair|smooth|fit|morph`.
//! Same runner, same params JSON: unknown `--some-name VALUE` flags become `some_name` params.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use meshwork_core::error::Error;
use meshwork_core::io::Format;
use meshwork_core::job::{JobKind, Progress};
use serde_json::{Map, Value};

use crate::params;
use crate::runner::{self, Input, Kind, Limits};

/// Options every job command understands (everything else is a job parameter).
#[derive(clap::Args, Debug, Clone)]
pub struct JobArgs {
    /// Input mesh file(s): one; fit: TEMPLATE CURVES; morph: 2..16 meshes
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output file (`-` = stdout); format from its extension unless --format
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Output format: glb, gltf, obj, ply, stl, off
    #[arg(long)]
    pub format: Option<String>,
    /// Write the JSON report here (else it goes to stdout when the mesh goes to a file)
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// JSON file with job parameters (flags override its keys)
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Stop the job after this many seconds
    #[arg(long)]
    pub timeout: Option<f64>,
    /// No progress line on the terminal
    #[arg(short, long)]
    pub quiet: bool,
}

/// Options of [`JobArgs`] that take a value / take none, for [`params::split_cli_args`].
pub const KNOWN_WITH_VALUE: &[&str] = &["-o", "--output", "--format", "--report", "--params", "--timeout"];
pub const KNOWN_SWITCHES: &[&str] = &["-q", "--quiet", "-h", "--help"];

/// A failure with the exit code it maps to: 2 for the caller's mistakes, 1 for ours.
pub struct Failure {
    pub code: i32,
    pub message: String,
}

impl Failure {
    fn usage(message: impl Into<String>) -> Self {
        Failure { code: 2, message: message.into() }
    }
    fn io(message: impl Into<String>) -> Self {
        Failure { code: 1, message: message.into() }
    }
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        let code = if runner::is_user_error(&e) { 2 } else { 1 };
        Failure { code, message: format!("error[{}]: {e}", e.kind()) }
    }
}

/// Runs one job command; `extra` holds the params collected from unknown flags.
pub fn run_job(kind: JobKind, args: JobArgs, extra: Map<String, Value>) -> Result<(), Failure> {
    let mut params = match &args.params {
        Some(p) => read_params_file(p)?,
        None => Map::new(),
    };
    params = params::merge(params, extra);
    if kind == JobKind::Fit {
        pairs_from_file(&mut params)?;
    }

    // `meshwork morph A B -o frames.zip`: the frames as separate files (GLB unless
    // `--frames-zip obj`), zipped; the job's first artifact is then the ZIP.
    let zip_out = kind == JobKind::Morph
        && args.format.is_none()
        && args.output.as_ref().is_some_and(|o| o.to_string_lossy().to_ascii_lowercase().ends_with(".zip"));
    if zip_out && !params.contains_key("frames_zip") {
        params.insert("frames_zip".into(), Value::String("glb".into()));
    }
    let out_format = if kind.returns_mesh() {
        let out = args.output.as_ref().ok_or_else(|| Failure::usage("error[usage]: -o OUT is required"))?;
        Some(if zip_out { Format::Glb } else { output_format(out, args.format.as_deref())? })
    } else {
        if args.output.is_some() {
            return Err(Failure::usage("error[usage]: `info` writes no mesh; use --report for the report"));
        }
        None
    };

    let mut inputs = Vec::with_capacity(args.inputs.len());
    for p in &args.inputs {
        let bytes = std::fs::read(p)
            .map_err(|e| Failure::usage(format!("error[io]: cannot read {}: {e}", p.display())))?;
        inputs.push(Input { bytes, name_hint: Some(p.display().to_string()) });
    }

    let progress = Progress::new();
    if let Some(t) = args.timeout {
        if !(t.is_finite() && t >= 0.0) {
            return Err(Failure::usage("error[usage]: --timeout must be a non-negative number of seconds"));
        }
        // A timeout too long for a Duration or an Instant (`--timeout 1e300` panicked here) would
        // never fire anyway: no deadline.
        if let Some(deadline) =
            Duration::try_from_secs_f64(t).ok().and_then(|d| Instant::now().checked_add(d))
        {
            progress.set_deadline(deadline);
        }
    }
    let show = !args.quiet && std::io::stderr().is_terminal();
    if show {
        install_progress_line(&progress, kind.name());
    }
    // Limits exist to protect a shared server; on the command line the user owns the machine.
    let limits = Limits {
        max_body_bytes: u64::MAX,
        max_vertices: u64::MAX,
        max_faces: u64::MAX,
        max_iterations: u64::MAX,
        max_frames: u64::MAX,
        max_curve_points: u64::MAX,
    };
    let result = runner::execute(Kind::Core(kind), inputs, params, &limits, &progress);
    if show {
        eprint!("\r\x1b[2K");
    }
    let done = result?;

    let mut mesh_to_stdout = false;
    if let (Some(format), Some(out)) = (out_format, &args.output) {
        let (bytes, media_type, _) = runner::encode(&done.output, format)?;
        if !done.output.artifacts.is_empty()
            && media_type != format.mime()
            && !(zip_out && media_type == "application/zip")
        {
            eprintln!("warning: {} produces {media_type}; writing that to {}", kind.name(), out.display());
        }
        if out == Path::new("-") {
            mesh_to_stdout = true;
            write_stdout(&bytes)?;
        } else {
            std::fs::write(out, &bytes)
                .map_err(|e| Failure::io(format!("error[io]: cannot write {}: {e}", out.display())))?;
        }
    }

    let report = serde_json::to_string_pretty(&done.output.report)
        .map_err(|e| Failure::io(format!("error[internal]: report: {e}")))?;
    match &args.report {
        Some(r) if r != Path::new("-") => std::fs::write(r, report + "\n")
            .map_err(|e| Failure::io(format!("error[io]: cannot write {}: {e}", r.display())))?,
        _ if mesh_to_stdout => {}
        _ => write_stdout(format!("{report}\n").as_bytes())?,
    }
    Ok(())
}

/// Writes to stdout; a closed pipe (`meshwork info x | head`) is not an error worth reporting.
fn write_stdout(bytes: &[u8]) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Failure::io(format!("error[io]: stdout: {e}"))),
    }
}

fn read_params_file(path: &Path) -> Result<Map<String, Value>, Failure> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Failure::usage(format!("error[io]: cannot read {}: {e}", path.display())))?;
    match serde_json::from_str::<Value>(&text) {
        Ok(Value::Object(m)) => Ok(m),
        Ok(_) => {
            Err(Failure::usage(format!("error[invalid-params]: {} must hold a JSON object", path.display())))
        }
        Err(e) => Err(Failure::usage(format!("error[invalid-params]: {}: {e}", path.display()))),
    }
}

/// `--format` wins; else the output's extension; `-o -` defaults to GLB.
fn output_format(out: &Path, flag: Option<&str>) -> Result<Format, Failure> {
    if let Some(f) = flag {
        return Format::from_name(f)
            .ok_or_else(|| Failure::usage(format!("error[usage]: unknown --format `{f}`")));
    }
    if out == Path::new("-") {
        return Ok(Format::Glb);
    }
    let name = out.file_name().and_then(|n| n.to_str()).unwrap_or("");
    if !name.contains('.') {
        return Err(Failure::usage(format!(
            "error[usage]: cannot tell the format of {}; add --format",
            out.display()
        )));
    }
    Format::from_name(name).ok_or_else(|| {
        Failure::usage(format!("error[usage]: unknown output extension in {}; use --format", out.display()))
    })
}

/// `smooth: solve  42%` on stderr, at most 10 times a second.
fn install_progress_line(progress: &Progress, job: &'static str) {
    let last = Mutex::new(Instant::now() - Duration::from_secs(1));
    progress.set_listener(move |stage, fraction| {
        let mut last = last.lock().unwrap_or_else(|e| e.into_inner());
        if last.elapsed() >= Duration::from_millis(100) {
            *last = Instant::now();
            eprint!("\r\x1b[2K{job}: {stage} {:3.0}%", fraction * 100.0);
        }
    });
}

/// `meshwork fit … --pairs PAIRS.json`: a string value of `pairs` names a file holding
/// `{"pairs": [...]}` (or the bare array), which replaces it; arrays given inline pass unchanged.
fn pairs_from_file(params: &mut Map<String, Value>) -> Result<(), Failure> {
    let Some(Value::String(path)) = params.get("pairs") else { return Ok(()) };
    let text = std::fs::read_to_string(path)
        .map_err(|e| Failure::usage(format!("error[io]: cannot read --pairs {path}: {e}")))?;
    let doc: Value = serde_json::from_str(&text)
        .map_err(|e| Failure::usage(format!("error[invalid-params]: --pairs {path}: {e}")))?;
    let pairs = match doc {
        Value::Object(mut m) if m.contains_key("pairs") => m.remove("pairs").unwrap_or(Value::Null),
        v @ Value::Array(_) => v,
        _ => {
            return Err(Failure::usage(format!(
                "error[invalid-params]: --pairs {path}: expected {{\"pairs\": [...]}} or an array"
            )))
        }
    };
    params.insert("pairs".into(), pairs);
    Ok(())
}
