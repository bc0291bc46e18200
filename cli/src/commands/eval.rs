//! `sonolube eval`: evaluates a model in fixed point and in the f64 reference, as JSON.
//!
//! ```text
//! sonolube eval MODEL key=value ...     one JSON object on stdout
//! sonolube eval --batch                 JSON lines in, JSON lines out
//! sonolube eval --list                  the model names
//! ```
//!
//! A `key=value` whose key is a variant key (`E_star_rule`, `contact`, `window`, `u_phase`,
//! `quadrature_points`) is a variant choice; every other key is an input in SI units. A batch
//! line is `{"model": ..., "inputs": {...}, "variant": {...}}` (variant optional; its values
//! are strings or whole numbers). Each answer is `{"outputs": {...}, "reference": {...}}`:
//! the fixed-point result converted to SI and the f64 reference, with the same keys; or
//! `{"error": "..."}` for an unknown model, a missing or unknown key, an out-of-domain value,
//! or a malformed line. A batch never stops on a bad line. Exit status: 0, or 1 when the single
//! evaluation failed, 2 on usage errors.
//!
//! At the extremes (`fixed_eval::extremes`): an output that is undefined at the inputs (zeta
//! without vibration, a ratio to or a percent reduction of zero friction) is `null` on the side
//! where it is undefined, and `"undefined": {key: reason}` says why; it is never a finite
//! stand-in nor a limit value. `"flags": {key: reason}` names an input `f` outside the 20-60 kHz
//! drive band and an output outside its physical range (for example a friction ratio below
//! zero); the numbers are kept, the flag says why they are not physical. Both fields are
//! present only when not empty. Numbers in flags are short (`1e-300`, never 300 digits); a
//! `reduction_pct` within the rounding of `100 (1 - ratio)` at ratio 1 ([`PERCENT_ROUNDING`])
//! is written as 0 and flagged with the value it had.

use std::collections::BTreeMap;
use std::io::{BufRead, Write};
use std::process::ExitCode;

use serde_json::{Map, Value, json};

use sonolube_host::fixed_eval::extremes::{flags, short_number, undefined_keys, undefined_reason};
use sonolube_host::fixed_eval::{Outputs, eval_fixed_named, models};
use sonolube_host::reference::eval_named;

/// Keys that select a variant rather than give an input.
pub const VARIANT_KEYS: &[&str] = &[
    "E_star_rule",
    "contact",
    "window",
    "u_phase",
    "quadrature_points",
];

/// The command line of `sonolube eval`.
#[derive(clap::Parser, Debug)]
#[command(
    name = "eval",
    bin_name = "sonolube eval",
    about = "Evaluate a model in fixed point and in the f64 reference, as JSON",
    after_help = "A KEY that is a variant key (E_star_rule, contact, window, u_phase, \
                  quadrature_points) chooses a variant; every other KEY is an input in SI units.\n\
                  Exit status: 0, or 1 when the single evaluation failed; 2 usage."
)]
pub struct Args {
    /// Print the model names.
    #[arg(long)]
    pub list: bool,
    /// Read JSON lines {"model", "inputs", "variant"} on stdin, answer each on stdout.
    #[arg(long, conflicts_with_all = ["list", "model"])]
    pub batch: bool,
    /// The model to evaluate (`--list` names them).
    pub model: Option<String>,
    /// Inputs and variant choices.
    #[arg(value_name = "KEY=VALUE", allow_hyphen_values = true)]
    pub words: Vec<String>,
}

/// Entry point of `sonolube eval`.
pub fn run(args: &[String]) -> ExitCode {
    let args = match super::args::parse::<Args>(args) {
        Ok(args) => args,
        Err(code) => return code,
    };
    if args.list {
        for model in models() {
            println!("{model}");
        }
        return ExitCode::SUCCESS;
    }
    if args.batch {
        return batch();
    }
    let Some(model) = args.model else {
        return super::args::usage_error::<Args>("a MODEL, --batch or --list is needed");
    };
    let answer = single(&model, &args.words);
    let failed = answer.get("error").is_some();
    println!("{answer}");
    if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// One evaluation from command-line `key=value` words.
fn single(model: &str, words: &[String]) -> Value {
    let mut inputs = BTreeMap::new();
    let mut variant = BTreeMap::new();
    for word in words {
        let Some((key, value)) = word.split_once('=') else {
            return error(format!("`{word}` is not key=value"));
        };
        if VARIANT_KEYS.contains(&key) {
            variant.insert(key.to_string(), value.to_string());
        } else {
            match value.trim().parse::<f64>() {
                Ok(number) => {
                    inputs.insert(key.to_string(), number);
                }
                Err(_) => return error(format!("input `{key}`: `{value}` is not a number")),
            }
        }
    }
    evaluate(model, &inputs, &variant)
}

/// Reads JSON lines from stdin and answers each on stdout.
fn batch() -> ExitCode {
    let stdin = std::io::stdin();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for line in stdin.lock().lines() {
        let answer = match line {
            Ok(line) if line.trim().is_empty() => continue,
            Ok(line) => batch_line(&line),
            Err(e) => error(format!("unreadable input line: {e}")),
        };
        if writeln!(out, "{answer}").is_err() {
            return ExitCode::from(1);
        }
    }
    ExitCode::SUCCESS
}

/// Answers one batch line.
pub fn batch_line(line: &str) -> Value {
    let request: Value = match serde_json::from_str(line) {
        Ok(value) => value,
        Err(e) => return error(format!("not a JSON object: {e}")),
    };
    let Some(object) = request.as_object() else {
        return error("a line must be a JSON object".into());
    };
    if let Some(key) = object
        .keys()
        .find(|k| !matches!(k.as_str(), "model" | "inputs" | "variant"))
    {
        return error(format!("unknown field `{key}` (model, inputs, variant)"));
    }
    let Some(model) = object.get("model").and_then(Value::as_str) else {
        return error("`model` (a string) is missing".into());
    };
    let inputs = match object.get("inputs") {
        None => BTreeMap::new(),
        Some(Value::Object(map)) => match numbers(map) {
            Ok(inputs) => inputs,
            Err(message) => return error(message),
        },
        Some(_) => return error("`inputs` must be an object".into()),
    };
    let variant = match object.get("variant") {
        None | Some(Value::Null) => BTreeMap::new(),
        Some(Value::Object(map)) => match choices(map) {
            Ok(variant) => variant,
            Err(message) => return error(message),
        },
        Some(_) => return error("`variant` must be an object".into()),
    };
    evaluate(model, &inputs, &variant)
}

fn numbers(map: &Map<String, Value>) -> Result<BTreeMap<String, f64>, String> {
    map.iter()
        .map(|(key, value)| match value.as_f64() {
            Some(number) => Ok((key.clone(), number)),
            None => Err(format!("input `{key}` must be a number")),
        })
        .collect()
}

fn choices(map: &Map<String, Value>) -> Result<BTreeMap<String, String>, String> {
    map.iter()
        .map(|(key, value)| match value {
            Value::String(text) => Ok((key.clone(), text.clone())),
            Value::Number(number) if number.is_u64() => Ok((key.clone(), number.to_string())),
            _ => Err(format!(
                "variant `{key}` must be a string or a whole number"
            )),
        })
        .collect()
}

/// Fixed point and reference for one request, or an error naming the side that failed.
pub fn evaluate(
    model: &str,
    inputs: &BTreeMap<String, f64>,
    variant: &BTreeMap<String, String>,
) -> Value {
    let reference = match eval_named(model, inputs, variant) {
        Ok(outputs) => outputs,
        Err(e) => return error(e.to_string()),
    };
    match eval_fixed_named(model, inputs, variant) {
        Ok(outputs) => {
            let mut fixed = outputs;
            let mut reference = reference;
            let rounded = [
                ("the fixed point", zero_within_rounding(&mut fixed)),
                ("the reference", zero_within_rounding(&mut reference)),
            ];
            let mut answer = answer(model, inputs, &fixed, &reference);
            for (side, value) in rounded {
                if let Some(x) = value {
                    add_flag(
                        &mut answer,
                        PERCENT_KEY,
                        format!(
                            "{side}: {} % is within the rounding of 100 (1 - F'/F) at F'/F = 1 \
                             (8 ulps of 1, {} %): written as 0",
                            short_number(x),
                            short_number(PERCENT_ROUNDING)
                        ),
                    );
                }
            }
            answer
        }
        Err(e) => error(format!("fixed point: {e}")),
    }
}

/// The JSON answer: both sides with `null` for their undefined outputs, the reasons, the flags.
fn answer(
    model: &str,
    inputs: &BTreeMap<String, f64>,
    fixed: &Outputs,
    reference: &Outputs,
) -> Value {
    let mut undefined = Map::new();
    let mut missing: Vec<&str> = undefined_keys(model, fixed);
    missing.extend(undefined_keys(model, reference));
    // A key one side gives and the other does not is undefined on the other side.
    missing.extend(fixed.keys().filter(|k| !reference.contains_key(*k)));
    missing.extend(reference.keys().filter(|k| !fixed.contains_key(*k)));
    for key in missing {
        let why = undefined_reason(model, key).unwrap_or("not computed on this side");
        undefined.insert(key.to_string(), json!(why));
    }
    let mut result = Map::new();
    result.insert("outputs".into(), as_json(fixed, &undefined));
    result.insert("reference".into(), as_json(reference, &undefined));
    if !undefined.is_empty() {
        result.insert("undefined".into(), Value::Object(undefined));
    }
    let flags: Map<String, Value> = flags(model, inputs, fixed, reference)
        .into_iter()
        .map(|(key, why)| (key.to_string(), json!(why)))
        .collect();
    if !flags.is_empty() {
        result.insert("flags".into(), Value::Object(flags));
    }
    Value::Object(result)
}

/// The side's outputs, with `null` for each key in `undefined` it does not give.
fn as_json(outputs: &Outputs, undefined: &Map<String, Value>) -> Value {
    let mut map: Map<String, Value> = outputs
        .iter()
        .map(|(key, value)| (key.to_string(), json!(value)))
        .collect();
    for key in undefined.keys() {
        map.entry(key.clone()).or_insert(Value::Null);
    }
    Value::Object(map)
}

/// The output that is a percentage of a ratio near 1: `100 (1 - ratio)`.
const PERCENT_KEY: &str = "reduction_pct";

/// How far from zero `100 (1 - ratio)` lands from rounding alone when the ratio is 1: 8 ulps
/// of 1, in percent (1.8e-13 %). The cube model with A = B = 0 gave -2.2e-14 % (issue 26).
pub const PERCENT_ROUNDING: f64 = 100.0 * 8.0 * f64::EPSILON;

/// Sets a `reduction_pct` within [`PERCENT_ROUNDING`] of zero to zero; the value it had.
fn zero_within_rounding(outputs: &mut sonolube_host::fixed_eval::Outputs) -> Option<f64> {
    let value = outputs.get_mut(PERCENT_KEY)?;
    if *value != 0.0 && value.abs() < PERCENT_ROUNDING {
        let was = *value;
        *value = 0.0;
        return Some(was);
    }
    None
}

/// Adds (or extends) the flag of `key` in an answer.
fn add_flag(answer: &mut Value, key: &str, why: String) {
    let Some(object) = answer.as_object_mut() else {
        return;
    };
    let flags = object
        .entry("flags")
        .or_insert_with(|| Value::Object(Map::new()));
    if let Some(flags) = flags.as_object_mut() {
        let text = match flags.get(key).and_then(Value::as_str) {
            Some(before) => format!("{before}; {why}"),
            None => why,
        };
        flags.insert(key.to_string(), json!(text));
    }
}

fn error(message: String) -> Value {
    json!({ "error": message })
}
