//! `sonolube scene --file` with a scene whose values are each within the schema's range but
//! cannot build a run together: the message names the scene values and why (never a variant
//! name such as `Config(Shaper(OutOfRange))`), and the exit status is 1; usage errors are 2.

use std::path::{Path, PathBuf};
use std::process::Command;

fn sonolube(args: &[&str]) -> (i32, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_sonolube"))
        .args(args)
        .output()
        .expect("the sonolube binary runs");
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// The reference scene with `key = value` lines replaced, written to a temporary file.
fn variant_of_reference(tag: &str, edits: &[(&str, &str)]) -> PathBuf {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/reference.toml");
    let mut text = std::fs::read_to_string(path).expect("scenes/reference.toml");
    for (key, value) in edits {
        let start = text.find(&format!("\n{key} = ")).expect("key in the file") + 1;
        let end = start + text[start..].find('\n').unwrap();
        text.replace_range(start..end, &format!("{key} = {value}"));
    }
    let dir = std::env::temp_dir().join(format!("sonolube-cannot-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{tag}.toml"));
    std::fs::write(&file, text).unwrap();
    file
}

fn run(file: &Path) -> (i32, String) {
    let out = file.with_extension("out");
    sonolube(&[
        "scene",
        "--file",
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

fn assert_words(stderr: &str, names: &[&str]) {
    assert!(
        !stderr.contains("OutOfRange") && !stderr.contains("Config("),
        "{stderr}"
    );
    for name in names {
        assert!(stderr.contains(name), "{name} missing from: {stderr}");
    }
}

#[test]
fn a_quality_factor_too_high_for_the_lead_is_named_with_its_limit() {
    // Q = 1e4 is within the schema (1 ..= 1e4), but its 80 ms envelope needs a lead gain of
    // 263, and the lead's Q8.24 stops below 128.
    let (code, stderr) = run(&variant_of_reference(
        "high-q",
        &[("name", "\"high-q\""), ("quality_factor", "10000.0")],
    ));
    assert_eq!(code, 1, "{stderr}");
    assert_words(
        &stderr,
        &["transducer.quality_factor = 10000", "lead", "128"],
    );
    // The limit the message gives is the real one: at it the run builds, one above it does not.
    let limit: u32 = stderr
        .split("at most about ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .expect("the message gives the largest quality factor");
    let at = |q: u32| {
        run(&variant_of_reference(
            &format!("q{q}"),
            &[
                ("name", &format!("\"q{q}\"")),
                ("quality_factor", &format!("{q}.0")),
            ],
        ))
    };
    let (code, stderr) = at(limit);
    assert!(!stderr.contains("cannot build the run"), "{stderr}");
    assert!(code == 0 || code == 1, "{stderr}");
    let (code, stderr) = at(limit + 1);
    assert_eq!(code, 1);
    assert!(stderr.contains("cannot build the run"), "{stderr}");
}

#[test]
fn a_control_rate_below_the_measured_range_is_named_with_why() {
    let (code, stderr) = run(&variant_of_reference(
        "slow",
        &[("name", "\"slow\""), ("control_rate_hz", "1000.0")],
    ));
    assert_eq!(code, 1, "{stderr}");
    assert_words(
        &stderr,
        &[
            "control_rate_hz",
            "1000 is outside 6000 ..= 100000",
            "below 6000 Hz the loop has not been shown to hold",
        ],
    );
    let (code, stderr) = run(&variant_of_reference(
        "fast",
        &[("name", "\"fast\""), ("control_rate_hz", "200000.0")],
    ));
    assert_eq!(code, 1, "{stderr}");
    assert_words(&stderr, &["200000 is outside", "6e6 control steps"]);
}

#[test]
fn exit_status_is_1_for_a_scene_that_cannot_run_and_2_for_usage() {
    let (code, stderr) = sonolube(&["scene", "--file", "/nonexistent/scene.toml"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("cannot run"), "{stderr}");
    for args in [
        &["scene"][..],
        &["scene", "--bogus"],
        &["scene", "no-such-scene"],
        &["scene", "--file"],
    ] {
        assert_eq!(sonolube(args).0, 2, "{args:?}");
    }
}
