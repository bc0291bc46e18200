//! `sonolube scene --file` with a scene whose every value is in range but that cannot work
//! (issue 26): refused before the run with the key, the value and the number that fails
//! (exit 1), where it used to run and FAIL with errors of thousands of percent. And the
//! `--csv` choices of a long run.

use std::path::PathBuf;
use std::process::Command;

fn sonolube(args: &[&str]) -> (i32, String, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_sonolube"))
        .args(args)
        .output()
        .expect("the sonolube binary runs");
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// The reference scene with exact text replaced (each `from` must occur), renamed `tag`.
fn reference_with(tag: &str, edits: &[(&str, &str)]) -> PathBuf {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/reference.toml");
    let mut text = std::fs::read_to_string(path).expect("scenes/reference.toml");
    text = text.replacen("name = \"reference\"", &format!("name = \"{tag}\""), 1);
    for (from, to) in edits {
        assert!(text.contains(from), "{from} not in the reference scene");
        text = text.replacen(from, to, 1);
    }
    let dir = std::env::temp_dir().join(format!("sonolube-feasible-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{tag}.toml"));
    std::fs::write(&file, text).unwrap();
    file
}

fn run(tag: &str, edits: &[(&str, &str)]) -> (i32, String, String) {
    let file = reference_with(tag, edits);
    let out = file.with_extension("out");
    sonolube(&[
        "scene",
        "--file",
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

fn refused(tag: &str, edits: &[(&str, &str)], words: &[&str]) {
    let (code, stdout, stderr) = run(tag, edits);
    assert_eq!(code, 1, "{stdout}{stderr}");
    assert!(stdout.is_empty(), "the run went ahead: {stdout}");
    for word in words {
        assert!(stderr.contains(word), "{word:?} missing from: {stderr}");
    }
}

#[test]
fn a_reduction_beyond_the_full_drive_is_refused_with_the_reachable_value() {
    refused(
        "too-much",
        &[("reduction_pct = 50.0", "reduction_pct = 99.0")],
        &[
            "refused: profiles.target[1].reduction_pct = 99",
            "reaches at best",
            "full scale",
        ],
    );
}

#[test]
fn a_one_millinewton_force_target_is_refused() {
    refused(
        "one-mn",
        &[("reduction_pct = 50.0", "force_n = 0.001")],
        &["profiles.target[1].force_n = 0.001"],
    );
}

#[test]
fn a_speed_below_the_sliding_threshold_is_refused() {
    refused(
        "creep",
        &[
            (
                "sliding_velocity_m_per_s = [[0.0, 0.038]]",
                "sliding_velocity_m_per_s = [[0.0, 0.0008]]",
            ),
            (
                "velocity_range_m_per_s = [0.038, 0.038]",
                "velocity_range_m_per_s = [0.0008, 0.0008]",
            ),
        ],
        &[
            "profiles.sliding_velocity_m_per_s",
            "sliding threshold 0.001 m/s",
        ],
    );
}

#[test]
fn cell_noise_as_large_as_the_friction_is_refused() {
    refused(
        "light",
        &[
            (
                "normal_load_n = [[0.0, 4.155]]",
                "normal_load_n = [[0.0, 0.1]]",
            ),
            ("load_range_n = [4.155, 4.155]", "load_range_n = [0.1, 0.1]"),
        ],
        &[
            "sensors.tangential.noise_rms_pct_fs",
            "accuracy.friction_pct = 1 %",
        ],
    );
}

#[test]
fn a_drive_at_half_the_resonance_is_refused() {
    refused(
        "half-freq",
        &[("drive_hz = 40000.0", "drive_hz = 20000.0")],
        &["profiles.target[1].reduction_pct = 50", "full scale"],
    );
}

#[test]
fn a_control_rate_the_controller_refuses_is_refused_by_the_schema() {
    refused(
        "slow-rate",
        &[("control_rate_hz = 10000.0", "control_rate_hz = 3000.0")],
        &["control_rate_hz: 3000 is outside 6000 ..= 100000"],
    );
}

#[test]
fn a_velocity_range_through_zero_names_its_key() {
    refused(
        "reversal",
        &[(
            "velocity_range_m_per_s = [0.038, 0.038]",
            "velocity_range_m_per_s = [-0.038, 0.038]",
        )],
        &["contents.velocity_range_m_per_s = [-0.038, 0.038]"],
    );
}

#[test]
fn csv_none_writes_no_csv_and_every_n_thins_it() {
    let file = reference_with("csv-choice", &[]);
    let out = file.with_extension("csv-out");
    let out_text = out.to_str().unwrap();
    let csv = out.join("csv-choice.csv");
    let (code, stdout, stderr) = sonolube(&[
        "scene",
        "--file",
        file.to_str().unwrap(),
        "--out",
        out_text,
        "--csv",
        "none",
    ]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(!csv.exists() && out.join("csv-choice.svg").exists());
    let rows = |args: &[&str]| {
        let mut all = vec!["scene", "--file", file.to_str().unwrap(), "--out", out_text];
        all.extend_from_slice(args);
        let (code, stdout, stderr) = sonolube(&all);
        assert_eq!(code, 0, "{stdout}{stderr}");
        std::fs::read_to_string(&csv).unwrap().lines().count() - 1
    };
    let every = rows(&[]);
    // 0.025 s at 10 kHz: 250 steps; one in 10 plus the steps where the state changes.
    assert_eq!(every, 250);
    let thinned = rows(&["--csv", "every", "10"]);
    assert!((25..=35).contains(&thinned), "{thinned} rows");
    // Off a terminal there is no progress output.
    let (_, _, stderr) = sonolube(&["scene", "--file", file.to_str().unwrap(), "--out", out_text]);
    assert!(stderr.is_empty(), "{stderr}");
    for bad in [&["--csv"][..], &["--csv", "every", "0"], &["--csv", "some"]] {
        let mut all = vec!["scene", "reference"];
        all.extend_from_slice(bad);
        assert_eq!(sonolube(&all).0, 2, "{bad:?}");
    }
}

/// A reduction step near what the cells resolve (mu0's learning error against the overshoot
/// criterion) runs with a warning that gives the step, mu0's error and the chance of passing
/// the criterion by that error alone.
#[test]
fn a_small_reduction_step_runs_with_the_resolution_warning() {
    let (_, stdout, stderr) = run(
        "small-step",
        &[("reduction_pct = 50.0", "reduction_pct = 2.0")],
    );
    let all = format!("{stdout}{stderr}");
    assert!(
        all.contains("warning: profiles.target[1].reduction_pct: a step of 2.00 %")
            && all.contains("40 samples")
            && all.contains("of runs"),
        "{all}"
    );
}

/// The envelope sweep judges every run by the feasibility check that `scene --file` applies:
/// each point it lists as infeasible is refused when its file is run alone, and its counts
/// add up (refused + accepted = every run).
#[test]
fn the_envelope_refuses_what_scene_file_refuses() {
    let out = std::env::temp_dir().join(format!("sonolube-envelope-{}", std::process::id()));
    let (code, stdout, stderr) = sonolube(&[
        "scene",
        "reference",
        "--envelope",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(code == 0 || code == 1, "{stderr}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("  the feasibility check (all runs run"))
        .unwrap_or_else(|| panic!("no check line: {stdout}"));
    let numbers: Vec<usize> = line
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|w| w.parse().ok())
        .collect();
    // refused, refused-but-passed, warned, warned-passed, clean, clean-passed.
    assert_eq!(numbers.len(), 6, "{line}");
    assert_eq!(numbers[0] + numbers[2] + numbers[4], 60, "{line}");
    let infeasible: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("  INFEASIBLE ") && !l.contains("sized cells"))
        .collect();
    assert_eq!(infeasible.len(), numbers[0], "{stdout}");
    // The first refused point, run alone from its file: refused the same way.
    let first = infeasible.first().expect("the 0.5 N points are refused");
    let load = first
        .trim_start_matches("  INFEASIBLE ")
        .split(" N,")
        .next()
        .unwrap();
    assert_eq!(load, "0.5", "{first}");
    let file = out.join("envelope").join("env-0p5n-10mms-9pct.toml");
    let (code, _, stderr) = sonolube(&[
        "scene",
        "env-0p5n-10mms-9pct",
        "--file",
        file.to_str().unwrap(),
        "--csv",
        "none",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("refused"), "{stderr}");
}
