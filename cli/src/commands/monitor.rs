//! `sonolube monitor`: talks to the firmware's command interface over its UART (QEMU's socket,
//! TCP or a serial port): sends commands and prints their replies, records telemetry to CSV and
//! SVG, and runs the acceptance test of the interface. The logic is in
//! [`crate::monitor`]; this module reads the arguments and prints.
//!
//! ```text
//! sonolube monitor --connect unix:/tmp/uart.sock -c "target coef 0.15" -c start -c "wait 50"
//! sonolube monitor --connect serial:/dev/ttyACM0 --script session.txt --csv run.csv --svg run.svg
//! sonolube monitor --connect unix:/tmp/uart.sock --acceptance --csv target/monitor/acceptance.csv
//! sonolube monitor --connect unix:/tmp/uart.sock --commission
//! ```
//!
//! Exit status: 0 when every reply was `ok` (and the acceptance test passed, when asked); 1 when
//! a command got an `err` reply (unless `--allow-errors`), a check failed, the connection was
//! lost or timed out, the firmware sent malformed lines, or an output file could not be
//! written; 2 for a usage error. The output files (`--csv`, `--svg`) are checked before
//! anything is sent: a path that cannot be written ends the run there, with exit status 1 and
//! the reason, so a session with the board is never run only to lose its record.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use crate::monitor::{
    AcceptanceConfig, CommissionOutcome, Endpoint, Link, LinkOptions, Session, Step, parse_script,
    parse_step, run_acceptance, run_commission, run_steps, telemetry_csv, telemetry_svg,
};

/// The command line of `sonolube monitor`.
#[derive(clap::Parser, Debug)]
#[command(
    name = "monitor",
    bin_name = "sonolube monitor",
    about = "Talk to the firmware: send commands and print their replies ('> command', '< reply'), \
             record the telemetry, run the acceptance test of the command interface",
    after_help = "The --csv and --svg paths are checked before connecting: if one cannot be \
                  written, nothing is sent.\n\n\
                  Exit status: 0 all ok; 1 an err reply, a failed check, a lost or silent \
                  connection, malformed lines from the firmware, or an unwritable output file; \
                  2 a usage error."
)]
pub struct Args {
    /// unix:PATH (Unix socket, QEMU -chardev socket), tcp:HOST:PORT, or serial:DEV[@BAUD]
    /// (8N1, default 115200 baud); sockets are retried until they accept or
    /// --connect-timeout-ms passes.
    #[arg(long, value_name = "ENDPOINT")]
    pub connect: Option<String>,
    /// Send CMD (repeatable; -c and --script run in the order given).
    #[arg(short = 'c', long = "command", value_name = "CMD")]
    pub commands: Vec<String>,
    /// Send FILE's lines: one command per line, blank lines and lines starting with '#'
    /// skipped, and 'wait MS': MS ms of firmware time (telemetry t_us) while telemetry is on,
    /// of wall time while it is off.
    #[arg(long, value_name = "FILE")]
    pub script: Vec<String>,
    /// After the commands: 'commission' (drive off, contact loaded and sliding), then
    /// 'commission status' every 20 ms until it ends; exit 1 unless it is done.
    #[arg(long)]
    pub commission: bool,
    /// Run the acceptance test after the commands ('monitor acceptance: N passed, M failed');
    /// exit 1 unless all pass.
    #[arg(long)]
    pub acceptance: bool,
    /// Write every telemetry record: header row, one column per field.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Plot the telemetry: friction target and estimate, drive amplitude, forces.
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// Exit 0 even when a command got an err reply.
    #[arg(long)]
    pub allow_errors: bool,
    /// Longest wait for a reply, and longest telemetry silence while waiting on it (default 5000).
    #[arg(long, value_name = "MS")]
    pub timeout_ms: Option<String>,
    /// How long to retry connecting to a socket (default 10000).
    #[arg(long, value_name = "MS")]
    pub connect_timeout_ms: Option<String>,
    /// Seed of the acceptance flood (decimal or 0x hex; default 0x50a01be5).
    #[arg(long, value_name = "N")]
    pub seed: Option<String>,
    /// Malformed lines in the acceptance flood (default 10000).
    #[arg(long, value_name = "N")]
    pub flood_lines: Option<String>,
    /// Flood lines sent ahead of their replies (default 4).
    #[arg(long, value_name = "N")]
    pub window: Option<String>,
    /// Telemetry rate of the acceptance test (default 1000; lower it on a 115200-baud serial
    /// port, the observation lengthens to match).
    #[arg(long, value_name = "N")]
    pub telemetry_hz: Option<String>,
}

/// The parsed command line.
struct Options {
    endpoint: Endpoint,
    steps: Vec<Step>,
    acceptance: bool,
    /// Run `commission` after the commands and wait for its result.
    commission: bool,
    csv: Option<PathBuf>,
    svg: Option<PathBuf>,
    allow_errors: bool,
    link: LinkOptions,
    config: AcceptanceConfig,
}

/// Entry point: `args` are the arguments after `monitor`.
pub fn run(args: &[String]) -> ExitCode {
    let options = match parse_args(args) {
        Ok(Some(options)) => options,
        Ok(None) => {
            print!(
                "{}",
                <Args as clap::CommandFactory>::command().render_long_help()
            );
            return ExitCode::SUCCESS;
        }
        Err(problem) => return super::args::usage_error::<Args>(&problem),
    };
    if options.steps.is_empty() && !options.acceptance && !options.commission {
        return super::args::usage_error::<Args>(
            "nothing to do: give -c, --script, --commission or --acceptance",
        );
    }
    for path in [&options.csv, &options.svg].into_iter().flatten() {
        if let Err(why) = check_writable(path) {
            eprintln!("sonolube monitor: {why} (checked before connecting; nothing was sent)");
            return ExitCode::FAILURE;
        }
    }
    if let (Some(csv), Some(svg)) = (&options.csv, &options.svg)
        && csv == svg
    {
        eprintln!(
            "sonolube monitor: --csv and --svg both name {}: one would overwrite the other",
            csv.display()
        );
        return ExitCode::from(2);
    }
    let mut link = match Link::connect(&options.endpoint, options.link) {
        Ok(link) => link,
        Err(error) => {
            eprintln!("sonolube monitor: {error}");
            return ExitCode::FAILURE;
        }
    };
    let mut failed = false;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let _ = writeln!(out, "# connected to {}", options.endpoint);
    let mut connected = true;
    match run_steps(&mut link, &options.steps, &mut out) {
        Ok(outcome) => {
            if outcome.errors + outcome.malformed > 0 {
                let _ = writeln!(
                    out,
                    "# {} of {} commands got an err reply, {} a malformed reply{}",
                    outcome.errors,
                    outcome.commands,
                    outcome.malformed,
                    if options.allow_errors {
                        " (allowed)"
                    } else {
                        ""
                    }
                );
                failed |= !options.allow_errors || outcome.malformed > 0;
            }
        }
        Err(error) => {
            eprintln!("sonolube monitor: {error}");
            failed = true;
            connected = false;
        }
    }
    if options.commission && connected {
        match run_commission(&mut link, &mut out) {
            Ok(CommissionOutcome::Done(_)) => {}
            Ok(CommissionOutcome::Refused(_)) => failed = true,
            Ok(CommissionOutcome::TimedOut) => {
                let _ = writeln!(out, "# commissioning did not end");
                failed = true;
            }
            Err(error) => {
                eprintln!("sonolube monitor: {error}");
                failed = true;
                connected = false;
            }
        }
    }
    if options.acceptance {
        if connected {
            let _ = writeln!(
                out,
                "# acceptance test on {} (flood seed {:#x}, {} lines)",
                options.endpoint, options.config.seed, options.config.flood_lines
            );
            let report = run_acceptance(&mut link, &options.config, &mut out);
            let _ = writeln!(out, "{}", report.summary());
            failed |= !report.all_passed();
        } else {
            let _ = writeln!(out, "monitor acceptance: not run, the connection failed");
        }
    }
    let session = link.finish();
    failed |= !summarize(&session, &mut out);
    let band = options.acceptance.then_some(options.config.tolerance_pct);
    let title = format!(
        "sonolube monitor {}: {} telemetry records",
        options.endpoint,
        session.telemetry.received()
    );
    let records = session.telemetry.records();
    if let Some(path) = &options.csv {
        failed |= !write(&mut out, path, &telemetry_csv(records));
    }
    if let Some(path) = &options.svg {
        failed |= !write(&mut out, path, &telemetry_svg(&title, records, band));
    }
    let _ = out.flush();
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// Prints what was received; false when the firmware broke the protocol.
fn summarize(session: &Session, out: &mut dyn Write) -> bool {
    let log = &session.telemetry;
    let gaps = log.gaps();
    let _ = writeln!(
        out,
        "# received {} lines: {} telemetry records ({} kept), seq gaps {} ({} records missing, \
         {} accounted by lost, {} unexplained, {} restarts)",
        session.lines,
        log.received(),
        log.records().len(),
        gaps.gaps,
        gaps.missing,
        gaps.explained,
        gaps.unexplained,
        gaps.restarts
    );
    let anomalies = &session.anomalies;
    if let Some(partial) = &anomalies.partial_first_line {
        let _ = writeln!(out, "# first line discarded as partial: {partial:?}");
    }
    if anomalies.is_clean() {
        return true;
    }
    eprintln!(
        "sonolube monitor: the firmware sent {} malformed lines and {} replies without a command",
        anomalies.malformed, anomalies.unsolicited
    );
    for example in &anomalies.examples {
        eprintln!("  {example}");
    }
    false
}

/// Checks that `path` can be written: its folder exists or is created, and the file opens for
/// writing (an existing file is left as it is; a file created by the check is removed again).
fn check_writable(path: &Path) -> Result<(), String> {
    if path.is_dir() {
        return Err(format!("{}: is a directory, not a file", path.display()));
    }
    if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create its folder: {e}", path.display()))?;
    }
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .map_err(|e| format!("{}: cannot be written: {e}", path.display()))?;
    if !existed {
        std::fs::remove_file(path)
            .map_err(|e| format!("{}: cannot remove the probe file: {e}", path.display()))?;
    }
    Ok(())
}

fn write(out: &mut dyn Write, path: &Path, text: &str) -> bool {
    let result = match path.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir),
        None => Ok(()),
    }
    .and_then(|()| std::fs::write(path, text));
    match result {
        Ok(()) => {
            let _ = writeln!(out, "# wrote {}", path.display());
            true
        }
        Err(error) => {
            eprintln!("sonolube monitor: {}: {error}", path.display());
            false
        }
    }
}

fn number<T: std::str::FromStr>(flag: &str, text: &str) -> Result<T, String> {
    text.parse()
        .map_err(|_| format!("{flag} {text}: not a valid number"))
}

fn seed(text: &str) -> Result<u64, String> {
    let parsed = match text.strip_prefix("0x").or_else(|| text.strip_prefix("0X")) {
        Some(hex) => u64::from_str_radix(hex, 16),
        None => text.parse(),
    };
    parsed.map_err(|_| format!("--seed {text}: not a decimal or 0x hex number"))
}

/// `Ok(None)` for `--help`.
fn parse_args(args: &[String]) -> Result<Option<Options>, String> {
    let Some((args, matches)) = super::args::parse_matches::<Args>(args)? else {
        return Ok(None);
    };
    let mut link = LinkOptions::default();
    let mut config = AcceptanceConfig::default();
    // The -c commands and the --script files, in the order given.
    let mut given: Vec<(usize, &str, &String)> = Vec::new();
    for (id, values) in [("commands", &args.commands), ("script", &args.script)] {
        let indices = matches.indices_of(id).into_iter().flatten();
        given.extend(indices.zip(values).map(|(index, value)| (index, id, value)));
    }
    given.sort_by_key(|(index, _, _)| *index);
    let mut steps = Vec::new();
    for (_, id, value) in given {
        if id == "commands" {
            match parse_step(value) {
                Ok(Some(step)) => steps.push(step),
                Ok(None) => return Err(format!("-c {value:?}: no command")),
                Err(why) => return Err(format!("-c: {why}")),
            }
        } else {
            let text =
                std::fs::read_to_string(value).map_err(|e| format!("--script {value}: {e}"))?;
            steps.extend(parse_script(&text).map_err(|e| format!("{value}: {e}"))?);
        }
    }
    if let Some(value) = &args.timeout_ms {
        link.reply_timeout = Duration::from_millis(number::<u64>("--timeout-ms", value)?.max(1));
    }
    if let Some(value) = &args.connect_timeout_ms {
        link.connect_timeout = Duration::from_millis(number("--connect-timeout-ms", value)?);
    }
    if let Some(value) = &args.seed {
        config.seed = seed(value)?;
    }
    if let Some(value) = &args.flood_lines {
        config.flood_lines = number("--flood-lines", value)?;
    }
    if let Some(value) = &args.telemetry_hz {
        config.telemetry_hz = number::<u16>("--telemetry-hz", value)
            .ok()
            .filter(|hz| (1..=10_000).contains(hz))
            .ok_or_else(|| format!("--telemetry-hz {value}: not 1..=10000"))?;
    }
    if let Some(value) = &args.window {
        config.window = number::<usize>("--window", value)?.max(1);
    }
    let endpoint = match &args.connect {
        Some(text) => Endpoint::parse(text)?,
        None => return Err("--connect ENDPOINT is required".into()),
    };
    Ok(Some(Options {
        endpoint,
        steps,
        acceptance: args.acceptance,
        commission: args.commission,
        csv: args.csv,
        svg: args.svg,
        allow_errors: args.allow_errors,
        link,
        config,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn arguments_in_order() {
        let options = parse_args(&args(&[
            "--connect",
            "unix:/tmp/x.sock",
            "-c",
            "status",
            "--command",
            "wait 5",
            "--acceptance",
            "--seed",
            "0x10",
            "--window",
            "0",
            "--timeout-ms",
            "250",
        ]))
        .unwrap()
        .unwrap();
        assert_eq!(options.endpoint, Endpoint::Unix("/tmp/x.sock".into()));
        assert_eq!(
            options.steps,
            [Step::Command("status".into()), Step::Wait(5)]
        );
        assert!(options.acceptance && !options.allow_errors);
        assert_eq!((options.config.seed, options.config.window), (16, 1));
        assert_eq!(options.link.reply_timeout, Duration::from_millis(250));
    }

    #[test]
    fn commands_and_scripts_run_in_the_order_given() {
        let dir =
            std::env::temp_dir().join(format!("sonolube-monitor-order-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let script = dir.join("s.txt");
        std::fs::write(&script, "start\nwait 7\n").unwrap();
        let script = script.to_str().unwrap();
        let options = parse_args(&args(&[
            "-c",
            "status",
            "--script",
            script,
            "--connect",
            "unix:/x",
            "-c",
            "stop",
        ]))
        .unwrap()
        .unwrap();
        assert_eq!(
            options.steps,
            [
                Step::Command("status".into()),
                Step::Command("start".into()),
                Step::Wait(7),
                Step::Command("stop".into()),
            ]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn usage_errors() {
        assert!(parse_args(&args(&["--help"])).unwrap().is_none());
        for bad in [
            &["-c", "status"][..],
            &["--connect"],
            &["--connect", "com1"],
            &["--connect", "unix:/x", "-c", " "],
            &["--connect", "unix:/x", "-c", "wait"],
            &["--connect", "unix:/x", "--seed", "0xzz"],
            &["--connect", "unix:/x", "--script", "/nonexistent/script"],
            &["--connect", "unix:/x", "extra"],
            &["--connect", "unix:/x", "--telemetry-hz", "0"],
        ] {
            assert!(parse_args(&args(bad)).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn output_paths_are_checked_without_leaving_files() {
        let dir = std::env::temp_dir().join(format!("sonolube-monitor-{}", std::process::id()));
        let fresh = dir.join("sub").join("run.csv");
        assert_eq!(check_writable(&fresh), Ok(()));
        assert!(!fresh.exists(), "the probe file is removed");
        assert!(check_writable(&dir).unwrap_err().contains("is a directory"));
        let kept = dir.join("kept.csv");
        std::fs::write(&kept, "old").unwrap();
        assert_eq!(check_writable(&kept), Ok(()));
        assert_eq!(std::fs::read_to_string(&kept).unwrap(), "old");
        // A folder that cannot exist: its parent is a file.
        let under_file = kept.join("x.svg");
        assert!(check_writable(&under_file).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
