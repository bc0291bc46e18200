//! `sonolube dahl-table [--check]`: writes `src/model/dahl/dahl_table_nodes.rs` from the f64
//! reference ([`sonolube_host::dahl_table`]), or checks that the committed file is current.

use std::process::ExitCode;

use crate::speed::repo_root;
use sonolube_host::dahl_table::{PATH, render};

/// The command line of `sonolube dahl-table`.
#[derive(clap::Parser, Debug)]
#[command(
    name = "dahl-table",
    bin_name = "sonolube dahl-table",
    about = "Write src/model/dahl/dahl_table_nodes.rs from the f64 reference (about 80 s), or check it",
    after_help = "Exit status: 0 written (or current), 1 a failed reference or a stale file, 2 usage."
)]
pub struct Args {
    /// Write nothing: exit 1 unless the committed nodes are what the reference gives.
    #[arg(long)]
    pub check: bool,
}

/// Entry point: `args` are the arguments after `dahl-table`.
pub fn run(args: &[String]) -> ExitCode {
    let check = match super::args::parse::<Args>(args) {
        Ok(args) => args.check,
        Err(code) => return code,
    };
    let text = match render() {
        Ok(text) => text,
        Err(e) => {
            eprintln!("sonolube dahl-table: reference failed: {e}");
            return ExitCode::FAILURE;
        }
    };
    let path = repo_root().join(PATH);
    if check {
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        if committed == text {
            println!("{PATH} is current");
            return ExitCode::SUCCESS;
        }
        eprintln!("{PATH} is stale: run `sonolube dahl-table`");
        return ExitCode::FAILURE;
    }
    match std::fs::write(&path, text) {
        Ok(()) => {
            println!("wrote {}", path.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("sonolube dahl-table: {}: {e}", path.display());
            ExitCode::FAILURE
        }
    }
}
