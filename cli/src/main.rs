//! `sonolube`: the host command-line tool (see `sonolube help`).

use std::process::ExitCode;

/// Subcommand name, one-line description, entry point.
type Subcommand = (&'static str, &'static str, fn(&[String]) -> ExitCode);

const SUBCOMMANDS: &[Subcommand] = &[
    // (subcommands register here)
    (
        "dahl-table",
        "write the Dahl steady-state table nodes from the f64 reference",
        sonolube_cli::commands::dahl_table::run,
    ),
    (
        "docs",
        "regenerate or check the measured figures of the docs (generated blocks)",
        sonolube_cli::commands::docs::run,
    ),
    (
        "eval",
        "evaluate a model in fixed point and f64 (JSON)",
        sonolube_cli::commands::eval::run,
    ),
    (
        "monitor",
        "talk to the firmware: commands, telemetry CSV/SVG, acceptance test",
        sonolube_cli::commands::monitor::run,
    ),
    (
        "papers",
        "paper numbers vs reference vs fixed point (markdown)",
        sonolube_cli::commands::papers::run,
    ),
    (
        "scene",
        "run a scene closed loop: CSV, SVG and metrics",
        sonolube_cli::commands::scene::run,
    ),
    (
        "speed",
        "speed vs accuracy of every model variant (markdown, SVG, table)",
        sonolube_cli::commands::speed::run,
    ),
];

fn usage() -> String {
    let mut text = String::from("usage: sonolube <command> [arguments]\n\ncommands:\n");
    for (name, about, _) in SUBCOMMANDS {
        text.push_str(&format!("  {name:<10} {about}\n"));
    }
    text
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(command) = args.first() else {
        eprint!("{}", usage());
        return ExitCode::from(2);
    };
    if command == "help" || command == "--help" || command == "-h" {
        print!("{}", usage());
        return ExitCode::SUCCESS;
    }
    match SUBCOMMANDS.iter().find(|(name, _, _)| name == command) {
        Some((_, _, run)) => run(&args[1..]),
        None => {
            eprint!("sonolube: unknown command '{command}'\n\n{}", usage());
            ExitCode::from(2)
        }
    }
}
