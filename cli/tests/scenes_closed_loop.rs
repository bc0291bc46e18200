//! Closed-loop scene runs (`sonolube_sim`, `sonolube scene`): the acceptance numbers on
//! the three acceptance scenes, measured here from the step records as well as by the judge;
//! every shipped scene runs; runs and their files are the same every time; the command line's
//! exit codes.

use std::path::PathBuf;
use std::process::Command;

use sonolube::protocol::SupervisorState;
use sonolube::scene::{SCENES, Scene, find};
use sonolube::variant::{Reason, select};
use sonolube_cli::commands::scene::{model_line, model_name, run_one};
use sonolube_sim::{ClosedLoop, Measured, RunSummary, StepRecord};

fn run(scene: &Scene<'_>) -> (Vec<StepRecord>, RunSummary) {
    let mut sim = ClosedLoop::new(scene).unwrap_or_else(|e| panic!("{}: {e:?}", scene.name));
    let records: Vec<StepRecord> = std::iter::from_fn(|| sim.step()).collect();
    (records, sim.summary())
}

/// Relative error of the plant's true value against the target, %.
fn error_pct(record: &StepRecord) -> f64 {
    let judged = record.judged.expect("a target");
    100.0 * f64::from(judged.relative_error())
}

fn measured(summary: &RunSummary, index: usize) -> Measured {
    summary.verdicts[index].measured
}

fn scratch_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Settling time after the step at `step_s` into +-`band_pct`, overshoot in % of the step
/// from 1 to `target`, RMS error in % over `from_s..=to_s`, all from the records.
fn step_numbers(
    records: &[StepRecord],
    step_s: f64,
    band_pct: f64,
    window: (f64, f64),
) -> [f64; 3] {
    let after: Vec<&StepRecord> = records
        .iter()
        .filter(|r| f64::from(r.time_s) >= step_s - 1e-7)
        .collect();
    let last_outside = after.iter().rposition(|r| error_pct(r).abs() > band_pct);
    let settle_s = last_outside.map_or(0.0, |i| (i + 1) as f64 * 1e-4);
    let target = f64::from(after[0].judged.expect("a target").target);
    let lowest = after
        .iter()
        .map(|r| f64::from(r.judged.expect("a target").actual))
        .fold(f64::INFINITY, f64::min);
    let overshoot_pct = 100.0 * ((target - lowest) / (1.0 - target)).max(0.0);
    let in_window: Vec<f64> = records
        .iter()
        .filter(|r| (window.0 - 5e-5..=window.1 + 5e-5).contains(&f64::from(r.time_s)))
        .map(error_pct)
        .collect();
    let rms = (in_window.iter().map(|e| e * e).sum::<f64>() / in_window.len() as f64).sqrt();
    [settle_s, overshoot_pct, rms]
}

/// The reference step on its own seed and seven others: every seed must settle within 3 ms,
/// overshoot at most 5 % and hold 1 % RMS (seed 2 used to settle in 3.1 ms, before the
/// prediction passed the cell's lag as a stage of its own; `sonolube scene reference --seeds
/// 100` covers seeds 1-100).
#[test]
fn reference_step_settles_in_3_ms_overshoots_at_most_5_pct_and_holds_1_pct_rms_on_eight_seeds() {
    let reference = find("reference").expect("built in");
    // The acceptance conditions are in the scene: 40 kHz, Q = 100 (tau 0.8 ms), 0.5 % FS
    // noise on both cells, plant mu +20 % and k_t -20 % from the controller's.
    assert!((reference.transducer.envelope_time_constant_s() - 0.8e-3).abs() < 1e-5);
    assert_eq!(reference.tangential_cell.noise_rms_pct_fs, 0.5);
    assert!((reference.mismatch.mu_ratio - 1.2).abs() < 1e-9);
    assert!((reference.mismatch.k_t_ratio.expect("both give k_t") - 0.8).abs() < 1e-9);
    // The scene's own seed and seven others: the numbers are not one noise sequence's luck.
    for seed in [reference.noise_seed, 1, 2, 3, 4, 5, 6, 7] {
        let scene = Scene {
            noise_seed: seed,
            ..*reference
        };
        let (records, summary) = run(&scene);
        let [settle_s, overshoot_pct, rms_pct] = step_numbers(&records, 0.005, 2.0, (0.01, 0.025));
        eprintln!(
            "reference seed {seed}: settles in {:.1} ms, overshoot {overshoot_pct:.2} %, \
             RMS error {rms_pct:.3} %",
            settle_s * 1e3
        );
        assert!(settle_s <= 0.003, "seed {seed}: {settle_s} s");
        assert!(overshoot_pct <= 5.0, "seed {seed}: {overshoot_pct} %");
        assert!(rms_pct <= 1.0, "seed {seed}: {rms_pct} %");
        // The judge measures the same.
        let close = |m: Measured, x: f64, tol: f64| match m {
            Measured::Seconds(v) | Measured::Percent(v) => (f64::from(v) - x).abs() <= tol,
            _ => false,
        };
        assert!(close(measured(&summary, 0), settle_s, 1e-6), "{summary:?}");
        assert!(
            close(measured(&summary, 1), overshoot_pct, 1e-3),
            "{summary:?}"
        );
        assert!(close(measured(&summary, 2), rms_pct, 1e-3), "{summary:?}");
        assert_eq!(summary.passed(), settle_s <= 0.003);
    }
}

#[test]
fn load_ramp_holds_the_coefficient_within_2_pct() {
    let scene = find("load-ramp").expect("built in");
    let (records, summary) = run(scene);
    // 40 N to 240 N in 1 s (0.05 to 1.05 s) with the coefficient target 0.38 held.
    let at = |t: f32| {
        records
            .iter()
            .find(|r| (r.time_s - t).abs() < 5e-5)
            .expect("a step")
    };
    assert_eq!(at(0.05).normal_load_n, 40.0);
    assert!((at(0.55).normal_load_n - 140.0).abs() < 0.01);
    assert_eq!(at(1.05).normal_load_n, 240.0);
    let window: Vec<f64> = records
        .iter()
        .filter(|r| r.time_s >= 0.04 - 5e-5)
        .map(error_pct)
        .collect();
    let ramp: Vec<f64> = records
        .iter()
        .filter(|r| (0.05..1.05).contains(&r.time_s))
        .map(error_pct)
        .collect();
    let largest = |errors: &[f64]| errors.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    eprintln!(
        "load-ramp: largest error {:.3} % from 40 ms, {:.3} % during the ramp ({} samples)",
        largest(&window),
        largest(&ramp),
        ramp.len()
    );
    assert_eq!(ramp.len(), 10_000);
    assert!(largest(&window) <= 2.0, "{}", largest(&window));
    assert!(largest(&ramp) <= 2.0);
    assert!(
        matches!(measured(&summary, 0), Measured::Percent(p) if (f64::from(p) - largest(&window)).abs() < 1e-4),
        "{summary:?}"
    );
    assert!(
        matches!(summary.load_ramp.largest, Measured::Percent(p) if f64::from(p) <= 2.0),
        "{:?}",
        summary.load_ramp
    );
    assert!(
        records
            .iter()
            .all(|r| r.state == SupervisorState::Running || r.time_s < 0.02)
    );
    assert!(summary.passed());
}

#[test]
fn a_disconnected_cell_faults_the_supervisor_with_zero_drive_within_one_period() {
    let scene = find("sensor-fault").expect("built in");
    let (records, summary) = run(scene);
    let onset = records
        .iter()
        .position(|r| r.injected_fault)
        .expect("the fault is injected");
    assert!((records[onset].time_s - 0.015).abs() < 1e-6);
    // Running with the drive on until the fault, then fault and zero drive from the very step
    // that read the first faulty sample, to the end.
    assert_eq!(records[onset - 1].state, SupervisorState::Running);
    assert!(records[onset - 1].drive_amplitude > 0.3);
    let reacted = records[onset..]
        .iter()
        .position(|r| r.state == SupervisorState::Fault && r.drive_amplitude == 0.0)
        .expect("reacts");
    assert_eq!(reacted + 1, 1, "control periods from the onset");
    assert!(
        records[onset..]
            .iter()
            .all(|r| r.state == SupervisorState::Fault && r.drive_amplitude == 0.0)
    );
    assert_eq!(measured(&summary, 0), Measured::Periods(1));
    assert_eq!(summary.faults[0].periods, Some(1));
    assert!(summary.passed());
}

#[test]
fn every_shipped_scene_runs_to_its_end() {
    for scene in SCENES {
        let (records, summary) = run(scene);
        assert_eq!(records.len() as u32, scene.step_count(), "{}", scene.name);
        assert_eq!(
            summary.verdicts.len(),
            scene.criteria.len(),
            "{}",
            scene.name
        );
        assert!(
            records
                .iter()
                .all(|r| (0.0..=1.0).contains(&r.drive_amplitude)),
            "{}",
            scene.name
        );
        eprintln!(
            "{:<13} {} {:?}",
            scene.name,
            if summary.passed() { "PASS" } else { "FAIL" },
            summary
                .verdicts
                .iter()
                .map(|v| v.measured)
                .collect::<Vec<_>>()
        );
        assert!(summary.passed(), "{}: {summary:?}", scene.name);
    }
}

#[test]
fn a_run_and_its_files_are_the_same_every_time() {
    let scene = find("sensor-stuck").expect("built in");
    let (first, _) = run(scene);
    let (second, _) = run(scene);
    assert_eq!(first.len(), second.len());
    for (a, b) in first.iter().zip(&second) {
        // Bit for bit, NaN included.
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        assert_eq!(a.true_friction_n.to_bits(), b.true_friction_n.to_bits());
        assert_eq!(a.drive_amplitude.to_bits(), b.drive_amplitude.to_bits());
    }
    let (one, two) = (scratch_dir("determinism-1"), scratch_dir("determinism-2"));
    let report_one = run_one(scene, &one).expect("writes").report;
    let report_two = run_one(scene, &two).expect("writes").report;
    let strip = |text: &str| -> String {
        text.lines()
            .filter(|l| !l.contains("wrote"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(strip(&report_one), strip(&report_two));
    assert!(report_one.contains("PASS fault with zero drive within 50 period(s)"));
    for file in ["sensor-stuck.csv", "sensor-stuck.svg"] {
        let a = std::fs::read(one.join(file)).expect("written");
        let b = std::fs::read(two.join(file)).expect("written");
        assert!(a.len() > 1000, "{file}");
        assert!(a == b, "{file} differs");
    }
    let csv = std::fs::read_to_string(one.join("sensor-stuck.csv")).expect("written");
    assert_eq!(csv.lines().count() as u32, scene.step_count() + 1);
    assert!(csv.starts_with("step,time_s,target,target_friction_n,"));
}

#[test]
fn the_command_line_reports_and_exits_as_documented() {
    let tool = env!("CARGO_BIN_EXE_sonolube");
    let out = scratch_dir("cli");
    let scene = |args: &[&str]| {
        Command::new(tool)
            .arg("scene")
            .args(args)
            .output()
            .expect("the tool runs")
    };
    for bad in [
        &[][..],
        &["no-such-scene"],
        &["--all", "reference"],
        &["--out"],
    ] {
        assert_eq!(scene(bad).status.code(), Some(2), "{bad:?}");
    }
    let out_dir = out.to_str().expect("utf-8 path");
    let one = scene(&["reference", "--out", out_dir]);
    let text = String::from_utf8_lossy(&one.stdout);
    assert_eq!(one.status.code(), Some(0), "{text}");
    assert!(text.contains("PASS settle to ±2 % within 3 ms"), "{text}");
    let reference = find("reference").expect("built in");
    let station_line = model_line(ClosedLoop::new(reference).expect("runs").station());
    assert!(
        text.lines().take(3).any(|l| l.trim() == station_line),
        "{station_line} not in the header of {text}"
    );
    assert!(out.join("reference.csv").is_file() && out.join("reference.svg").is_file());
    let file = sonolube_cli::scene_file::scenes_dir().join("sensor-fault.toml");
    let from_file = scene(&["--file", file.to_str().expect("utf-8"), "--out", out_dir]);
    assert_eq!(from_file.status.code(), Some(0));
    let mismatch = scene(&["reference", "--file", file.to_str().expect("utf-8")]);
    assert_eq!(mismatch.status.code(), Some(2));
    // `--all`: one line per scene, then the count; the exit code says whether all passed.
    let all = scene(&["--all", "--out", out_dir]);
    let text = String::from_utf8_lossy(&all.stdout).to_string();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), SCENES.len() + 1, "{text}");
    let failed = lines.iter().filter(|l| l.starts_with("FAIL")).count();
    let passed = lines.iter().filter(|l| l.starts_with("PASS")).count();
    assert_eq!(passed + failed, SCENES.len());
    assert_eq!(
        lines.last().copied(),
        Some(format!("{passed} passed, {failed} failed").as_str())
    );
    // Each line ends with the model the scene's controller ran, the variant `select` names.
    for (line, built) in lines.iter().zip(SCENES) {
        let variant = select(built).variant.expect(built.name);
        assert!(
            line.ends_with(&format!("; model {}", variant.name)),
            "{line}"
        );
    }
    assert_eq!(all.status.code(), Some(if failed == 0 { 0 } else { 1 }));
    let again = scene(&["--all", "--out", out_dir]);
    assert_eq!(again.stdout, all.stdout);
}

/// The line printed at scene start names the variant the controller runs and carries the
/// reason's numbers (error, budget, instructions, grid points) and the parts kept or skipped.
#[test]
fn the_model_line_names_the_selected_variant_and_its_reason() {
    for built in SCENES {
        let selection = select(built);
        let run = ClosedLoop::new(built).unwrap_or_else(|e| panic!("{}: {e:?}", built.name));
        let line = model_line(run.station());
        let variant = selection.variant.expect(built.name);
        assert!(
            line.starts_with(&format!("controller model {}: ", variant.name)),
            "{line}"
        );
        assert_eq!(model_name(run.station()), format!("model {}", variant.name));
        let numbers = match selection.reason {
            Reason::Meets {
                error_pct,
                budget_pct,
                instructions,
                points,
                candidates,
            } => vec![
                format!("within budget of {candidates} measured"),
                format!("{instructions:.0} instructions"),
                format!("max error {error_pct:.2e} % <= {budget_pct} %"),
                format!("over {points} points"),
            ],
            Reason::NoneMeets {
                error_pct,
                budget_pct,
                instructions,
                points,
            } => vec![
                format!("NO variant meets the budget {budget_pct} %"),
                format!("{instructions:.0} instructions"),
                format!("max error {error_pct:.2e} %"),
                format!("over {points} points"),
            ],
            Reason::NotMeasured { .. } => panic!("{}: built-in scenes are measured", built.name),
            Reason::Overruns { .. } => panic!("{}: a built-in scene fits its period", built.name),
        };
        let period = selection.period;
        assert!(period.fits(), "{line}");
        assert!(line.contains(&format!("{period}")), "{line}");
        for number in numbers {
            assert!(line.contains(&number), "{number:?} not in {line}");
        }
        let parts = selection.parts.expect(built.name);
        assert!(line.ends_with(&format!("; {parts}")), "{line}");
    }
    // A scene outside the table (another mu: other errors): its own model, and the line says
    // it was not measured. Another name alone keeps the built-in scene's measurements.
    let horn = find("horn-al-ss").expect("built in");
    let renamed = Scene {
        name: "my-horn",
        ..*horn
    };
    let twin = ClosedLoop::new(&renamed).expect("runs");
    assert_eq!(
        model_line(twin.station()),
        model_line(ClosedLoop::new(horn).expect("runs").station())
    );
    let renamed = Scene {
        controller: sonolube::scene::ModelSpec {
            mu: horn.controller.mu + 0.05,
            ..horn.controller
        },
        ..renamed
    };
    let run = ClosedLoop::new(&renamed).expect("runs");
    let line = model_line(run.station());
    assert!(
        line.starts_with(&format!("controller model {:?} ", horn.controller.kind))
            && line.contains("not in the measured table"),
        "{line}"
    );
}
