//! `sonolube papers`: every paper number next to the f64 reference and the fixed-point model.
//!
//! Prints a markdown table (the one in `docs/models.md`) from [`sonolube_host::papers::PAPER_CASES`]: where
//! the number is printed, the printed value, the reference model's value, the fixed-point
//! model's value, and whether the model reproduces the paper (with the reason when it does not).
//! With `--check`, exits 1 if a fixed-point value differs from the reference by more than the
//! case's agreement tolerance would allow, or if the reference misses its own expected value.

use std::process::ExitCode;

use sonolube_host::fixed_eval::eval_fixed_named;
use sonolube_host::papers::{Agreement, PAPER_CASES, PaperCase, Tolerance};
use sonolube_host::reference::eval_named;

/// Entry point of `sonolube papers`.
pub fn run(args: &[String]) -> ExitCode {
    let check = match args {
        [] => false,
        [flag] if flag == "--check" => true,
        _ => {
            eprintln!("usage: sonolube papers [--check]");
            return ExitCode::from(2);
        }
    };
    let (table, problems) = table();
    print!("{table}");
    for problem in &problems {
        eprintln!("papers: {problem}");
    }
    if check && !problems.is_empty() {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

fn reference(
    model: &str,
    inputs: &std::collections::BTreeMap<String, f64>,
    variant: &std::collections::BTreeMap<String, String>,
) -> Result<std::collections::BTreeMap<&'static str, f64>, String> {
    eval_named(model, inputs, variant).map_err(|e| e.to_string())
}

fn display(case: &PaperCase, value: Result<f64, String>) -> String {
    match value {
        Ok(v) => {
            let shown = v * case.unit.scale();
            let digits = if shown.abs() >= 1e5 || (shown != 0.0 && shown.abs() < 1e-3) {
                return format!("{shown:.4e}");
            } else {
                4
            };
            format!("{shown:.digits$}")
        }
        Err(e) => format!("error: {e}"),
    }
}

/// The markdown table and the list of consistency problems found while building it.
pub fn table() -> (String, Vec<String>) {
    let mut out = String::from(
        "| source | printed | reference (f64) | fixed point | unit | paper vs model |\n|---|---|---|---|---|---|\n",
    );
    let mut problems = Vec::new();
    for case in PAPER_CASES {
        let reference_value = case.value_with(&reference);
        let fixed_value = case.value_with(&eval_fixed_named);
        if let Ok(r) = &reference_value
            && !case.tolerance.accepts(*r, case.expected)
        {
            problems.push(format!(
                "{}: reference {r} misses its expected {}",
                case.id, case.expected
            ));
        }
        let agreement_tolerance = match case.agreement {
            Agreement::Reproduces(t) | Agreement::Differs(t) => t,
            Agreement::NoPrintedValue => Tolerance::Rel(1e-3),
        };
        match (&reference_value, &fixed_value) {
            (Ok(r), Ok(f)) if !agreement_tolerance.accepts(*f, *r) => problems.push(format!(
                "{}: fixed point {f} is farther from the reference {r} than {agreement_tolerance:?}",
                case.id
            )),
            (_, Err(e)) => problems.push(format!("{}: fixed point failed: {e}", case.id)),
            (Err(e), _) => problems.push(format!("{}: reference failed: {e}", case.id)),
            _ => {}
        }
        let verdict = match case.agreement {
            Agreement::Reproduces(_) => "reproduced".to_string(),
            Agreement::Differs(_) => format!("**differs**: {}", case.note),
            Agreement::NoPrintedValue => "no printed value".to_string(),
        };
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} |\n",
            case.source,
            case.printed,
            display(case, reference_value),
            display(case, fixed_value),
            case.unit.label(),
            verdict.replace('|', "/"),
        ));
    }
    (out, problems)
}
