//! `sonolube`: the host command-line tool (`sonolube --help`; `sonolube COMMAND --help` for each
//! command).
//!
//! The command line is clap's (derive): this file names the subcommands, each subcommand's
//! module declares its own arguments (`sonolube_cli::commands::*::Args`) and parses them in its
//! `run`, so that `--help` and the usage errors (exit status 2) read the same everywhere.

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};
use sonolube_cli::commands;

/// Sonolube's host tool: models, paper numbers, scenes closed loop, the speed table, the
/// firmware monitor and the generated figures of the docs.
#[derive(Parser, Debug)]
#[command(
    name = "sonolube",
    bin_name = "sonolube",
    subcommand_required = true,
    arg_required_else_help = true,
    after_help = "`sonolube COMMAND --help` (or `sonolube help COMMAND`) gives each command's arguments.\n\
                  Exit status: 0 done, 1 a failed verdict or check, 2 a usage error."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The arguments after a subcommand's name, parsed by the subcommand itself.
#[derive(clap::Args, Debug)]
struct Rest {
    #[arg(num_args = 0.., trailing_var_arg = true, allow_hyphen_values = true)]
    args: Vec<String>,
}

#[derive(Subcommand, Debug)]
#[command(disable_help_subcommand = true)]
enum Command {
    /// Write the Dahl steady-state table nodes from the f64 reference, or check them.
    #[command(disable_help_flag = true)]
    DahlTable(Rest),
    /// Regenerate or check the measured figures of the docs (the generated blocks).
    #[command(disable_help_flag = true)]
    Docs(Rest),
    /// Evaluate a model in fixed point and in the f64 reference (JSON).
    #[command(disable_help_flag = true)]
    Eval(Rest),
    /// Talk to the firmware: commands, telemetry CSV/SVG, acceptance test.
    #[command(disable_help_flag = true)]
    Monitor(Rest),
    /// Paper numbers against the reference and the fixed point (markdown).
    #[command(disable_help_flag = true)]
    Papers(Rest),
    /// Run a scene closed loop: CSV, SVG and metrics; sweeps over seeds and mismatch.
    #[command(disable_help_flag = true)]
    Scene(Rest),
    /// Speed against accuracy of every model variant (markdown, SVG, the firmware's table).
    #[command(disable_help_flag = true)]
    Speed(Rest),
    /// Print the help of the tool, or of COMMAND.
    #[command(disable_help_flag = true)]
    Help(Rest),
}

fn dispatch(command: Command) -> ExitCode {
    match command {
        Command::DahlTable(rest) => commands::dahl_table::run(&rest.args),
        Command::Docs(rest) => commands::docs::run(&rest.args),
        Command::Eval(rest) => commands::eval::run(&rest.args),
        Command::Monitor(rest) => commands::monitor::run(&rest.args),
        Command::Papers(rest) => commands::papers::run(&rest.args),
        Command::Scene(rest) => commands::scene::run(&rest.args),
        Command::Speed(rest) => commands::speed::run(&rest.args),
        Command::Help(rest) => match rest.args.first() {
            // `sonolube help COMMAND` is `sonolube COMMAND --help`.
            Some(name) => match Cli::try_parse_from(["sonolube", name.as_str(), "--help"]) {
                Ok(Cli {
                    command: Command::Help(_),
                })
                | Err(_) => {
                    eprintln!("sonolube: no command '{name}'");
                    let _ = Cli::command().print_help();
                    ExitCode::from(2)
                }
                Ok(cli) => dispatch(cli.command),
            },
            None => {
                let _ = Cli::command().print_help();
                ExitCode::SUCCESS
            }
        },
    }
}

fn main() -> ExitCode {
    match Cli::try_parse() {
        Ok(cli) => dispatch(cli.command),
        Err(error) => {
            let _ = error.print();
            ExitCode::from(if error.use_stderr() { 2 } else { 0 })
        }
    }
}
