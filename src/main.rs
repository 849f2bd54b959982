//! `facet`: measured materials to microfacet models.

mod dpf_cmd;
mod fit_cmd;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "facet",
    version,
    about = "Measured materials to microfacet models: NDF extraction, fitting, glint DPF tables"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Extract the NDF of each input and fit tabulated, GGX and Beckmann models.
    Fit(fit_cmd::FitArgs),
    /// The glint model's Directional Probability Function: one query, or the tables as EXR.
    Dpf(dpf_cmd::DpfArgs),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Fit(args)) => fit_cmd::run(&args),
        Some(Command::Dpf(args)) => dpf_cmd::run(&args),
        None => fit_cmd::run_default(),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
