//! Numerical behaviour at the extremes (issue 15), through `sonolube eval`'s answers
//! (`cli::eval::batch_line`, the JSON a user sees) and the fixed-point/reference pair:
//! - an undefined quantity is `null` with a reason, never a finite stand-in or a limit value;
//! - an output outside its physical range is flagged (or the inputs refused) with the reason;
//! - a nonzero velocity the fixed point would read as zero is refused;
//! - an input frequency outside the 20-60 kHz drive band is flagged;
//! - `dahl_steady` in fixed point is monotone in amplitude wherever the reference is, and within
//!   max(1e-3 relative, 3 / N^2 absolute) of it.

use std::collections::BTreeMap;

use proptest::prelude::*;
use serde_json::{Value, json};
use sonolube_cli::commands::eval::batch_line;
use sonolube_host::fixed_eval::coulomb_dahl::eval_with_quantized_inputs;
use sonolube_host::reference::{eval_named, example_inputs};

type Inputs = BTreeMap<String, f64>;

fn ask(model: &str, inputs: &[(&str, f64)]) -> Value {
    let inputs: BTreeMap<&str, f64> = inputs.iter().copied().collect();
    batch_line(&json!({ "model": model, "inputs": inputs }).to_string())
}

fn ask_map(model: &str, inputs: &Inputs) -> Value {
    batch_line(&json!({ "model": model, "inputs": inputs }).to_string())
}

/// Every number of both sides, with its key.
fn numbers(answer: &Value) -> Vec<(String, f64)> {
    let mut all = Vec::new();
    for side in ["outputs", "reference"] {
        if let Some(map) = answer[side].as_object() {
            for (key, value) in map {
                if let Some(x) = value.as_f64() {
                    all.push((format!("{side}.{key}"), x));
                }
            }
        }
    }
    all
}

/// No output is a finite stand-in for an infinite or undefined value.
fn no_stand_in(answer: &Value) -> Result<(), TestCaseError> {
    for (key, x) in numbers(answer) {
        prop_assert!(x.is_finite() && x.abs() < 1e300, "{key} = {x}: {answer}");
    }
    Ok(())
}

/// `key` is null on both sides and its reason is given.
fn undefined(answer: &Value, key: &str) -> Result<(), TestCaseError> {
    prop_assert!(answer["outputs"][key].is_null(), "{key}: {answer}");
    prop_assert!(answer["reference"][key].is_null(), "{key}: {answer}");
    prop_assert!(
        answer["undefined"][key]
            .as_str()
            .is_some_and(|why| why.len() > 20),
        "{key} has no reason: {answer}"
    );
    Ok(())
}

fn defined(answer: &Value, key: &str) -> Result<(), TestCaseError> {
    prop_assert!(answer["outputs"][key].is_f64(), "{key}: {answer}");
    prop_assert!(answer["reference"][key].is_f64(), "{key}: {answer}");
    Ok(())
}

/// 0 half the time, else log-uniform in [lo, hi].
fn zero_or(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), (lo.ln()..hi.ln()).prop_map(f64::exp)]
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

#[test]
fn the_issue_examples() {
    // No vibration: zeta is undefined, not -1.797e308.
    let answer = ask(
        "coulomb_avg_friction",
        &[
            ("mu", 0.2),
            ("W", 0.54),
            ("v", -0.038),
            ("x_a", 0.0),
            ("f", 40e3),
        ],
    );
    assert!(!answer.to_string().contains("e+308"), "{answer}");
    assert!(answer["outputs"]["zeta"].is_null() && answer["undefined"]["zeta"].is_string());
    assert_eq!(answer["outputs"]["reduction_pct"], json!(0.0));
    // Every sample at one phase: refused, with the reason.
    let answer = ask(
        "coulomb_sampled_avg_sign",
        &[
            ("v", -0.2),
            ("v_a", 0.77),
            ("f", 40e3),
            ("dt", 2.5e-5),
            ("Tw", 1e-3),
        ],
    );
    let error = answer["error"].as_str().unwrap_or_default();
    assert!(error.contains("2 samples per vibration period"), "{answer}");
    // The cube at x = -0.1 mm: F'/F = -13.7 from both sides, flagged with the reason.
    let mut cube = example_inputs("cube_reduction").unwrap();
    cube.insert("x".into(), -1e-4);
    let answer = ask_map("cube_reduction", &cube);
    assert!(
        answer["outputs"]["ratio"].as_f64().unwrap() < -13.0,
        "{answer}"
    );
    let flag = answer["flags"]["ratio"].as_str().unwrap_or_default();
    assert!(flag.contains("< 0") && flag.contains("u/delta"), "{answer}");
    // A subnormal velocity: refused by the fixed point, which would read it as 0.
    let answer = ask(
        "coulomb_avg_friction",
        &[
            ("mu", 0.2),
            ("W", 0.54),
            ("v", 1e-310),
            ("x_a", 1e-7),
            ("f", 40e3),
        ],
    );
    let error = answer["error"].as_str().unwrap_or_default();
    assert!(
        error.contains("below the fixed-point resolution"),
        "{answer}"
    );
    // Percent reduction of zero natural friction (v = 0): undefined, not 100 %.
    let answer = ask(
        "coulomb_avg_friction",
        &[
            ("mu", 0.2),
            ("W", 0.54),
            ("v", 0.0),
            ("x_a", 1e-7),
            ("f", 40e3),
        ],
    );
    assert!(answer["outputs"]["reduction_pct"].is_null(), "{answer}");
    // The Dahl step the issue found non-monotone, now decreasing like the reference.
    let dahl = |v_a: f64| {
        let answer = ask(
            "dahl_steady",
            &[
                ("mu", 0.5809),
                ("W", 0.0197),
                ("v", 0.0303),
                ("f", 20e3),
                ("k_t", 1.399e8),
                ("alpha", 0.5),
                ("v_a", v_a),
            ],
        );
        (
            answer["outputs"]["ratio"].as_f64().unwrap(),
            answer["reference"]["ratio"].as_f64().unwrap(),
        )
    };
    let (low, high) = (dahl(1.3980), dahl(1.4137));
    assert!(high.1 < low.1 && high.0 < low.0, "{low:?} -> {high:?}");
    assert!((low.0 - low.1).abs() <= 1e-3 * low.1, "{low:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Coulomb average: zeta is undefined exactly without vibration, the reduction exactly when
    /// there is no friction to reduce; nothing else is ever null, and no number is a stand-in.
    #[test]
    fn coulomb_undefined_outputs_are_null_with_a_reason(
        mu in zero_or(0.01, 2.0),
        w in zero_or(0.01, 100.0),
        v in zero_or(1e-6, 10.0),
        negative in any::<bool>(),
        x_a in zero_or(1e-9, 1e-5),
        f in 20e3..60e3f64,
    ) {
        let v = if negative { -v } else { v };
        let answer = ask("coulomb_avg_friction", &[("mu", mu), ("W", w), ("v", v), ("x_a", x_a), ("f", f)]);
        if v == 0.0 && x_a == 0.0 {
            prop_assert!(answer["error"].as_str().is_some_and(|e| e.contains("no relative motion")), "{answer}");
            return Ok(());
        }
        no_stand_in(&answer)?;
        if x_a == 0.0 { undefined(&answer, "zeta")?; } else { defined(&answer, "zeta")?; }
        if v == 0.0 || mu == 0.0 || w == 0.0 {
            undefined(&answer, "reduction_pct")?;
        } else {
            defined(&answer, "reduction_pct")?;
            let reduction = answer["reference"]["reduction_pct"].as_f64().unwrap();
            prop_assert!((0.0..=100.0).contains(&reduction) && answer["flags"].is_null(), "{answer}");
        }
        for key in ["v_a", "F_novib", "F_avg"] {
            defined(&answer, key)?;
        }
    }

    /// Dahl steady state and window, sampled sign: the ratio and reductions are undefined at
    /// v = 0, zeta without vibration; never a stand-in.
    #[test]
    fn dahl_and_sampled_undefined_outputs_are_null_with_a_reason(
        v in zero_or(1e-4, 0.5),
        v_a in zero_or(1e-3, 1.0),
        k_t in log_uniform(1e3, 1e9),
        alpha in 0.3..2.0f64,
        f in 20e3..60e3f64,
    ) {
        let base = [("mu", 0.3), ("W", 2.0), ("v", v), ("v_a", v_a), ("f", f), ("k_t", k_t)];
        let mut steady = base.to_vec();
        steady.push(("alpha", alpha));
        let answer = ask("dahl_steady", &steady);
        if v == 0.0 && v_a == 0.0 {
            prop_assert!(answer["error"].is_string(), "{answer}");
            return Ok(());
        }
        no_stand_in(&answer)?;
        if v_a == 0.0 { undefined(&answer, "zeta")?; } else { defined(&answer, "zeta")?; }
        if v == 0.0 {
            undefined(&answer, "ratio")?;
            undefined(&answer, "reduction_pct")?;
        } else {
            defined(&answer, "ratio")?;
            defined(&answer, "reduction_pct")?;
        }
        let mut window = base.to_vec();
        window.extend([("Tw", 20.0 / f), ("f0", 1.0)]);
        let answer = ask("dahl_window", &window);
        no_stand_in(&answer)?;
        if v == 0.0 { undefined(&answer, "reduction_pct")?; } else { defined(&answer, "reduction_pct")?; }
        let sampled = [("v", v), ("v_a", v_a), ("f", f), ("dt", 0.01 / f), ("Tw", 3.0 / f)];
        let answer = ask("coulomb_sampled_avg_sign", &sampled);
        no_stand_in(&answer)?;
        if v == 0.0 { undefined(&answer, "reduction_pct")?; } else { defined(&answer, "reduction_pct")?; }
    }

    /// The sampled average refuses steps of half a period or more (the samples alias); with
    /// finer steps, a reduction outside [0, 100] % (a window shorter than a period) is flagged.
    #[test]
    fn sampled_average_is_refused_when_aliased_and_flagged_out_of_range(
        v in -0.5..0.5f64,
        v_a in 0.0..1.0f64,
        f in 20e3..60e3f64,
        samples_per_period in 0.2..400.0f64,
        periods in 0.01..10.0f64,
    ) {
        prop_assume!(v != 0.0);
        let dt = 1.0 / (f * samples_per_period);
        let tw = (periods / f).max(dt);
        let answer = ask("coulomb_sampled_avg_sign", &[("v", v), ("v_a", v_a), ("f", f), ("dt", dt), ("Tw", tw)]);
        if f * dt > 0.5 {
            prop_assert!(answer["error"].as_str().is_some_and(|e| e.contains("alias")), "{answer}");
            return Ok(());
        }
        for side in ["outputs", "reference"] {
            let reduction = answer[side]["reduction_pct"].as_f64().unwrap();
            if !(0.0..=100.0).contains(&reduction) {
                prop_assert!(answer["flags"]["reduction_pct"].is_string(), "{answer}");
            }
        }
    }

    /// Cube: wherever the contact sits along the horn, a negative friction ratio is flagged
    /// with the reason, as is |u/delta| > 1 (outside the model's validity); at the node neither.
    #[test]
    fn cube_outputs_outside_the_physical_range_are_flagged(
        x in -0.0635..0.0635f64,
        load in log_uniform(40.0, 240.0),
    ) {
        let mut inputs = example_inputs("cube_reduction").unwrap();
        inputs.insert("x".into(), x);
        inputs.insert("F_n".into(), load);
        let answer = ask_map("cube_reduction", &inputs);
        if answer["error"].is_string() {
            // Far off the node F'/F leaves the Q8.24 range: the fixed point refuses it, saying why.
            prop_assert!(answer["error"].as_str().unwrap().contains("saturates"), "{answer}");
            return Ok(());
        }
        no_stand_in(&answer)?;
        let ratio = answer["reference"]["ratio"].as_f64().unwrap();
        let u = answer["reference"]["u_over_delta"].as_f64().unwrap();
        if ratio < 0.0 {
            prop_assert!(answer["flags"]["ratio"].as_str().is_some_and(|f| f.contains("< 0")), "{answer}");
        } else if u.abs() > 1.0 {
            prop_assert!(answer["flags"]["u_over_delta"].is_string(), "{answer}");
        } else {
            prop_assert!(answer["flags"].is_null(), "{answer}");
        }
    }

    /// A nonzero velocity below the fixed-point resolution (subnormal ones included) is refused
    /// by the fixed point, with the reason; one resolution step is accepted with its sign.
    #[test]
    fn a_velocity_the_fixed_point_would_read_as_zero_is_refused(
        exponent in -1074i32..-26,
        negative in any::<bool>(),
    ) {
        let v = if negative { -(exponent as f64).exp2() } else { (exponent as f64).exp2() };
        let answer = ask("coulomb_avg_friction", &[("mu", 0.2), ("W", 0.54), ("v", v), ("x_a", 1e-7), ("f", 40e3)]);
        prop_assert!(answer["error"].as_str().is_some_and(|e| e.contains("below the fixed-point resolution")), "{answer}");
        let step = if negative { -(2f64.powi(-24)) } else { 2f64.powi(-24) };
        let answer = ask("coulomb_avg_friction", &[("mu", 0.2), ("W", 0.54), ("v", step), ("x_a", 1e-7), ("f", 40e3)]);
        prop_assert_eq!(answer["outputs"]["F_novib"].as_f64().unwrap().signum(), step.signum(), "{}", answer);
    }

    /// Drive band: a frequency outside 20-60 kHz is flagged by the models that take the drive
    /// frequency, with the band in the reason; inside it, never.
    #[test]
    fn frequencies_outside_the_drive_band_are_flagged(
        f in log_uniform(1e3, 3e5),
        model in prop::sample::select(vec!["coulomb_avg_friction", "dahl_steady", "cube_reduction", "horn_kinematics", "actuator"]),
    ) {
        let mut inputs = example_inputs(model).unwrap();
        inputs.insert("f".into(), f);
        let answer = ask_map(model, &inputs);
        prop_assume!(answer["error"].is_null());
        let flagged = answer["flags"]["f"].as_str();
        if (20e3..=60e3).contains(&f) {
            prop_assert!(flagged.is_none(), "{answer}");
        } else {
            prop_assert!(flagged.is_some_and(|why| why.contains("20-60 kHz")), "{answer}");
        }
    }
}

/// The ratio of `dahl_steady` (fixed point, reference at the fixed point's quantised inputs).
fn dahl_ratio(inputs: &Inputs, points: u32) -> Option<(f64, f64)> {
    let variant = BTreeMap::from([("quadrature_points".to_string(), points.to_string())]);
    let (ours, quantized) = eval_with_quantized_inputs("dahl_steady", inputs, &variant)?.ok()?;
    let theirs = eval_named("dahl_steady", &quantized, &BTreeMap::new()).ok()?;
    Some((ours["ratio"], theirs["ratio"]))
}

/// The stated accuracy of the fixed-point steady state (`model::dahl_quadrature`): 1e-3
/// relative, or 3 / N^2 absolute, the quadrature's floor (the ratio is mu_i minus a difference
/// of two gap integrals of order 1; their O(1/N^2) error does not shrink with the ratio).
fn dahl_bound(reference: f64, points: u32) -> f64 {
    (1e-3 * reference.abs()).max(3.0 / (points as f64 * points as f64))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(192))]

    /// Over the domain (zeta 1e-3..0.999, k_t x_a / (mu W) from about 1e-4 to 1e8, alpha 0.05..3):
    /// within the stated bound of the reference, and monotone in the amplitude wherever the
    /// reference is (the inversion bisects on it).
    #[test]
    fn dahl_steady_is_accurate_and_monotone_in_amplitude(
        mu in 0.05..1.0f64,
        w in log_uniform(0.01, 10.0),
        v in log_uniform(1e-3, 0.1),
        zeta in log_uniform(1e-3, 0.999),
        f in 20e3..60e3f64,
        k_t in log_uniform(1e3, 1e10),
        alpha in prop_oneof![Just(1.0), 0.05..1.0f64, 1.0..3.0f64],
        step in log_uniform(1e-5, 3e-2),
        points in prop::sample::select(vec![64u32, 128]),
    ) {
        let v_a = v / zeta;
        let inputs: Inputs = [("mu", mu), ("W", w), ("v", v), ("v_a", v_a), ("f", f), ("k_t", k_t), ("alpha", alpha)]
            .iter().map(|&(k, x)| (k.to_string(), x)).collect();
        let Some((ours, theirs)) = dahl_ratio(&inputs, points) else { return Ok(()) };
        prop_assert!((ours - theirs).abs() <= dahl_bound(theirs, points),
            "N {points}: ours {ours} reference {theirs} at {inputs:?}");
        let mut louder = inputs.clone();
        louder.insert("v_a".into(), v_a * (1.0 + step));
        let Some((ours_up, theirs_up)) = dahl_ratio(&louder, points) else { return Ok(()) };
        if theirs_up < theirs {
            // Four Q2.30 ulps (3.7e-9) of slack: each end is a sum of 64-128 rounded quadrature
            // terms rounded again to Q2.30, and where the ratio is within 1e-8 of 1 (zeta near
            // 1) the reference's own step is of that size; a bisection on the ratio cannot
            // resolve it anyway. Seen: a 2-ulp rise where the reference fell 2.3e-9.
            prop_assert!(ours_up <= ours + 4.0 / (1u64 << 30) as f64,
                "N {points}: not monotone: {ours} -> {ours_up} (reference {theirs} -> {theirs_up}) at {inputs:?}, v_a x {}", 1.0 + step);
        }
    }
}

/// The measurement behind the bound's documentation (`model::dahl_quadrature`): worst absolute
/// and relative ratio error and monotonicity breaks over 3,000 seeded random points per N.
/// Run: `cargo test -p sonolube-cli --test extremes -- --ignored --nocapture dahl_survey`.
#[test]
#[ignore = "a measurement (prints a table), about 10 s"]
fn dahl_survey() {
    let mut state: u64 = 0x1234_5678_9abc_def1;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    println!("| N | alpha | worst abs | worst rel | ratio there | not monotone |");
    println!("|---|---|---|---|---|---|");
    for points in [64u32, 128, 256] {
        for (label, low, high) in [("1", 1.0, 1.0), ("0.05-1", 0.05, 1.0), ("1-3", 1.0, 3.0)] {
            let (mut worst_abs, mut worst_rel, mut at, mut breaks) = (0.0f64, 0.0f64, 0.0, 0);
            for _ in 0..3000 {
                let mut log = |a: f64, b: f64| (a.ln() + (b.ln() - a.ln()) * next()).exp();
                let (w, v, zeta, k_t) = (
                    log(0.01, 10.0),
                    log(1e-3, 0.1),
                    log(1e-3, 0.999),
                    log(1e3, 1e10),
                );
                let (mu, f) = (0.05 + 0.95 * next(), 20e3 + 40e3 * next());
                let alpha = low + (high - low) * next();
                let step = 1.0 + 1e-4 * (300f64).powf(next());
                let inputs: Inputs = [
                    ("mu", mu),
                    ("W", w),
                    ("v", v),
                    ("v_a", v / zeta),
                    ("f", f),
                    ("k_t", k_t),
                    ("alpha", alpha),
                ]
                .iter()
                .map(|&(k, x)| (k.to_string(), x))
                .collect();
                let Some((ours, theirs)) = dahl_ratio(&inputs, points) else {
                    continue;
                };
                let error = (ours - theirs).abs();
                worst_abs = worst_abs.max(error);
                if error / theirs > worst_rel {
                    (worst_rel, at) = (error / theirs, theirs);
                }
                let mut louder = inputs.clone();
                louder.insert("v_a".into(), v / zeta * step);
                if let Some((ours_up, theirs_up)) = dahl_ratio(&louder, points) {
                    breaks += usize::from(theirs_up < theirs && ours_up > ours + 1e-9);
                }
            }
            println!(
                "| {points} | {label} | {worst_abs:.2e} | {worst_rel:.2e} | {at:.2e} | {breaks} / 3000 |"
            );
        }
    }
}
