//! `sonolube scene`: runs a scene closed loop on the host ([`sonolube_sim::ClosedLoop`]),
//! writes its time series as CSV and an SVG plot, and prints the model variant the controller
//! runs and why (chosen by [`sonolube::variant::select`], as the firmware logs it at scene
//! start), the metrics and the verdict of each of the scene's criteria. `--all` prints one line
//! per scene: its verdicts, then the model it ran.
//!
//! ```text
//! sonolube scene NAME [--out DIR] [--file PATH.toml]
//! sonolube scene --all [--out DIR]
//! sonolube scene NAME|--all --seeds N|A-B [--plot PATH.svg]
//! sonolube scene NAME --mismatch|--envelope|--noise [--seeds N|A-B] [--out DIR]
//! sonolube scene NAME --mismatch --pinned [--seeds N|A-B]
//! ```
//!
//! The mismatch grid runs `freq auto` before `start` (the search, then the tracker, on the
//! transducer's complex envelope): a resonance known only to +-0.5 % must be followed.
//! `--pinned` holds the drive at the scene's frequency instead.
//!
//! `--seeds`, `--mismatch`, `--envelope` and `--noise` are the robustness sweeps ([`robust`]):
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

const USAGE: &str = "usage: sonolube scene NAME [--out DIR] [--file PATH.toml] [--model VARIANT]\n       \
                     sonolube scene --all [--out DIR]\n       \
                     sonolube scene NAME|--all --seeds N|A-B [--plot PATH.svg]\n       \
                     sonolube scene NAME --mismatch|--envelope|--noise [--seeds N|A-B] [--out DIR]\n       \
                     sonolube scene NAME --mismatch --pinned [--seeds N|A-B]\n\
                     exit status: 0 every criterion passes (every run of a sweep); 1 one fails, \
                     or the scene cannot run (a file that cannot be read or is invalid, values \
                     that cannot build a run); 2 a usage error\n";

/// Entry point: `args` are the arguments after `scene`.
pub fn run(args: &[String]) -> ExitCode {
    let mut name = None;
    let mut out = PathBuf::from("target/scenes");
    let mut file = None;
    let mut forced = None;
    let mut all = false;
    let mut seeds = None;
    let mut plot = None;
    let mut sweep = None;
    let mut pinned = false;
    let mut rest = args.iter();
    while let Some(arg) = rest.next() {
        match arg.as_str() {
            "--all" => all = true,
            "--mismatch" | "--envelope" | "--noise" => {
                if sweep.is_some() {
                    return usage("one of --mismatch, --envelope, --noise at a time");
                }
                sweep = Some(match arg.as_str() {
                    "--mismatch" => robust::Sweep::Mismatch(robust::GridDrive::FreqAuto),
                    "--envelope" => robust::Sweep::Envelope,
                    _ => robust::Sweep::Noise,
                });
            }
            "--out" | "--file" | "--model" | "--seeds" | "--plot" => {
                let Some(value) = rest.next() else {
                    return usage(&format!("{arg} needs a value"));
                };
                match arg.as_str() {
                    "--out" => out = PathBuf::from(value),
                    "--file" => file = Some(PathBuf::from(value)),
                    "--plot" => plot = Some(PathBuf::from(value)),
                    "--model" => match sonolube::variant::find(value) {
                        Some(v) if v.form == sonolube::variant::Form::Fixed => forced = Some(v),
                        _ => return usage(&format!("no fixed-point model variant '{value}'")),
                    },
                    _ => match robust::parse_seeds(value) {
                        Ok(list) => seeds = Some(list),
                        Err(problem) => return usage(&problem),
                    },
                }
            }
            "--pinned" => pinned = true,
            "-h" | "--help" => {
                print!("{USAGE}");
                return ExitCode::SUCCESS;
            }
            flag if flag.starts_with('-') => return usage(&format!("unknown option {flag}")),
            _ if name.is_none() => name = Some(arg.clone()),
            _ => return usage(&format!("unexpected argument {arg}")),
        }
    }
    if pinned {
        match sweep {
            Some(robust::Sweep::Mismatch(_)) => {
                sweep = Some(robust::Sweep::Mismatch(robust::GridDrive::Pinned));
            }
            _ => return usage("--pinned goes with --mismatch"),
        }
    }
    let robust = seeds.is_some() || sweep.is_some();
    if plot.is_some() && !robust {
        return usage("--plot goes with --seeds, --mismatch, --envelope or --noise");
    }
    if all {
        if name.is_some() || file.is_some() || forced.is_some() {
            return usage("--all takes no scene name, --file or --model");
        }
        if sweep.is_some() {
            return usage("--mismatch, --envelope and --noise take one scene NAME, not --all");
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
    match run_forced(&scene, &out, forced) {
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

fn usage(problem: &str) -> ExitCode {
    eprint!("sonolube scene: {problem}\n{USAGE}");
    ExitCode::from(2)
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
    let built = match forced {
        Some(variant) => {
            let model = sonolube::variant::fixed::fixed_model(scene, variant)
                .map_err(|e| format!("{}: {e}", variant.name))?;
            ClosedLoop::with_model(scene, model)
        }
        None => {
            let selection = crate::speed::table_rs::select_on_host(scene)?;
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
    let mut records = Vec::with_capacity(scene.step_count() as usize);
    while let Some(record) = sim.step() {
        records.push(record);
    }
    let summary = sim.summary();
    let station = sim.station();
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let csv_path = out.join(format!("{}.csv", scene.name));
    let svg_path = out.join(format!("{}.svg", scene.name));
    std::fs::write(&csv_path, csv(&records)).map_err(|e| format!("{}: {e}", csv_path.display()))?;
    std::fs::write(&svg_path, svg(scene, &summary, &records))
        .map_err(|e| format!("{}: {e}", svg_path.display()))?;
    let mut text = report(scene, station, &summary, &records);
    let _ = writeln!(
        text,
        "  wrote {} and {}",
        csv_path.display(),
        svg_path.display()
    );
    Ok(SceneRun {
        summary,
        report: text,
        model: model_name(station),
    })
}
