//! `sonolube speed`: the speed-versus-accuracy table (issue 7).
//!
//! ```text
//! sonolube speed --qemu LOG [--root DIR]
//! sonolube speed --check [--qemu LOG] [--root DIR]
//! sonolube speed --qemu LOG --keep-host-ratios [--root DIR]
//! ```
//!
//! Reads the instruction counts from `LOG` (the decoded output of the QEMU benchmark build;
//! `-` for stdin), measures the errors of every variant and their host times (release builds
//! only: a debug build's timings mean nothing), and writes `docs/speed.md`, `docs/speed.svg`
//! and `src/variant/table.rs` under `DIR` (default: the repository). `scripts/speed-table`
//! builds and runs the benchmark firmware and calls this with its log.
//!
//! `--keep-host-ratios` writes the files without timing the host: the host ratios are the
//! committed `docs/speed.md`'s (any build). For a change that adds a scene: its errors are
//! measured and every committed count and ratio stays.
//!
//! `--check` writes nothing and times nothing: it regenerates the files from the committed
//! counts (`docs/speed-qemu.txt` unless `--qemu` is given) and the host ratios recorded in the
//! committed `docs/speed.md`, and exits 1 when a committed file differs.
//!
//! Exit status: 0 done (or current), 1 a failed measurement or a stale file, 2 usage.

use std::collections::BTreeMap;
use std::io::Read as _;
use std::path::PathBuf;
use std::process::ExitCode;

use crate::speed::{self, MARKDOWN, QEMU_LOG, markdown, timing};

fn usage(message: &str) -> ExitCode {
    super::args::usage_error::<Args>(message)
}

fn read(path: &str) -> Result<String, String> {
    if path == "-" {
        let mut text = String::new();
        std::io::stdin()
            .read_to_string(&mut text)
            .map_err(|e| format!("stdin: {e}"))?;
        Ok(text)
    } else {
        std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))
    }
}

/// The command line of `sonolube speed`.
#[derive(clap::Parser, Debug)]
#[command(
    name = "speed",
    bin_name = "sonolube speed",
    about = "Speed against accuracy of every model variant: docs/speed.md, docs/speed.svg, src/variant/table.rs",
    after_help = "Exit status: 0 done (or current), 1 a failed measurement or a stale file, 2 usage."
)]
pub struct Args {
    /// The decoded log of the QEMU benchmark build (`-` for stdin); with --check, default docs/speed-qemu.txt.
    #[arg(long, value_name = "LOG")]
    pub qemu: Option<String>,
    /// The repository to write under (default: this one).
    #[arg(long, value_name = "DIR")]
    pub root: Option<PathBuf>,
    /// Write nothing, time nothing: exit 1 when a committed file is not what the committed counts give.
    #[arg(long)]
    pub check: bool,
    /// Keep the committed host ratios instead of timing the host (any build).
    #[arg(long)]
    pub keep_host_ratios: bool,
}

/// Entry point: `args` are the arguments after `speed`.
pub fn run(args: &[String]) -> ExitCode {
    let args = match super::args::parse::<Args>(args) {
        Ok(args) => args,
        Err(code) => return code,
    };
    let (log, check, keep_ratios) = (args.qemu, args.check, args.keep_host_ratios);
    let root = args.root.unwrap_or_else(speed::repo_root);
    let result = if check {
        let log = log.unwrap_or_else(|| root.join(QEMU_LOG).to_string_lossy().into_owned());
        run_check(&log, &root)
    } else {
        match log {
            Some(log) => run_write(&log, &root, keep_ratios),
            None => return usage("--qemu LOG is required (or --check)"),
        }
    };
    match result {
        Ok(code) => code,
        Err(message) => {
            eprintln!("sonolube speed: {message}");
            ExitCode::from(1)
        }
    }
}

fn run_write(log: &str, root: &std::path::Path, keep_ratios: bool) -> Result<ExitCode, String> {
    if cfg!(debug_assertions) && !keep_ratios {
        return Err("host timings need a release build: cargo run --release ... -- speed".into());
    }
    let log_text = read(log)?;
    speed::qemu::parse(&log_text)?; // fail before the long part
    let ratios: BTreeMap<String, f64> = if keep_ratios {
        let committed = std::fs::read_to_string(root.join(MARKDOWN))
            .map_err(|e| format!("{}: {e}", root.join(MARKDOWN).display()))?;
        markdown::host_ratios(&committed)
    } else {
        timing::measure()?
            .into_iter()
            .map(|(name, r)| (name.to_string(), r))
            .collect()
    };
    let outputs = speed::generate(&log_text, &ratios)?;
    for (path, contents) in outputs.files() {
        let full = root.join(path);
        if let Some(dir) = full.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        std::fs::write(&full, contents).map_err(|e| format!("{}: {e}", full.display()))?;
        println!("wrote {}", full.display());
    }
    Ok(ExitCode::SUCCESS)
}

fn run_check(log: &str, root: &std::path::Path) -> Result<ExitCode, String> {
    let committed = std::fs::read_to_string(root.join(MARKDOWN))
        .map_err(|e| format!("{}: {e}", root.join(MARKDOWN).display()))?;
    let outputs = speed::generate(&read(log)?, &markdown::host_ratios(&committed))?;
    let mut stale = Vec::new();
    for (path, contents) in outputs.files() {
        let on_disk = std::fs::read_to_string(root.join(path)).unwrap_or_default();
        if on_disk != contents {
            stale.push(path);
        }
    }
    if stale.is_empty() {
        println!(
            "speed table current: {}",
            outputs.files().map(|f| f.0).join(", ")
        );
        Ok(ExitCode::SUCCESS)
    } else {
        eprintln!(
            "sonolube speed: stale: {} (run scripts/speed-table)",
            stale.join(", ")
        );
        Ok(ExitCode::from(1))
    }
}
