//! `sonolube docs`: every measured figure of the documentation in a block that the command
//! measuring it regenerates (issue 28).
//!
//! ```text
//! sonolube docs --write [NAME...]   measure the named blocks (all when none), rewrite every block
//! sonolube docs --render            rewrite every block from the recorded outputs, measure nothing
//! sonolube docs --check [--logs DIR]
//! sonolube docs --list
//! ```
//!
//! A block in `README.md`, `scenes/README.md` or `docs/*.md` lies between
//!
//! ```text
//! <!-- generated: NAME: COMMAND -->
//! ...
//! <!-- end generated -->
//! ```
//!
//! and [`BLOCKS`] says how it is made: `COMMAND` (run by `bash -c` from the repository root,
//! with this tool first on `PATH` as `sonolube`) measures the figures, its standard output is
//! recorded in `docs/generated/NAME.txt`, and the block is that recording, or what a filter
//! keeps of it, in a `text` fence or as markdown. The same block may appear in several documents.
//!
//! `--check` (the check `docs: every generated block is current` of `scripts/test`) takes
//! seconds: every block must be its recording's rendering and its marker must name the
//! registered command; a [`Cost::Seconds`] block's command is run again and must print its
//! recording; a [`Cost::Slow`] block (QEMU, a cross-build, a sweep of minutes) is checked
//! against its recording only, and against the log `scripts/test` left of the same command in
//! this run (`--logs DIR`, [`Cost::Slow::fresh`]) where there is one.
//!
//! A command's exit status must be 0 or 1 (1 is this tool's "a verdict failed": a sweep with
//! misses, a forced model that fails); anything else (usage, panic, signal) is an error.
//!
//! Exit status: 0 done (or current), 1 a stale block or a failed command, 2 usage.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

use crate::speed::repo_root;

/// How long a block's command takes, which decides what `--check` does with it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cost {
    /// Seconds in all: `--check` runs the command again and compares with the recording.
    Seconds,
    /// QEMU, a cross-build or minutes: `--check` compares the block with the recording of the
    /// last `--write`, and the recording with `fresh` (logs of `scripts/test`, concatenated, in
    /// `--logs DIR`) when those files are there.
    Slow {
        /// Why it is not rerun by the check.
        why: &'static str,
        /// Files in `scripts/test`'s log directory whose concatenation is this command's output.
        fresh: &'static [&'static str],
    },
}

/// One generated block.
#[derive(Debug, Clone, Copy)]
pub struct Block {
    /// Its name in the markers and the recording's file name (`docs/generated/NAME.txt`).
    pub name: &'static str,
    /// The command that measures the figures (bash, from the repository root).
    pub run: &'static str,
    /// A filter from the recording to the block (bash, the recording on stdin); `None`: the
    /// recording itself.
    pub show: Option<&'static str>,
    /// The block is a ```text fence (the command's own words) rather than markdown.
    pub fence: bool,
    pub cost: Cost,
}

/// Every generated block. A new measured figure gets an entry here and markers in its document.
pub const BLOCKS: &[Block] = &[
    Block {
        name: "qemu-reference",
        run: "cargo build --quiet --release --target thumbv7em-none-eabihf -p sonolube-qemu && scripts/qemu-run target/thumbv7em-none-eabihf/release/sonolube-qemu 2>&1",
        show: Some(
            "grep -E 'self-check passed|scene reference: [0-9]+ steps|control step: mean [0-9]+ max|cpu load|(PASS|FAIL) [A-Z]|scene reference: (PASS|FAIL)'",
        ),
        fence: true,
        cost: Cost::Slow {
            why: "a QEMU run of the firmware",
            fresh: &["qemu-run.log"],
        },
    },
    Block {
        name: "scene-all",
        run: "sonolube scene --all",
        show: None,
        fence: true,
        cost: Cost::Seconds,
    },
    Block {
        name: "compliant",
        run: "{ sonolube scene compliant; sonolube scene compliant --model 'Coulomb ratio'; } | grep -E '^  controller model|^  (PASS|FAIL) |^  verdict' | sed -E 's/(controller model [^:]*):.*/\\1/'",
        show: None,
        fence: true,
        cost: Cost::Seconds,
    },
    Block {
        name: "dahl-round-trip",
        run: "cargo test --quiet --release -p sonolube-cli --test dahl_table --test inverse_round_trip -- --nocapture --test-threads 1 2>&1 | sed -E 's/^[.]+//' | grep -E '^T=[0-9]+x[0-9]+: max error|^round trip over|: [0-9]+ targets, worst'",
        show: None,
        fence: true,
        cost: Cost::Slow {
            why: "a test build of the command-line crate",
            fresh: &[],
        },
    },
    Block {
        name: "commission-host",
        run: "sonolube scene resonance-search --commission | grep -E '^  commissioned:'",
        show: None,
        fence: true,
        cost: Cost::Seconds,
    },
    Block {
        name: "resonance-tracking",
        run: "cargo test --quiet -p sonolube-sim --test resonance_scenes -- --nocapture --test-threads 1 2>/dev/null | sed -E 's/^[.]+//' | grep -E '^(resonance|  tracking)'",
        show: None,
        fence: true,
        cost: Cost::Slow {
            why: "a test build of the simulation crate",
            fresh: &[],
        },
    },
    Block {
        name: "closed-loop-tests",
        run: "cargo test --quiet -p sonolube --lib control::closed_loop -- --nocapture --test-threads 1 2>&1 | grep -vE '^(running|test result|$)' | sed -E 's/^[.]+//' | grep -v '^$'",
        show: None,
        fence: true,
        cost: Cost::Slow {
            why: "a test build of the firmware core",
            fresh: &[],
        },
    },
    Block {
        name: "settings-power-cut",
        run: "cargo test --quiet -p sonolube --lib power_cut -- --nocapture --test-threads 1 2>&1 | grep -oE 'power cut: .*'",
        show: None,
        fence: true,
        cost: Cost::Slow {
            why: "a test build of the firmware core",
            fresh: &[],
        },
    },
    Block {
        name: "robustness-sweeps",
        run: "for a in --mismatch '--mismatch --pinned' --resonators --envelope '--noise --seeds 20'; do echo \"\\$ sonolube scene reference $a\"; SONOLUBE_JOBS=2 sonolube scene reference $a | tail -n 1; done",
        show: None,
        fence: true,
        cost: Cost::Seconds,
    },
    Block {
        name: "envelope",
        run: "for a in '' ' --seeds 10'; do echo \"\\$ sonolube scene reference --envelope$a\"; SONOLUBE_JOBS=2 sonolube scene reference --envelope$a | grep -vE '^  (FAIL|INFEASIBLE) '; done",
        show: None,
        fence: true,
        cost: Cost::Seconds,
    },
    Block {
        name: "robustness-seeds",
        run: "echo '$ sonolube scene --all --seeds 100'; SONOLUBE_JOBS=2 sonolube scene --all --seeds 100 | tail -n 1; echo '$ sonolube scene reference --mismatch --seeds 10'; SONOLUBE_JOBS=2 sonolube scene reference --mismatch --seeds 10 | tail -n 1",
        show: None,
        fence: true,
        cost: Cost::Slow {
            why: "1,300 and 810 closed-loop runs, about a minute on 2 cores",
            fresh: &[],
        },
    },
    Block {
        name: "seeds-100",
        run: "SONOLUBE_JOBS=2 sonolube scene --all --seeds 100",
        show: None,
        fence: true,
        cost: Cost::Slow {
            why: "1,300 closed-loop runs, about a minute on 2 cores",
            fresh: &[],
        },
    },
    Block {
        name: "size-g474",
        run: "cargo build --quiet --release --target thumbv7em-none-eabihf -p sonolube-nucleo-g474re && scripts/size-report --top 0 target/thumbv7em-none-eabihf/release/sonolube-nucleo-g474re",
        show: None,
        fence: true,
        cost: Cost::Slow {
            why: "a release cross-build of the G474 firmware",
            fresh: &[],
        },
    },
    Block {
        name: "g474-flash-top",
        run: "board/nucleo-g474re/scripts/flash-top 25",
        show: None,
        fence: true,
        cost: Cost::Slow {
            why: "a release cross-build of the G474 firmware",
            fresh: &[],
        },
    },
    Block {
        name: "g474-scenes",
        run: "board/nucleo-g474re/scripts/scene-list",
        show: None,
        fence: true,
        cost: Cost::Slow {
            why: "a release cross-build of the G474 firmware",
            fresh: &[],
        },
    },
    Block {
        name: "qemu-horn-scenes",
        run: "cargo build --quiet --release --target thumbv7em-none-eabihf -p sonolube-qemu && for s in load-ramp horn-al-ss horn-ss-ss; do scripts/qemu-run target/thumbv7em-none-eabihf/release/sonolube-qemu scene=$s 2>&1; done",
        show: Some(
            "grep -E 'scene [a-z-]+: [0-9]+ steps|controller model|control step: mean|cpu load|scene [a-z-]+: (PASS|FAIL)' | sed -E 's/^[0-9.]+ +INFO +//; s/(controller model [^:]*):.*/\\1/'",
        ),
        fence: true,
        cost: Cost::Slow {
            why: "QEMU runs of the firmware",
            fresh: &[
                "qemu-scene-load-ramp.log",
                "qemu-scene-horn-al-ss.log",
                "qemu-scene-horn-ss-ss.log",
            ],
        },
    },
];

const GENERATED_DIR: &str = "docs/generated";
const END: &str = "<!-- end generated -->";
const BEGIN: &str = "<!-- generated: ";

/// The documents that may hold blocks, relative to the repository root, in a fixed order.
pub fn documents(root: &Path) -> Vec<PathBuf> {
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .map(|dir| {
            dir.filter_map(|entry| entry.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "md"))
                .filter_map(|p| p.strip_prefix(root).ok().map(Path::to_path_buf))
                .collect()
        })
        .unwrap_or_default();
    docs.sort();
    let mut all = vec![
        PathBuf::from("README.md"),
        PathBuf::from("scenes/README.md"),
    ];
    all.append(&mut docs);
    all
}

/// The marker line that opens block `block`.
pub fn begin_line(block: &Block) -> String {
    format!("{BEGIN}{}: {} -->", block.name, block.run)
}

/// The path of a block's recording, relative to the repository root.
pub fn recording_path(name: &str) -> String {
    format!("{GENERATED_DIR}/{name}.txt")
}

/// A block as found in a document.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Found {
    pub name: String,
    /// 1-based line of the opening marker.
    pub line: usize,
    pub begin: String,
    pub body: String,
}

/// The blocks of one document's text, or what is wrong with its markers.
pub fn find_blocks(text: &str) -> Result<Vec<Found>, String> {
    let mut found = Vec::new();
    let mut open: Option<Found> = None;
    for (index, line) in text.lines().enumerate() {
        if let Some(rest) = line.strip_prefix(BEGIN) {
            if let Some(block) = &open {
                return Err(format!(
                    "line {}: a block opens inside block `{}` (line {})",
                    index + 1,
                    block.name,
                    block.line
                ));
            }
            let name = rest.split(':').next().unwrap_or("").trim().to_string();
            open = Some(Found {
                name,
                line: index + 1,
                begin: line.to_string(),
                body: String::new(),
            });
        } else if line == END {
            match open.take() {
                Some(block) => found.push(block),
                None => return Err(format!("line {}: an end marker with no block", index + 1)),
            }
        } else if let Some(block) = &mut open {
            block.body.push_str(line);
            block.body.push('\n');
        }
    }
    match open {
        Some(block) => Err(format!(
            "line {}: block `{}` is never closed ({END})",
            block.line, block.name
        )),
        None => Ok(found),
    }
}

/// What a block named so renders to: its begin line and its body.
pub type Render<'a> = &'a dyn Fn(&str) -> Result<(String, String), String>;

/// The text of a document with every block replaced by `render(name)`, and its begin line by
/// the registered one.
pub fn rewrite(text: &str, render: Render<'_>) -> Result<String, String> {
    find_blocks(text)?;
    let mut out = String::with_capacity(text.len());
    let mut inside = false;
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix(BEGIN) {
            let name = rest.split(':').next().unwrap_or("").trim();
            let (begin, body) = render(name)?;
            out.push_str(&begin);
            out.push('\n');
            out.push_str(&body);
            inside = true;
        } else if line == END {
            inside = false;
            out.push_str(line);
            out.push('\n');
        } else if !inside {
            out.push_str(line);
            out.push('\n');
        }
    }
    if !text.ends_with('\n') {
        out.pop();
    }
    Ok(out)
}

/// Runs `script` with bash from `root`, this tool first on `PATH`, `input` on stdin; returns
/// its standard output.
fn shell(root: &Path, script: &str, input: Option<&str>) -> Result<String, String> {
    let mut path = std::env::current_exe()
        .ok()
        .and_then(|exe| exe.parent().map(Path::to_path_buf))
        .map(|dir| dir.into_os_string())
        .unwrap_or_default();
    if let Some(rest) = std::env::var_os("PATH") {
        path.push(":");
        path.push(rest);
    }
    let mut child = Command::new("bash")
        .arg("-c")
        .arg(script)
        .current_dir(root)
        .env("PATH", path)
        .stdin(if input.is_some() {
            Stdio::piped()
        } else {
            Stdio::null()
        })
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("cannot run bash: {e}"))?;
    if let (Some(text), Some(mut stdin)) = (input, child.stdin.take()) {
        // A filter that stops reading early closes the pipe: not an error of ours.
        let _ = stdin.write_all(text.as_bytes());
    }
    let output = child
        .wait_with_output()
        .map_err(|e| format!("`{script}`: {e}"))?;
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    match output.status.code() {
        Some(0 | 1) => Ok(stdout),
        Some(code) => Err(format!("`{script}` exited with status {code}")),
        None => Err(format!("`{script}` was killed by a signal")),
    }
}

/// The block text (fence included) of a recording.
fn render_body(root: &Path, block: &Block, recording: &str) -> Result<String, String> {
    let mut shown = match block.show {
        Some(filter) => shell(root, filter, Some(recording))?,
        None => recording.to_string(),
    };
    if shown.trim().is_empty() {
        return Err(format!(
            "block `{}`: the output of `{}` is empty",
            block.name, block.run
        ));
    }
    if !shown.ends_with('\n') {
        shown.push('\n');
    }
    Ok(if block.fence {
        format!("```text\n{shown}```\n")
    } else {
        shown
    })
}

fn registered(name: &str) -> Result<&'static Block, String> {
    BLOCKS.iter().find(|b| b.name == name).ok_or_else(|| {
        format!("no block `{name}` is registered (cli/src/commands/docs.rs, BLOCKS)")
    })
}

fn read_recording(root: &Path, name: &str) -> Result<String, String> {
    let path = recording_path(name);
    std::fs::read_to_string(root.join(&path))
        .map_err(|e| format!("{path}: {e}: measure it with `sonolube docs --write {name}`"))
}

/// The first line where `a` (what is there) and `b` (what should be) differ, for a message.
fn first_difference(a: &str, b: &str) -> String {
    let (mut la, mut lb) = (a.lines(), b.lines());
    for number in 1.. {
        match (la.next(), lb.next()) {
            (Some(x), Some(y)) if x == y => continue,
            (x, y) => {
                return format!(
                    "first difference at line {number}:\n      is: {}\n  should: {}",
                    x.unwrap_or("(nothing)"),
                    y.unwrap_or("(nothing)")
                );
            }
        }
    }
    unreachable!("the loop returns at the first difference")
}

/// Every problem of the documents' blocks; empty when all are current.
pub fn check(root: &Path, logs: Option<&Path>, report: &mut dyn FnMut(&str)) -> Vec<String> {
    let mut problems = Vec::new();
    let mut seen = Vec::new();
    for doc in documents(root) {
        let Ok(text) = std::fs::read_to_string(root.join(&doc)) else {
            continue;
        };
        let doc = doc.display().to_string();
        let blocks = match find_blocks(&text) {
            Ok(blocks) => blocks,
            Err(e) => {
                problems.push(format!("{doc}: {e}"));
                continue;
            }
        };
        for found in blocks {
            let at = format!("{doc}:{} block `{}`", found.line, found.name);
            let block = match registered(&found.name) {
                Ok(block) => block,
                Err(e) => {
                    problems.push(format!("{at}: {e}"));
                    continue;
                }
            };
            seen.push(block.name);
            if found.begin != begin_line(block) {
                problems.push(format!(
                    "{at}: its marker does not name the command `{}`: run `sonolube docs --render`",
                    block.run
                ));
            }
            let body = read_recording(root, block.name).and_then(|r| render_body(root, block, &r));
            match body {
                Err(e) => problems.push(format!("{at}: {e}")),
                Ok(body) if body != found.body => problems.push(format!(
                    "{at} is not the output of `{}` (recorded in {}): edited by hand, or recorded since: run `sonolube docs --render` (or `sonolube docs --write {}` to measure again)\n  {}",
                    block.run,
                    recording_path(block.name),
                    block.name,
                    first_difference(&found.body, &body)
                )),
                Ok(_) => report(&format!("{at}: current")),
            }
        }
    }
    for block in BLOCKS {
        if !seen.contains(&block.name) {
            problems.push(format!(
                "block `{}` (`{}`) is in no document",
                block.name, block.run
            ));
        }
        let Ok(recorded) = read_recording(root, block.name) else {
            continue;
        };
        let (label, now) = match block.cost {
            Cost::Seconds => ("this tree's output", shell(root, block.run, None)),
            Cost::Slow { fresh, .. } => {
                let Some(dir) = logs.filter(|_| !fresh.is_empty()) else {
                    continue;
                };
                let mut text = String::new();
                let mut complete = true;
                for file in fresh {
                    match std::fs::read_to_string(dir.join(file)) {
                        Ok(t) => text.push_str(&t),
                        Err(_) => complete = false,
                    }
                }
                if !complete {
                    report(&format!(
                        "block `{}`: no log of this run in {} to compare its recording with",
                        block.name,
                        dir.display()
                    ));
                    continue;
                }
                ("the log of this test run", Ok(text))
            }
        };
        match now {
            Err(e) => problems.push(format!("block `{}`: {e}", block.name)),
            Ok(now) if now != recorded => problems.push(format!(
                "block `{}`: {} is not {label} of `{}`: run `sonolube docs --write {}`\n  {}",
                block.name,
                recording_path(block.name),
                block.run,
                block.name,
                first_difference(&recorded, &now)
            )),
            Ok(_) => report(&format!(
                "block `{}`: {} is {label}",
                block.name,
                recording_path(block.name)
            )),
        }
    }
    problems
}

/// Measures `names` (their commands' outputs into their recordings).
fn measure(root: &Path, names: &[&'static Block]) -> Result<(), String> {
    std::fs::create_dir_all(root.join(GENERATED_DIR))
        .map_err(|e| format!("{GENERATED_DIR}: {e}"))?;
    for block in names {
        eprintln!("sonolube docs: measuring `{}`: {}", block.name, block.run);
        let output = shell(root, block.run, None)?;
        let path = recording_path(block.name);
        std::fs::write(root.join(&path), output).map_err(|e| format!("{path}: {e}"))?;
    }
    Ok(())
}

/// Rewrites every document's blocks from the recordings.
fn render_all(root: &Path) -> Result<(), String> {
    for doc in documents(root) {
        let path = root.join(&doc);
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let render = |name: &str| -> Result<(String, String), String> {
            let block = registered(name)?;
            let recording = read_recording(root, name)?;
            Ok((begin_line(block), render_body(root, block, &recording)?))
        };
        let new = rewrite(&text, &render).map_err(|e| format!("{}: {e}", doc.display()))?;
        if new != text {
            std::fs::write(&path, new).map_err(|e| format!("{}: {e}", doc.display()))?;
            println!("rewrote {}", doc.display());
        }
    }
    Ok(())
}

/// The command line of `sonolube docs`.
#[derive(clap::Parser, Debug)]
#[command(
    name = "docs",
    bin_name = "sonolube docs",
    about = "Regenerate or check the measured figures of README.md, scenes/README.md and docs/*.md (the generated blocks)",
    group(clap::ArgGroup::new("mode").required(true).args(["write", "render", "check", "list"])),
    after_help = "Exit status: 0 done (or current), 1 a stale block or a failed command, 2 usage."
)]
pub struct Args {
    /// Measure the named blocks (every block when none), then rewrite every block.
    #[arg(long, value_name = "NAME", num_args = 0..)]
    pub write: Option<Vec<String>>,
    /// Rewrite every block from the recorded outputs; measure nothing.
    #[arg(long)]
    pub render: bool,
    /// Exit 1 unless every block is current (seconds: what scripts/test runs).
    #[arg(long)]
    pub check: bool,
    /// With --check: scripts/test's log directory, whose QEMU logs the QEMU blocks' recordings must equal.
    #[arg(long, value_name = "DIR", requires = "check")]
    pub logs: Option<PathBuf>,
    /// Every block, its command and what --check does with it.
    #[arg(long)]
    pub list: bool,
}

/// Entry point: `args` are the arguments after `docs`.
pub fn run(args: &[String]) -> ExitCode {
    let root = repo_root();
    let args = match super::args::parse::<Args>(args) {
        Ok(args) => args,
        Err(code) => return code,
    };
    let result = if let Some(names) = &args.write {
        let mut chosen = Vec::new();
        for name in names {
            match registered(name) {
                Ok(block) => chosen.push(block),
                Err(e) => return super::args::usage_error::<Args>(&e),
            }
        }
        if chosen.is_empty() {
            chosen = BLOCKS.iter().collect();
        }
        measure(&root, &chosen).and_then(|()| render_all(&root))
    } else if args.render {
        render_all(&root)
    } else if args.list {
        let mut text = String::new();
        for block in BLOCKS {
            let cost = match block.cost {
                Cost::Seconds => "rerun by --check".to_string(),
                Cost::Slow { why, .. } => format!("recorded ({why})"),
            };
            let _ = writeln!(text, "{:<20} {cost}\n    {}", block.name, block.run);
        }
        print!("{text}");
        Ok(())
    } else {
        let problems = check(&root, args.logs.as_deref(), &mut |line| println!("{line}"));
        if problems.is_empty() {
            println!("every generated block is current ({} blocks)", BLOCKS.len());
            Ok(())
        } else {
            for problem in &problems {
                eprintln!("STALE {problem}");
            }
            Err(format!("{} stale generated block(s)", problems.len()))
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sonolube docs: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_are_found_with_their_lines_and_bodies() {
        let text = "a\n<!-- generated: x: echo 1 -->\n```text\n1\n```\n<!-- end generated -->\nb\n";
        let found = find_blocks(text).unwrap();
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].name, "x");
        assert_eq!(found[0].line, 2);
        assert_eq!(found[0].body, "```text\n1\n```\n");
    }

    #[test]
    fn broken_markers_are_reported() {
        assert!(find_blocks("<!-- generated: x: a -->\n1\n").is_err());
        assert!(find_blocks("1\n<!-- end generated -->\n").is_err());
        assert!(
            find_blocks(
                "<!-- generated: x: a -->\n<!-- generated: y: b -->\n<!-- end generated -->\n"
            )
            .is_err()
        );
    }

    #[test]
    fn rewrite_replaces_bodies_and_markers_and_keeps_the_rest() {
        let text = "a\n<!-- generated: x: old -->\nstale 1\n<!-- end generated -->\nb";
        let new = rewrite(text, &|name| {
            Ok((
                format!("<!-- generated: {name}: new -->"),
                "2\n".to_string(),
            ))
        })
        .unwrap();
        assert_eq!(
            new,
            "a\n<!-- generated: x: new -->\n2\n<!-- end generated -->\nb"
        );
    }

    #[test]
    fn every_block_name_is_unique_and_a_file_name() {
        for (i, block) in BLOCKS.iter().enumerate() {
            assert!(
                block
                    .name
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'),
                "{}",
                block.name
            );
            assert!(!block.run.contains("-->"), "{}", block.name);
            assert!(BLOCKS[..i].iter().all(|b| b.name != block.name));
        }
    }
}
