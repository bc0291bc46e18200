//! Subcommands of the `sonolube` host tool. Each subcommand is one module with a
//! `pub fn run(args: &[String]) -> std::process::ExitCode` (the arguments after its name).
pub mod args;
pub mod dahl_table;
pub mod docs;
pub mod eval;
pub mod monitor;
pub mod papers;
pub mod scene;
pub mod speed;
