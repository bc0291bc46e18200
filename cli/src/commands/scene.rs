//! `sonolube scene`: runs a scene closed loop on the host ([`sonolube_sim::ClosedLoop`]),
//! writes its time series as CSV and an SVG plot, and prints the model variant the controller
//! runs and why (chosen by [`sonolube::variant::select`], as the firmware logs it at scene
//! start), the metrics and the verdict of each of the scene's criteria. `--all` prints one line
//! per scene: its verdicts, then the model it ran.
//!
//! ```text
//! sonolube scene NAME [--out DIR] [--file PATH.toml] [--commission] [--csv all|none|every N]
//! sonolube scene --all [--out DIR]
//! sonolube scene NAME|--all --seeds N|A-B [--plot PATH.svg]
//! sonolube scene NAME --mismatch|--envelope|--noise|--resonators [--seeds N|A-B] [--out DIR]
//! sonolube scene NAME --mismatch --pinned [--seeds N|A-B]
//! ```
//!
//! The mismatch grid runs `freq auto` before `start` (the search, then the tracker, on the
//! transducer's complex envelope): a resonance known only to +-0.5 % must be followed.
//! `--pinned` holds the drive at the scene's frequency instead.
//!
//! `--commission` runs the scene as if it had `commission = true`: the firmware's `commission`
//! first measures f0, Q and mu0 on the simulated rig ([`sonolube_sim::commission_rig`]), the
//! run's controller uses them, and the report starts with what was measured (against the
//! declared and the true values) and the same values as `f64` bits, which the QEMU check
//! compares with the firmware's.
//!
//! `--seeds`, `--mismatch`, `--envelope`, `--noise` and `--resonators` are the robustness sweeps ([`robust`]):
//! many runs over every core, a table per criterion (pass rate, percentiles, worst run), a
//! closing one-line summary, exit 0 only when every run passes.
//!
//! `NAME` is a built-in scene (`scenes/*.toml`, compiled in); `--file` runs any scene file
//! (its `name` must match `NAME` when both are given). Files go to `DIR` (default
//! `target/scenes/`): `NAME.csv` and `NAME.svg`. Exit status: 0 when every criterion passes;
//! 1 when one fails, or the scene cannot run: a `--file` that cannot be read or breaks the
//! schema, or a scene whose values are each in range but cannot build a run together (the
//! message names the scene values and why, see `why.rs`); 2 for a usage error (an unknown
//! option or scene name, a missing value, `NAME` and `--file` naming different scenes). The
//! output is deterministic.
//!
//! Before a run the scene is judged against what its physics and its controller allow
//! ([`sonolube::scene::feasibility`]): a target beyond the drive's reach, a speed below the
//! sliding threshold, cell noise larger than the band are refused with the key and the number
//! that fails (exit 1); where the scene may hold with no margin, the report ends with a
//! `warning:` line.
//!
//! A long run shows its progress on a terminal (on stderr; nothing when stderr is not a
//! terminal). `--csv none` writes no CSV and `--csv every N` one row in N (rows where the
//! supervisor changes state are always kept): a 60 s scene at 100 kHz is 6 million rows.
//! The SVG is drawn from the rows kept (with `none`, about 20,000 of them).
//!
//! # CSV columns
//!
//! One row per control step; friction forces are magnitudes.
//!
//! | column | unit | meaning |
//! |---|---|---|
//! | `step` | 1 | control step, from 1 |
//! | `time_s` | s | time of the step's sample |
//! | `target` | | the scene's target, `kind:value` as in the protocol |
//! | `target_friction_n` | N | friction the target asks for (from the plant's true natural friction or load) |
//! | `estimated_friction_n` | N | the controller's filtered friction measurement |
//! | `true_friction_n` | N | the plant's friction |
//! | `quantity` | | what the criteria judge: `ratio`, `coef` or `force_n` |
//! | `target_value`, `true_value` | quantity | target and plant value in that quantity |
//! | `error_pct` | % | `(true - target) / target` |
//! | `drive_amplitude` | fraction of full scale | drive command for the next period |
//! | `vibration_amplitude` | fraction of full scale | the transducer's envelope |
//! | `normal_load_n` | N | the plant's normal load |
//! | `state`, `reason` | | supervisor state and reason of its last transition |
//! | `at_limit` | 0/1 | drive command at the actuator's ceiling |
//! | `sensor_fault` | | fault the sensing chain found (`-` for none) |
//! | `injected_fault` | 0/1 | a scene fault acts on the sample |

mod csv;
mod figure;
mod grid;
mod report;
pub mod robust;
mod spread;
mod sweep;
mod why;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::scene_file::LoadedScene;
use figure::svg;
use report::{pass, report};
use sonolube::scene::{SCENES, Scene};
use sonolube_sim::{ClosedLoop, RunSummary};

pub use csv::csv;
pub use report::{model_line, model_name, short};

/// The command line of `sonolube scene`.
#[derive(clap::Parser, Debug)]
#[command(
    name = "scene",
    bin_name = "sonolube scene",
    about = "Run a scene closed loop on the host: CSV, SVG, the model it runs and why, each criterion's verdict",
    args_override_self = true,
    after_help = "sonolube scene NAME [--out DIR] [--file PATH.toml] [--model VARIANT] [--commission] [--csv all|none|every N]\n\
                  sonolube scene --all [--out DIR]\n\
                  sonolube scene NAME|--all --seeds N|A-B [--plot PATH.svg]\n\
                  sonolube scene NAME --mismatch|--envelope|--noise|--resonators [--seeds N|A-B] [--out DIR]\n\
                  sonolube scene NAME --mismatch --pinned [--seeds N|A-B]\n\n\
                  Exit status: 0 every criterion passes (every run of a sweep); 1 one fails, or \
                  the scene cannot run (a file that cannot be read or is invalid, values that \
                  cannot build a run); 2 a usage error."
)]
pub struct Args {
    /// A built-in scene (scenes/*.toml, compiled in).
    pub name: Option<String>,
    /// Every built-in scene: one line each, its verdicts, then the model it ran.
    #[arg(long)]
    pub all: bool,
    /// Where NAME.csv and NAME.svg go.
    #[arg(long, value_name = "DIR", default_value = "target/scenes")]
    pub out: PathBuf,
    /// Run a scene file (its `name` must be NAME when both are given).
    #[arg(long, value_name = "PATH.toml")]
    pub file: Option<PathBuf>,
    /// Force a fixed-point model variant (a name of docs/speed.md's table).
    #[arg(long, value_name = "VARIANT")]
    pub model: Option<String>,
    /// Run as if the scene had `commission = true`: measure f0, Q, tau and mu0 first.
    #[arg(long)]
    pub commission: bool,
    /// The CSV's rows: all, none (the SVG from about 20,000 kept steps) or every N (one step
    /// in N, plus every change of the supervisor's state).
    #[arg(long, value_name = "all|none|every N")]
    pub csv: Option<String>,
    /// Noise seeds of a sweep: N (seeds 1 to N) or A-B.
    #[arg(long, value_name = "N|A-B")]
    pub seeds: Option<String>,
    /// A sweep's distributions as an SVG plot.
    #[arg(long, value_name = "PATH.svg")]
    pub plot: Option<PathBuf>,
    /// Sweep the mismatch grid (plant mu, k_t, cell gain, f0), drive `freq auto`.
    #[arg(long)]
    pub mismatch: bool,
    /// Sweep the operating envelope (load, speed, reduction) as scene files.
    #[arg(long)]
    pub envelope: bool,
    /// Sweep the sensor noise level.
    #[arg(long)]
    pub noise: bool,
    /// Sweep resonators (f0 x Q), drive `freq auto`.
    #[arg(long)]
    pub resonators: bool,
    /// With --mismatch: hold the drive at the scene's frequency instead of `freq auto`.
    #[arg(long)]
    pub pinned: bool,
}

/// `--csv every N` is two words on the command line; clap reads the option's value as one.
fn join_csv_every(args: &[String]) -> Vec<String> {
    let mut joined = Vec::with_capacity(args.len());
    let mut rest = args.iter().peekable();
    while let Some(arg) = rest.next() {
        joined.push(arg.clone());
        if arg == "--csv" && rest.peek().is_some_and(|v| *v == "every") {
            rest.next();
            match rest.next() {
                Some(n) => joined.push(format!("every {n}")),
                None => joined.push("every".into()),
            }
        }
    }
    joined
}

/// Entry point: `args` are the arguments after `scene`.
pub fn run(args: &[String]) -> ExitCode {
    let args = match super::args::parse::<Args>(&join_csv_every(args)) {
        Ok(args) => args,
        Err(code) => return code,
    };
    let (name, out, file, all, commission) =
        (args.name, args.out, args.file, args.all, args.commission);
    let plot = args.plot;
    let pinned = args.pinned;
    let forced = match &args.model {
        None => None,
        Some(value) => match sonolube::variant::find(value) {
            Some(v) if v.form == sonolube::variant::Form::Fixed => Some(v),
            _ => return usage(&format!("no fixed-point model variant '{value}'")),
        },
    };
    let seeds = match &args.seeds {
        None => None,
        Some(value) => match robust::parse_seeds(value) {
            Ok(list) => Some(list),
            Err(problem) => return usage(&problem),
        },
    };
    let sweeps = [
        (
            args.mismatch,
            robust::Sweep::Mismatch(robust::GridDrive::FreqAuto),
        ),
        (args.envelope, robust::Sweep::Envelope),
        (args.noise, robust::Sweep::Noise),
        (args.resonators, robust::Sweep::Resonators),
    ];
    let mut chosen = sweeps.into_iter().filter(|(on, _)| *on).map(|(_, s)| s);
    let mut sweep = chosen.next();
    if chosen.next().is_some() {
        return usage("one of --mismatch, --envelope, --noise, --resonators at a time");
    }
    let rows = match args.csv.as_deref() {
        None | Some("all") => Rows::All,
        Some("none") => Rows::None,
        Some(every) if every.starts_with("every") => {
            match every["every".len()..].trim().parse::<u32>() {
                Ok(n) if n >= 1 => Rows::Every(n),
                _ => return usage("--csv every needs a whole number N >= 1"),
            }
        }
        Some(_) => return usage("--csv takes all, none or every N"),
    };
    if pinned {
        match sweep {
            Some(robust::Sweep::Mismatch(_)) => {
                sweep = Some(robust::Sweep::Mismatch(robust::GridDrive::Pinned));
            }
            _ => return usage("--pinned goes with --mismatch"),
        }
    }
    let robust = seeds.is_some() || sweep.is_some();
    if rows != Rows::All && (all || robust) {
        return usage("--csv goes with a single run of one scene");
    }
    if plot.is_some() && !robust {
        return usage("--plot goes with --seeds, --mismatch, --envelope, --noise or --resonators");
    }
    if all {
        if name.is_some() || file.is_some() || forced.is_some() {
            return usage("--all takes no scene name, --file or --model");
        }
        if sweep.is_some() {
            return usage(
                "--mismatch, --envelope, --noise and --resonators take one scene NAME, not --all",
            );
        }
        if let Some(seeds) = &seeds {
            let scenes = robust::builtin();
            return robust::run(
                &scenes,
                robust::Sweep::Seeds,
                Some(seeds),
                plot.as_deref(),
                &out,
            );
        }
        return run_all(&out);
    }
    let loaded;
    let scene = match (&file, &name) {
        (Some(path), _) => {
            loaded = match LoadedScene::load(path) {
                Ok(loaded) => loaded,
                Err(error) => {
                    eprintln!("sonolube scene: the scene cannot run: {error}");
                    return ExitCode::FAILURE;
                }
            };
            let scene = loaded.scene();
            if name.as_deref().is_some_and(|n| n != scene.name) {
                return usage(&format!("{} holds scene '{}'", path.display(), scene.name));
            }
            scene
        }
        (None, Some(name)) => match sonolube::scene::find(name) {
            Some(scene) => *scene,
            None => return usage(&format!("no scene '{name}' (built in: {})", names())),
        },
        (None, None) => return usage("a scene NAME, --file or --all is needed"),
    };
    // `--commission`: as if the scene had `commission = true`.
    let scene = Scene {
        commission: scene.commission || commission,
        ..scene
    };
    if robust {
        if forced.is_some() {
            return usage("--model goes with a single run, not a sweep");
        }
        return robust::run(
            &[scene],
            sweep.unwrap_or(robust::Sweep::Seeds),
            seeds.as_deref(),
            plot.as_deref(),
            &out,
        );
    }
    match run_with(&scene, &out, forced, rows) {
        Ok(run) => {
            print!("{}", run.report);
            exit(run.summary.passed())
        }
        Err(error) => {
            eprintln!("sonolube scene {}: {error}", scene.name);
            ExitCode::FAILURE
        }
    }
}

/// What commissioning measured before the run, against the scene's declared and true values,
/// and the same values as `f64` bits (the QEMU check compares them with the firmware's).
fn commissioned_lines(scene: &Scene<'_>, r: &sonolube::commission::CommissionResult) -> String {
    let speed = scene
        .sliding_velocity_m_per_s
        .first()
        .map_or(0.0, |p| p.value.abs());
    let t = &scene.transducer;
    let mut text = format!(
        "  commissioned: f0 {:.2} +- {:.2} Hz (declared {}, true {}), Q {:.2} +- {:.2} \
         (declared {}, true {}), tau {:.4} +- {:.4} ms from {} ring-down points, mu0 {:.5} +- \
         {:.5} (declared {}, true {}), cell zeros {:.4} N normal, {:.4} N tangential\n",
        r.resonance_hz.value,
        r.resonance_hz.standard_error,
        t.resonance_hz,
        t.resonance_hz,
        r.quality_factor.value,
        r.quality_factor.standard_error,
        t.quality_factor,
        t.quality_factor,
        r.time_constant_s.value * 1e3,
        r.time_constant_s.standard_error * 1e3,
        r.ring_down_points,
        r.natural_coefficient.value,
        r.natural_coefficient.standard_error,
        scene.controller.natural_coefficient(speed),
        scene.plant.natural_coefficient(speed),
        r.normal.zero_n,
        r.tangential.zero_n,
    );
    let bits = [
        r.resonance_hz,
        r.quality_factor,
        r.time_constant_s,
        r.natural_coefficient,
    ]
    .map(|m| format!("{:x} {:x}", m.value.to_bits(), m.standard_error.to_bits()));
    let _ = writeln!(
        text,
        "  commissioned bits f0 {} q {} tau {} mu0 {}",
        bits[0], bits[1], bits[2], bits[3]
    );
    text
}

fn usage(problem: &str) -> ExitCode {
    super::args::usage_error::<Args>(problem)
}

fn exit(passed: bool) -> ExitCode {
    if passed {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

fn names() -> String {
    SCENES.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
}

fn run_all(out: &Path) -> ExitCode {
    let (mut passed, mut failed) = (0, 0);
    for scene in SCENES {
        let line = match run_one(scene, out) {
            Ok(SceneRun { summary, model, .. }) => {
                let verdicts: Vec<String> = summary
                    .verdicts
                    .iter()
                    .map(|v| short(&v.criterion, v.measured))
                    .collect();
                let ok = summary.passed();
                if ok {
                    passed += 1
                } else {
                    failed += 1
                }
                format!(
                    "{} {:<13} {}; {model}",
                    pass(ok),
                    scene.name,
                    verdicts.join(", ")
                )
            }
            Err(error) => {
                failed += 1;
                format!("FAIL {:<13} cannot run: {error}", scene.name)
            }
        };
        println!("{line}");
    }
    println!("{passed} passed, {failed} failed");
    exit(failed == 0)
}

/// What [`run_one`] returns.
#[derive(Debug, Clone)]
pub struct SceneRun {
    /// The judge's summary.
    pub summary: RunSummary,
    /// The text `sonolube scene NAME` prints.
    pub report: String,
    /// The model the controller ran, in a few words ([`model_name`]).
    pub model: String,
}

/// Runs `scene`, writes its CSV and SVG to `out`, returns the summary, the report text and
/// the model the controller ran: the variant the host selects for it
/// ([`crate::speed::table_rs::select_on_host`]: the firmware's choice for a built-in scene,
/// and for a scene file one measured against the reference when the file is loaded).
pub fn run_one(scene: &Scene<'_>, out: &Path) -> Result<SceneRun, String> {
    run_forced(scene, out, None)
}

/// [`run_one`], with the controller forced to run `forced` (a fixed-point model variant)
/// instead of the selected one: `sonolube scene NAME --model VARIANT`.
pub fn run_forced(
    scene: &Scene<'_>,
    out: &Path,
    forced: Option<&sonolube::variant::Variant>,
) -> Result<SceneRun, String> {
    run_with(scene, out, forced, Rows::All)
}

/// Which rows of a run the CSV gets (`--csv`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rows {
    /// Every control step (the default).
    All,
    /// No CSV file.
    None,
    /// One step in N, and every step where the supervisor changes state.
    Every(u32),
}

/// Rows an SVG needs at most: with `--csv none` the run keeps one step in
/// `step_count / SVG_ROWS`.
const SVG_ROWS: u32 = 20_000;

/// [`run_forced`] writing the CSV rows `rows` asks for, with a progress bar on a terminal.
pub fn run_with(
    scene: &Scene<'_>,
    out: &Path,
    forced: Option<&sonolube::variant::Variant>,
    rows: Rows,
) -> Result<SceneRun, String> {
    let built = match forced {
        Some(variant) => {
            let model = sonolube::variant::fixed::fixed_model(scene, variant)
                .map_err(|e| format!("{}: {e}", variant.name))?;
            ClosedLoop::with_model(scene, model)
        }
        None => {
            let selection = crate::speed::table_rs::select_on_host(scene)
                .map_err(|error| why::cannot_select(scene, &error))?;
            if selection.refused() {
                return Err(format!(
                    "scene {} refused at load: controller {selection}",
                    scene.name
                ));
            }
            ClosedLoop::with_selection(scene, selection)
        }
    };
    let mut sim = built.map_err(|e| why::cannot_run(scene, &e))?;
    // What cannot work is refused before the run, with the number that fails (issue 26).
    let feasibility = sonolube::scene::feasibility::check(scene, sim.station().model());
    if let Some(refusal) = feasibility.refusal() {
        return Err(refusal.to_string());
    }
    let steps = scene.step_count();
    let every = match rows {
        Rows::All => 1,
        Rows::Every(n) => n,
        Rows::None => steps.div_ceil(SVG_ROWS).max(1),
    };
    let mut records = Vec::with_capacity((steps / every) as usize + 1);
    // Hidden when stderr is not a terminal (indicatif's default draw target).
    let progress = indicatif::ProgressBar::new(u64::from(steps));
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{prefix} [{bar:30}] {percent:>3} % of {len} steps, {eta} left",
    ) {
        progress.set_style(style.progress_chars("=> "));
    }
    progress.set_prefix(scene.name.to_string());
    let mut last_state = None;
    while let Some(record) = sim.step() {
        if record.step % 4096 == 0 {
            progress.set_position(u64::from(record.step));
        }
        if record.step % every == 0 || last_state != Some(record.state) || record.step == 1 {
            last_state = Some(record.state);
            records.push(record);
        }
    }
    progress.finish_and_clear();
    let summary = sim.summary();
    let station = sim.station();
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let csv_path = out.join(format!("{}.csv", scene.name));
    let svg_path = out.join(format!("{}.svg", scene.name));
    if rows != Rows::None {
        std::fs::write(&csv_path, csv(&records))
            .map_err(|e| format!("{}: {e}", csv_path.display()))?;
    }
    std::fs::write(&svg_path, svg(scene, &summary, &records))
        .map_err(|e| format!("{}: {e}", svg_path.display()))?;
    let mut text = String::new();
    if let Some(result) = sim.commissioned() {
        text.push_str(&commissioned_lines(scene, result));
    }
    text.push_str(&report(scene, station, &summary, &records));
    for warning in feasibility.warnings() {
        let _ = writeln!(text, "  {warning}");
    }
    let _ = match rows {
        Rows::None => writeln!(text, "  wrote {} (no CSV)", svg_path.display()),
        Rows::All => writeln!(
            text,
            "  wrote {} and {}",
            csv_path.display(),
            svg_path.display()
        ),
        Rows::Every(n) => writeln!(
            text,
            "  wrote {} (one step in {n}) and {}",
            csv_path.display(),
            svg_path.display()
        ),
    };
    Ok(SceneRun {
        summary,
        report: text,
        model: model_name(station),
    })
}
