//! `sonolube eval` and `sonolube papers`, run as a user runs them: the built binary, its
//! stdout and its exit status.

use std::io::Write;
use std::process::{Command, Stdio};

use serde_json::{Value, json};
use sonolube_host::reference::{MODELS, example_inputs};

fn sonolube(args: &[&str], stdin: Option<&str>) -> (i32, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sonolube"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the sonolube binary runs");
    {
        let mut input = child.stdin.take().expect("stdin is piped");
        if let Some(text) = stdin {
            input
                .write_all(text.as_bytes())
                .expect("stdin accepts the batch");
        }
    }
    let output = child.wait_with_output().expect("sonolube finishes");
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8(output.stdout).expect("stdout is UTF-8"),
    )
}

/// Outputs and reference carry the same keys, and agree to a loose tolerance (the tight ones are
/// asserted by the fixed-vs-reference tests; this checks the plumbing, not the numerics).
fn assert_answer(model: &str, answer: &Value) {
    let outputs = answer["outputs"]
        .as_object()
        .unwrap_or_else(|| panic!("{model}: {answer}"));
    let reference = answer["reference"].as_object().expect("reference object");
    assert_eq!(
        outputs.keys().collect::<Vec<_>>(),
        reference.keys().collect::<Vec<_>>(),
        "{model}: same output keys"
    );
    for (key, value) in outputs {
        let (fixed, exact) = (value.as_f64().unwrap(), reference[key].as_f64().unwrap());
        let scale = exact.abs().max(1e-30);
        assert!(
            (fixed - exact).abs() <= 1e-2 * scale + 1e-2 * (key.ends_with("_pct") as u8 as f64),
            "{model}.{key}: fixed {fixed} vs reference {exact}"
        );
    }
}

#[test]
fn single_mode_answers_every_model_with_one_json_object() {
    for model in MODELS {
        let inputs = example_inputs(model).expect("example inputs");
        let words: Vec<String> = inputs.iter().map(|(k, v)| format!("{k}={v:e}")).collect();
        let mut args = vec!["eval", model];
        args.extend(words.iter().map(String::as_str));
        let (status, stdout) = sonolube(&args, None);
        assert_eq!(status, 0, "{model}: {stdout}");
        assert_eq!(stdout.lines().count(), 1, "{model}: one line");
        let answer: Value = serde_json::from_str(&stdout).expect("JSON");
        assert_answer(model, &answer);
    }
}

#[test]
fn single_mode_reports_bad_input_as_an_error_object_and_exit_1() {
    for args in [
        vec!["eval", "no_such_model", "x=1"],
        vec!["eval", "littmann_mu_i"],
        vec!["eval", "littmann_mu_i", "zeta=abc"],
        vec!["eval", "littmann_mu_i", "zeta=0.5", "window=sideways"],
        vec!["eval", "contact_ep", "F_n=-1"],
    ] {
        let (status, stdout) = sonolube(&args, None);
        assert_eq!(status, 1, "{args:?}");
        let answer: Value = serde_json::from_str(&stdout).expect("JSON");
        assert!(
            answer["error"].as_str().is_some_and(|m| !m.is_empty()),
            "{args:?}: {answer}"
        );
    }
    let (status, _) = sonolube(&["eval"], None);
    assert_eq!(status, 2);
}

#[test]
fn batch_mode_answers_every_line_and_never_stops_on_a_bad_one() {
    let mut lines = Vec::new();
    let mut expect_error = Vec::new();
    for model in MODELS {
        let inputs = example_inputs(model).expect("example inputs");
        lines.push(json!({ "model": model, "inputs": inputs }).to_string());
        expect_error.push(false);
        lines.push("{ not json".to_string());
        expect_error.push(true);
    }
    for bad in [
        json!({ "model": "cube_reduction", "inputs": { "F_n": 40.0 } }),
        json!({ "model": "littmann_mu_i", "inputs": { "zeta": "half" } }),
        json!({ "model": "littmann_mu_i", "inputs": { "zeta": 0.5 }, "variant": { "window": 3.5 } }),
        json!({ "inputs": { "zeta": 0.5 } }),
        json!([1, 2, 3]),
    ] {
        lines.push(bad.to_string());
        expect_error.push(true);
    }
    lines.push(
        json!({ "model": "cube_reduction", "inputs": example_inputs("cube_reduction").unwrap(),
                "variant": { "quadrature_points": 32, "contact": "el" } })
        .to_string(),
    );
    expect_error.push(false);
    let (status, stdout) = sonolube(&["eval", "--batch"], Some(&(lines.join("\n") + "\n")));
    assert_eq!(status, 0);
    let answers: Vec<Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).expect("each answer is JSON"))
        .collect();
    assert_eq!(answers.len(), lines.len(), "one answer per line");
    for ((answer, error), line) in answers.iter().zip(&expect_error).zip(&lines) {
        if *error {
            assert!(answer["error"].is_string(), "{line} -> {answer}");
        } else {
            let model: Value = serde_json::from_str(line).unwrap();
            assert_answer(model["model"].as_str().unwrap(), answer);
        }
    }
}

#[test]
fn papers_table_has_a_row_per_case_and_the_fixed_point_agrees() {
    let (status, stdout) = sonolube(&["papers", "--check"], None);
    assert_eq!(status, 0, "{stdout}");
    let rows = stdout.lines().filter(|l| l.starts_with("| ")).count();
    assert_eq!(
        rows,
        1 + sonolube_host::papers::PAPER_CASES.len(),
        "header + one row per case"
    );
}

#[test]
fn readme_paper_table_is_the_current_output_of_sonolube_papers() {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/models.md"))
        .expect("docs/models.md is readable");
    let (_, rest) = readme
        .split_once("<!-- papers:begin -->\n")
        .expect("docs/models.md has the papers:begin marker");
    let (block, _) = rest
        .split_once("<!-- papers:end -->")
        .expect("docs/models.md has the papers:end marker");
    let (table, _) = sonolube_cli::commands::papers::table();
    assert_eq!(
        block, table,
        "docs/models.md paper table is stale: run scripts/readme-papers"
    );
}
