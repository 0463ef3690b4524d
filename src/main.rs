//! The `inspc` command line: the only place that does IO.

use clap::{Parser, Subcommand, ValueEnum};
use inspc::diag::{render_human, to_json, RenderOptions};
use inspc::source::FsWorld;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "inspc", version, about = "Compiles .insp inspection specs into CMM programs")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MessageFormat {
    /// Graphical reports on stderr.
    Human,
    /// One JSON object per diagnostic per line on stdout.
    Json,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Emit {
    /// Only diagnostics.
    Nothing,
    /// The resolved model as text on stdout.
    Model,
}

#[derive(Subcommand)]
enum Command {
    /// Checks specs: parses, resolves names and units, checks values. Exits 1 on error.
    Check {
        /// The `.insp` files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// How to print diagnostics.
        #[arg(long, value_enum, default_value_t = MessageFormat::Human)]
        message_format: MessageFormat,
        /// What to print besides diagnostics.
        #[arg(long, value_enum, default_value_t = Emit::Nothing)]
        emit: Emit,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { files, message_format, emit } => {
            let checked = inspc::check(&FsWorld, &files);
            let mut stdout = std::io::stdout().lock();
            let mut stderr = std::io::stderr().lock();
            let opts = RenderOptions { width: 100, color: std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none() };
            for d in &checked.diagnostics {
                match message_format {
                    MessageFormat::Json => {
                        let _ = writeln!(stdout, "{}", to_json(&checked.sources, d));
                    }
                    MessageFormat::Human => {
                        let _ = write!(stderr, "{}", render_human(&checked.sources, d, opts));
                    }
                }
            }
            if emit == Emit::Model && !checked.has_errors() {
                let _ = write!(stdout, "{}", checked.summary());
            }
            let errors = checked.diagnostics.iter().filter(|d| d.severity() == miette::Severity::Error).count();
            let warnings = checked.diagnostics.len() - errors;
            if message_format == MessageFormat::Human {
                let plural = |n: usize, w: &str| format!("{n} {w}{}", if n == 1 { "" } else { "s" });
                let _ = if errors > 0 {
                    writeln!(stderr, "inspc: {} and {} in {}", plural(errors, "error"), plural(warnings, "warning"), plural(files.len(), "file"))
                } else {
                    writeln!(stderr, "inspc: {} checked, no errors ({})", plural(files.len(), "file"), plural(warnings, "warning"))
                };
            }
            if errors > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS }
        }
    }
}
