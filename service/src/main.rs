//! `meshwork`: the HTTP job service (`meshwork serve`) and its command-line twin.

mod cli;
mod config;
mod params;
mod runner;
mod server;

use clap::{Parser, Subcommand};
use meshwork_core::job::JobKind;

#[derive(Parser)]
#[command(name = "meshwork", version, about = "Mesh processing jobs: CLI and HTTP service")]
#[command(after_help = "Job parameters: any other `--some-name VALUE` flag becomes the JSON parameter \
`some_name` (VALUE parsed as JSON when it parses, else taken as a string; `--flag` alone = true), \
merged over --params FILE. See docs/api.md for each job's parameters.")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Validation report of a mesh as JSON on stdout
    #[command(alias = "validate")]
    Info(cli::JobArgs),
    /// Read and write again in another format
    Convert(cli::JobArgs),
    /// Weld, clean, make manifold and consistently oriented, fill holes
    Repair(cli::JobArgs),
    /// Smooth or fair a mesh (--method laplacian|taubin|implicit|mcf|fair|inflate|tangential)
    Smooth(cli::JobArgs),
    /// Deform TEMPLATE so that it passes through the CURVES network
    Fit(cli::JobArgs),
    /// Morph sequence between 2..16 meshes, written as an animated GLB
    Morph(cli::JobArgs),
    /// Run the HTTP service (defaults: 127.0.0.1:8080)
    Serve(config::ServeArgs),
    /// Print the OpenAPI document
    Openapi {
        /// Write to this file instead of stdout
        #[arg(short, long)]
        output: Option<std::path::PathBuf>,
    },
}

fn job_of(name: &str) -> Option<JobKind> {
    match name {
        "info" | "validate" => Some(JobKind::Validate),
        _ => JobKind::parse(name).filter(|k| *k != JobKind::Validate),
    }
}

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    // One line instead of a backtrace; the runner turns the panic into an error for that job.
    std::panic::set_hook(Box::new(|info| {
        let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        eprintln!("internal error: panic{at}: {}", panic_message(info.payload()));
    }));

    // Job commands: pull the job parameters (unknown --flags) out before clap sees the arguments.
    let argv: Vec<String> = std::env::args().collect();
    let mut extra = serde_json::Map::new();
    let argv = match argv.get(1).map(String::as_str).and_then(job_of) {
        Some(_) => {
            let (known, params) =
                params::split_cli_args(&argv[2..], cli::KNOWN_WITH_VALUE, cli::KNOWN_SWITCHES);
            extra = params;
            argv[..2].iter().cloned().chain(known).collect()
        }
        None => argv,
    };
    let parsed = Cli::parse_from(argv);

    let result = match parsed.cmd {
        Cmd::Info(a) => cli::run_job(JobKind::Validate, a, extra),
        Cmd::Convert(a) => cli::run_job(JobKind::Convert, a, extra),
        Cmd::Repair(a) => cli::run_job(JobKind::Repair, a, extra),
        Cmd::Smooth(a) => cli::run_job(JobKind::Smooth, a, extra),
        Cmd::Fit(a) => cli::run_job(JobKind::Fit, a, extra),
        Cmd::Morph(a) => cli::run_job(JobKind::Morph, a, extra),
        Cmd::Serve(a) => server::serve_main(a),
        Cmd::Openapi { output } => print_openapi(output),
    };
    if let Err(f) = result {
        eprintln!("{}", f.message);
        std::process::exit(f.code);
    }
}

fn print_openapi(output: Option<std::path::PathBuf>) -> Result<(), cli::Failure> {
    let text = server::openapi::document_json();
    match output {
        Some(p) => std::fs::write(&p, text)
            .map_err(|e| cli::Failure { code: 1, message: format!("error[io]: {}: {e}", p.display()) }),
        None => {
            print!("{text}");
            Ok(())
        }
    }
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}
