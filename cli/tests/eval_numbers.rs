//! `sonolube eval`'s numbers as a person reads them (issue 26): a flag quotes its number in
//! short form, never spelled out to hundreds of digits; a percentage within the rounding of
//! zero is zero and says so, never an unflagged -2.2e-14.

use serde_json::json;
use sonolube_cli::commands::eval::{PERCENT_ROUNDING, batch_line};
use sonolube_host::reference::example_inputs;

#[test]
fn a_tiny_frequency_is_quoted_short_in_its_flag() {
    for model in ["coulomb_avg_friction", "dahl_steady"] {
        let mut inputs = example_inputs(model).expect("example inputs");
        inputs.insert("f".into(), 1e-300);
        let answer = batch_line(&json!({ "model": model, "inputs": inputs }).to_string());
        let flag = answer["flags"]["f"].as_str().unwrap_or_default();
        assert!(flag.contains("f = 1e-300 Hz"), "{model}: {answer}");
        assert!(flag.len() < 300, "{model}: {} bytes: {flag}", flag.len());
    }
}

#[test]
fn a_reduction_within_rounding_of_zero_is_zero_and_flagged() {
    let mut inputs = example_inputs("cube_reduction").expect("example inputs");
    inputs.insert("A".into(), 0.0);
    inputs.insert("B".into(), 0.0);
    let answer = batch_line(&json!({ "model": "cube_reduction", "inputs": inputs }).to_string());
    for side in ["outputs", "reference"] {
        let x = answer[side]["reduction_pct"].as_f64();
        // Without vibration there is no reduction: exactly zero, or a flag names the value.
        assert!(
            x == Some(0.0) || answer["flags"]["reduction_pct"].is_string(),
            "{side}: {answer}"
        );
        assert!(
            x.is_none_or(|x| x == 0.0 || x.abs() >= PERCENT_ROUNDING),
            "{side}: {answer}"
        );
    }
}
