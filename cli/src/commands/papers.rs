//! `sonolube papers`: every paper number next to the f64 reference and the fixed-point model.
//!
//! Prints a markdown table (the one in `docs/models.md`) from [`sonolube_host::papers::PAPER_CASES`]: where
//! the number is printed, the printed value, the reference model's value, the fixed-point
//! model's value, how far the fixed point is from the reference against the model tolerance,
//! and, as a separate verdict, whether the model reproduces the paper at the paper's own
//! precision (with the reason when it does not).
//!
//! Model tolerances of the fixed point against the reference (as in the fixed-vs-reference
//! tests): closed forms 1e-4 relative, stiffness (and delta = F_t0 / K_t) 5e-4 relative,
//! averaged ratios 1e-3 absolute, percent reductions 0.1 point; a quantity formed from two
//! evaluations (a difference, a ratio) carries the sum of its terms' tolerances.
//!
//! With `--check`, exits 1 if a fixed-point value is farther from the reference than its model
//! tolerance, if the reference misses its own expected value, or if a case's paper verdict
//! (reproduces / differs) is false.

use std::process::ExitCode;

use sonolube_host::fixed_eval::eval_fixed_named;
use sonolube_host::papers::{Agreement, Evaluation, PAPER_CASES, PaperCase, Quantity};
use sonolube_host::reference::eval_named;

/// The command line of `sonolube papers`.
#[derive(clap::Parser, Debug)]
#[command(
    name = "papers",
    bin_name = "sonolube papers",
    about = "Paper numbers against the f64 reference and the fixed point, as a markdown table",
    after_help = "Exit status: 0, or 1 with --check when a case is outside its tolerance; 2 usage."
)]
pub struct Args {
    /// Exit 1 when the fixed point or the reference misses a paper number's tolerance.
    #[arg(long)]
    pub check: bool,
}

/// Entry point of `sonolube papers`.
pub fn run(args: &[String]) -> ExitCode {
    let check = match super::args::parse::<Args>(args) {
        Ok(args) => args.check,
        Err(code) => return code,
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

/// Allowed |fixed - reference| of one evaluation's output `value` (module docs).
fn output_tolerance(evaluation: &Evaluation, value: f64) -> f64 {
    match evaluation.output {
        "reduction_pct" => 0.1,
        "ratio" => 1e-3,
        "K_t" | "delta" => 5e-4 * value.abs(),
        _ => 1e-4 * value.abs(),
    }
}

/// Allowed |fixed - reference| of a case's quantity, from the reference's values of its
/// terms, and what it is in words.
fn model_tolerance(case: &PaperCase) -> Result<(f64, &'static str), String> {
    let main = case.evaluation.run_with(&reference)?;
    let tol_main = output_tolerance(&case.evaluation, main);
    let inputs = case.evaluation.input_map();
    let rule = match case.evaluation.output {
        "reduction_pct" => "0.1 point",
        "ratio" => "1e-3",
        "K_t" | "delta" => "5e-4 rel",
        _ => "1e-4 rel",
    };
    Ok(match case.quantity {
        Quantity::Output => (tol_main, rule),
        Quantity::MinusOther(other) => {
            let value = other.run_with(&reference)?;
            (
                tol_main + output_tolerance(&other, value),
                "sum of both terms'",
            )
        }
        Quantity::OverOther(other) => {
            let value = other.run_with(&reference)?;
            let relative = tol_main / main.abs() + output_tolerance(&other, value) / value.abs();
            (
                relative * (main / value).abs(),
                "sum of both terms' (relative)",
            )
        }
        Quantity::InputOverOutput(key) => {
            (tol_main / main.abs() * (inputs[key] / main).abs(), rule)
        }
        Quantity::OutputOverInput(key) => (tol_main / inputs[key].abs(), rule),
    })
}

/// The markdown table and the list of consistency problems found while building it.
pub fn table() -> (String, Vec<String>) {
    let mut out = String::from(
        "| source | printed | reference (f64) | fixed point | unit | fixed vs reference (model tolerance) | paper vs model (paper precision) |\n|---|---|---|---|---|---|---|\n",
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
        let scale = case.unit.scale();
        let fixed_verdict = match (&reference_value, &fixed_value, &model_tolerance(case)) {
            (Ok(r), Ok(f), Ok((allowed, rule))) => {
                let (allowed, rule) = (*allowed, *rule);
                let gap = (f - r).abs();
                let shown = format!("{:.1e} <= {:.1e} ({rule})", gap * scale, allowed * scale);
                if gap <= allowed {
                    format!("agrees: {shown}")
                } else {
                    problems.push(format!(
                        "{}: fixed point {f} is {gap:e} from the reference {r}, beyond the model tolerance {allowed:e} ({rule})",
                        case.id
                    ));
                    format!(
                        "**disagrees**: {:.1e} > {:.1e} ({rule})",
                        gap * scale,
                        allowed * scale
                    )
                }
            }
            (_, Err(e), _) => {
                problems.push(format!("{}: fixed point failed: {e}", case.id));
                "**failed**".to_string()
            }
            (Err(e), _, _) | (_, _, Err(e)) => {
                problems.push(format!("{}: reference failed: {e}", case.id));
                "**failed**".to_string()
            }
        };
        let (holds, verdict) = match (case.agreement, case.paper_value, &reference_value) {
            (Agreement::Reproduces(p), Some(paper), Ok(r)) => (
                p.accepts(*r, paper),
                format!("reproduced ({})", p.describe(case.unit)),
            ),
            (Agreement::Differs(p), Some(paper), Ok(r)) => (
                !p.accepts(*r, paper),
                format!("**differs** ({}): {}", p.describe(case.unit), case.note),
            ),
            (Agreement::NoPrintedValue, None, _) => (true, "no printed value".to_string()),
            _ => (false, "inconsistent".to_string()),
        };
        if !holds {
            problems.push(format!(
                "{}: the paper verdict `{verdict}` is false",
                case.id
            ));
        }
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} |\n",
            case.source,
            case.printed,
            display(case, reference_value),
            display(case, fixed_value),
            case.unit.label(),
            fixed_verdict,
            verdict.replace('|', "/"),
        ));
    }
    (out, problems)
}
