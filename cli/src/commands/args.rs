//! Argument parsing shared by the subcommands: each declares its command line as a
//! `clap::Parser` struct, and these turn clap's outcome into the tool's conventions: `--help`
//! prints on stdout and exits 0; a usage error prints the problem and the usage on stderr and
//! exits 2 (as every subcommand did before clap).

use std::process::ExitCode;

use clap::{ArgMatches, CommandFactory, Parser};

/// The arguments after the subcommand's name, with the tool's name in front for clap.
fn argv(name: &str, args: &[String]) -> Vec<String> {
    std::iter::once(format!("sonolube {name}"))
        .chain(args.iter().cloned())
        .collect()
}

/// clap's own problem statement of an error, without its `error: ` prefix, usage and tip.
fn problem(error: &clap::Error) -> String {
    let text = error.render().to_string();
    let first = text.lines().next().unwrap_or("").trim();
    first.strip_prefix("error: ").unwrap_or(first).to_string()
}

/// Prints `problem` and the usage of `A` on stderr; exit status 2.
pub fn usage_error<A: CommandFactory>(problem: &str) -> ExitCode {
    let mut command = A::command();
    let name = command.get_bin_name().unwrap_or("sonolube").to_string();
    let usage = command.render_usage().to_string();
    let usage = usage.strip_prefix("Usage: ").unwrap_or(&usage);
    eprint!(
        "{name}: {problem}\nusage: {usage}\n(`{name} --help` says more)\n",
        name = name.trim()
    );
    ExitCode::from(2)
}

/// Parses a subcommand's arguments: the values, or the exit status once `--help` or the usage
/// error has been printed.
pub fn parse<A: Parser>(args: &[String]) -> Result<A, ExitCode> {
    let name = A::command().get_name().to_string();
    A::try_parse_from(argv(&name, args)).map_err(|error| {
        if error.use_stderr() {
            usage_error::<A>(&problem(&error))
        } else {
            // --help (and --version): clap's text on stdout.
            print!("{}", error.render());
            ExitCode::SUCCESS
        }
    })
}

/// Like [`parse`], for a subcommand that needs clap's matches too (the order of its values):
/// `Ok(None)` for `--help`, `Err` with the problem for a usage error (not printed).
pub fn parse_matches<A: Parser>(args: &[String]) -> Result<Option<(A, ArgMatches)>, String> {
    let mut command = A::command();
    let name = command.get_name().to_string();
    let matches = match command.try_get_matches_from_mut(argv(&name, args)) {
        Ok(matches) => matches,
        Err(error) if !error.use_stderr() => return Ok(None),
        Err(error) => return Err(problem(&error)),
    };
    let values = A::from_arg_matches(&matches).map_err(|e| problem(&e))?;
    Ok(Some((values, matches)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::{dahl_table, docs, eval, monitor, papers, scene, speed};

    /// clap's own consistency checks of every subcommand's declaration (names, groups,
    /// `requires`), which it otherwise runs only when an argument reaches the broken part.
    #[test]
    fn every_subcommand_declaration_is_consistent() {
        dahl_table::Args::command().debug_assert();
        docs::Args::command().debug_assert();
        eval::Args::command().debug_assert();
        monitor::Args::command().debug_assert();
        papers::Args::command().debug_assert();
        scene::Args::command().debug_assert();
        speed::Args::command().debug_assert();
    }

    #[test]
    fn help_exits_0_and_a_usage_error_2() {
        let args = |list: &[&str]| list.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert_eq!(
            parse::<papers::Args>(&args(&["--help"])).unwrap_err(),
            ExitCode::SUCCESS
        );
        assert_eq!(
            parse::<papers::Args>(&args(&["--bogus"])).unwrap_err(),
            ExitCode::from(2)
        );
        assert!(parse::<papers::Args>(&args(&["--check"])).unwrap().check);
        assert_eq!(
            parse::<docs::Args>(&args(&[])).unwrap_err(),
            ExitCode::from(2),
            "docs needs one of --write, --render, --check, --list"
        );
        assert_eq!(
            parse::<docs::Args>(&args(&["--logs", "x"])).unwrap_err(),
            ExitCode::from(2),
            "--logs goes with --check"
        );
        let write = parse::<docs::Args>(&args(&["--write", "a", "b"])).unwrap();
        assert_eq!(write.write, Some(vec!["a".to_string(), "b".to_string()]));
        assert_eq!(
            parse::<docs::Args>(&args(&["--write"])).unwrap().write,
            Some(vec![])
        );
    }
}
