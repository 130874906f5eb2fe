//! The `atelier` command-line program (issue 7, in progress): `atelier validate FILE…`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "atelier",
    version,
    about = "Garments from measured fabric mechanics"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check fabric, pattern, garment, body, motion and range side files (RON) and body meshes
    /// (OBJ, PLY); print each problem with file:line:column and field.
    Validate {
        /// Files to check.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Validate { files } => {
            let mut failed = 0;
            for f in &files {
                let outcome = atelier::validate::validate(f);
                failed += usize::from(outcome.is_err());
                // The report is the program's output.
                #[allow(clippy::print_stdout)]
                {
                    println!("{}", atelier::validate::report_line(f, &outcome));
                }
            }
            if failed > 0 {
                eprintln!("{failed} of {} files have problems", files.len());
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            }
        }
    }
}
