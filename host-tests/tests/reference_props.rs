//! Properties of the reference model: exact limits, cross-checks between independent methods
//! (closed form vs fine numerical averages, exact Dahl update vs RK4, forward vs inverse
//! contact maps, adaptive vs brute-force quadrature), domain errors, and proptest sweeps over
//! the physical domain (never panics, finite or Err, physical bounds, monotonicity).

use std::collections::BTreeMap;
use std::f64::consts::PI;

use proptest::prelude::*;
use sonolube_host::papers::{AL_SS, SS_SS, TEST_1};
use sonolube_host::reference::coulomb::littmann_ratio;
use sonolube_host::reference::{MODELS, Outputs, RefError, eval_named, example_inputs};

type Pairs<'a> = &'a [(&'a str, f64)];

fn eval_with(
    model: &str,
    groups: &[Pairs<'_>],
    variant: &[(&str, &str)],
) -> Result<Outputs, RefError> {
    let inputs: BTreeMap<String, f64> = groups
        .iter()
        .flat_map(|g| g.iter())
        .map(|&(k, v)| (k.to_string(), v))
        .collect();
    let variant = variant
        .iter()
        .map(|&(k, v)| (k.to_string(), v.to_string()))
        .collect();
    eval_named(model, &inputs, &variant)
}

fn eval(model: &str, groups: &[Pairs<'_>]) -> Outputs {
    eval_with(model, groups, &[]).unwrap_or_else(|e| panic!("{model}: {e}"))
}

fn dahl(w: f64, k_t: f64, v: f64, v_a: f64, alpha: f64) -> Outputs {
    let p = [
        ("mu", 0.2),
        ("W", w),
        ("k_t", k_t),
        ("v", v),
        ("v_a", v_a),
        ("f", 40e3),
        ("alpha", alpha),
    ];
    eval("dahl_steady", &[&p])
}

/// Forward and backward travel per period, in units of x_a, from the plain textbook formulas.
fn travel_limit(zeta: f64) -> f64 {
    let theta = (-zeta).acos();
    let forward = zeta * theta + theta.sin();
    let backward = theta.sin() - zeta * (PI - theta);
    (forward - backward) / (forward + backward)
}

/// RK4 integration of the Dahl law in theta = omega t (seed 003 eq 7 with f = F / (mu W)):
/// df/dtheta = k v(theta) (1 - f sgn v)^alpha, k = k_t / (mu W omega). Returns the Simpson
/// average of f over the last `average_periods` periods of `periods`. With 4000 steps per
/// period it agrees with the exact solution to about 1e-8 (1e-10 at 64000 steps).
fn dahl_rk4(
    k: f64,
    v: f64,
    v_a: f64,
    alpha: f64,
    f0: f64,
    periods: usize,
    average_periods: usize,
) -> f64 {
    let steps_per_period = 4000;
    let h = 2.0 * PI / steps_per_period as f64;
    let rate = |theta: f64, f: f64| {
        let velocity = v + v_a * theta.cos();
        let base = (1.0 - f * velocity.signum()).max(0.0);
        if velocity == 0.0 {
            0.0
        } else {
            k * velocity * base.powf(alpha)
        }
    };
    let start_average = (periods - average_periods) * steps_per_period;
    let (mut f, mut sum) = (f0, 0.0);
    for step in 0..periods * steps_per_period {
        let theta = step as f64 * h;
        if step >= start_average {
            let weight = if step == start_average {
                1.0
            } else if (step - start_average) % 2 == 1 {
                4.0
            } else {
                2.0
            };
            sum += weight * f;
        }
        let k1 = rate(theta, f);
        let k2 = rate(theta + 0.5 * h, f + 0.5 * h * k1);
        let k3 = rate(theta + 0.5 * h, f + 0.5 * h * k2);
        let k4 = rate(theta + h, f + h * k3);
        f += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    (sum + f) * h / 3.0 / (2.0 * PI * average_periods as f64)
}

#[test]
fn no_vibration_means_no_reduction() {
    let coulomb = eval(
        "coulomb_avg_friction",
        &[&[
            ("mu", 0.3),
            ("W", 2.0),
            ("v", 0.01),
            ("x_a", 0.0),
            ("f", 40e3),
        ]],
    );
    assert_eq!(coulomb["reduction_pct"], 0.0);
    assert_eq!(coulomb["F_avg"], coulomb["F_novib"]);
    assert_eq!(dahl(2.0, 5.6e4, 0.01, 0.0, 1.0)["ratio"], 1.0);
    let window = [
        ("mu", 0.2),
        ("W", 1.0),
        ("k_t", 5.6e4),
        ("v", 0.01),
        ("v_a", 0.0),
        ("f", 40e3),
        ("Tw", 1e-3),
        ("f0", 1.0),
    ];
    assert_eq!(eval("dahl_window", &[&window])["reduction_pct"], 0.0);
    let cube = eval(
        "cube_reduction",
        &[AL_SS, TEST_1, &[("F_n", 100.0), ("A", 0.0), ("B", 0.0)]],
    );
    assert!((cube["ratio"] - 1.0).abs() < 1e-14);
}

#[test]
fn velocity_ratio_limits_are_exact() {
    for zeta in [1.0f64, 1.5, 10.0, -1.0, -3.0] {
        let v_a = 0.05;
        assert_eq!(littmann_ratio(zeta), zeta.signum());
        assert_eq!(
            dahl(1.0, 5.6e4, zeta * v_a, v_a, 1.0)["ratio"],
            1.0,
            "zeta {zeta}"
        );
        let x_a = v_a / (2.0 * PI * 40e3);
        let c = eval(
            "coulomb_avg_friction",
            &[&[
                ("mu", 0.2),
                ("W", 1.0),
                ("v", zeta * v_a),
                ("x_a", x_a),
                ("f", 40e3),
            ]],
        );
        assert_eq!(c["reduction_pct"], 0.0);
    }
    assert_eq!(littmann_ratio(0.0), 0.0);
    let c = eval(
        "coulomb_avg_friction",
        &[&[
            ("mu", 0.2),
            ("W", 1.0),
            ("v", 0.0),
            ("x_a", 1e-6),
            ("f", 40e3),
        ]],
    );
    // v = 0: the friction averages to zero; there is no natural friction to reduce, so the
    // percent reduction (and the Dahl ratio to it) is undefined, not 100 %.
    assert_eq!(c["F_avg"], 0.0);
    assert!(!c.contains_key("reduction_pct"));
    for k_t in [1.0, 5.6e4, 1e9] {
        let still = dahl(1.0, k_t, 0.0, 0.05, 1.0);
        assert!(still["F_avg"].abs() < 1e-14 * 0.2);
        assert!(!still.contains_key("ratio") && !still.contains_key("reduction_pct"));
    }
}

#[test]
fn dahl_stiff_limit_is_coulomb_and_soft_limit_is_travel_ratio() {
    for zeta in [-0.8, -0.2, 0.3, 0.5564, 0.9] {
        let v_a = 5.0; // x_a = 20 um at 40 kHz; kappa x_a = 1e10 x_a / (0.2e-3) = 1e9
        let stiff = dahl(1e-3, 1e10, zeta * v_a, v_a, 1.0);
        let bound = 10.0 / stiff["kxa"].sqrt();
        assert!(
            (stiff["ratio"] - littmann_ratio(zeta.abs())).abs() < bound,
            "zeta {zeta}"
        );
        let soft = dahl(1.0, 1e-3, zeta * 0.0683, 0.0683, 1.0);
        assert!(soft["kxa"] < 1e-8);
        assert!(
            (soft["ratio"] - travel_limit(zeta.abs())).abs() < 1e-7,
            "zeta {zeta}"
        );
    }
}

#[test]
fn littmann_is_the_average_of_the_coulomb_sign() {
    for zeta in [-0.95, -0.4, 0.0, 0.25, 0.5564, 0.9, 0.999] {
        let n = 400_000;
        let sum: f64 = (0..n)
            .map(|k| (zeta + (2.0 * PI * (k as f64 + 0.5) / n as f64).cos()).signum())
            .sum();
        assert!(
            (sum / n as f64 - littmann_ratio(zeta)).abs() < 4.0 / n as f64,
            "zeta {zeta}"
        );
        let sampled = [
            ("v", zeta * 0.07),
            ("v_a", 0.07),
            ("f", 40e3),
            ("dt", 2.5e-10),
            ("Tw", 25e-6),
        ];
        let mean = eval("coulomb_sampled_avg_sign", &[&sampled])["mean_sign"];
        assert!((mean - littmann_ratio(zeta)).abs() < 5e-5, "zeta {zeta}");
    }
}

#[test]
fn dahl_window_matches_rk4() {
    for (w, k_t, v, f0) in [
        (0.54, 5.6e4, 0.038, 1.0),
        (1.902, 5.6e4, 0.038, 1.0),
        (0.54, 5.6e5, 0.02, -0.3),
        (4.0, 5.6e4, -0.05, 0.5),
    ] {
        let p = [
            ("mu", 0.2),
            ("W", w),
            ("k_t", k_t),
            ("v", v),
            ("v_a", 0.0683),
            ("f", 40e3),
            ("Tw", 1e-3),
            ("f0", f0),
        ];
        let exact = eval("dahl_window", &[&p])["F_avg"] / (0.2 * w);
        let k = k_t / (0.2 * w * 2.0 * PI * 40e3);
        let rk4 = dahl_rk4(k, v, 0.0683, 1.0, f0, 40, 40);
        assert!(
            (exact - rk4).abs() < 5e-8,
            "W {w} k_t {k_t}: {exact} vs {rk4}"
        );
    }
}

#[test]
fn dahl_steady_matches_rk4_for_several_shapes() {
    for (alpha, zeta, tolerance) in [
        (1.0, 0.5564f64, 3e-8),
        (2.0, 0.3, 3e-8),
        (0.5, -0.4, 3e-8),
        (1.0, 0.95, 3e-8),
    ] {
        let (v_a, k_t) = (0.0683, 2e5);
        let steady = dahl(1.0, k_t, zeta * v_a, v_a, alpha);
        let k = k_t / (0.2 * 2.0 * PI * 40e3);
        let rk4 = dahl_rk4(k, zeta * v_a, v_a, alpha, 1.0, 80, 2) * zeta.signum();
        assert!(
            (steady["ratio"] - rk4).abs() < tolerance,
            "alpha {alpha}: {} vs {rk4}",
            steady["ratio"]
        );
    }
}

/// The steady state is what the switch-on window settles to: the average over periods
/// [n1, n2), from two windows, equals the periodic steady state once n1 is many e-folding
/// times (1.5 periods at 0.54 N, 22 at 7.9 N, physics-notes §2).
#[test]
fn dahl_steady_is_the_late_window_average() {
    for (w, n1) in [(0.54, 100.0), (7.905, 1000.0)] {
        let n2 = n1 + 100.0;
        let window = |periods: f64| {
            let tw = periods / 40e3;
            let p = [
                ("mu", 0.2),
                ("W", w),
                ("k_t", 5.6e4),
                ("v", 0.038),
                ("v_a", 0.0683),
                ("f", 40e3),
                ("Tw", tw),
                ("f0", 1.0),
            ];
            eval("dahl_window", &[&p])["F_avg"] * tw
        };
        let late = (window(n2) - window(n1)) / ((n2 - n1) / 40e3);
        let steady = dahl(w, 5.6e4, 0.038, 0.0683, 1.0)["F_avg"];
        assert!(
            (late / steady - 1.0).abs() < 1e-10,
            "W {w}: {late} vs {steady}"
        );
    }
}

#[test]
fn dahl_delta_transient_matches_rk4() {
    let (force, stiffness, v_rel, delta0): (f64, f64, f64, f64) = (21.6, 4.4e10, -0.005, 3e-10);
    let rate = |d: f64| v_rel * (1.0 - stiffness * d / force * v_rel.signum());
    let (t_end, n) = (3e-7, 30_000);
    let h = t_end / n as f64;
    let mut d = delta0;
    for _ in 0..n {
        let (k1, k2) = (rate(d), rate(d + 0.5 * h * rate(d)));
        let k3 = rate(d + 0.5 * h * k2);
        d += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + rate(d + h * k3));
    }
    let p = [
        ("F_t0", force),
        ("K_t", stiffness),
        ("v_rel", v_rel),
        ("t", t_end),
        ("delta0", delta0),
    ];
    let exact = eval("dahl_delta_transient", &[&p]);
    assert!((exact["delta"] - d).abs() < 1e-12 * force / stiffness);
    assert_eq!(exact["delta_ss"], force / stiffness);
}

#[test]
fn contact_forward_and_inverse_maps_agree() {
    for material in [AL_SS, SS_SS] {
        for exponent in -3..=4 {
            let load = 10f64.powi(exponent) * 4.7;
            let from_force = eval("contact_ep", &[material, &[("F_n", load)]]);
            let back = eval("contact_ep_of_d", &[material, &[("d", from_force["d"])]]);
            for key in ["A_r", "K_t"] {
                assert!(
                    (back[key] / from_force[key] - 1.0).abs() < 1e-11,
                    "{key} at {load} N"
                );
            }
            assert!((back["F_n"] / load - 1.0).abs() < 1e-11);
            // Independent inversion: bisection of F_n(d) = load.
            // Below about 3.5 um the real area would exceed A_n (refused): treat as "too close".
            let residual =
                |d: f64| match eval_with("contact_ep_of_d", &[material, &[("d", d)]], &[]) {
                    Ok(state) => state["F_n"] - load,
                    Err(_) => f64::INFINITY,
                };
            let (mut lo, mut hi) = (1e-7, 1e-4);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if residual(mid) > 0.0 {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            assert!((lo / from_force["d"] - 1.0).abs() < 1e-13, "d at {load} N");
        }
    }
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

fn frequency() -> impl Strategy<Value = f64> {
    prop_oneof![Just(20e3), Just(60e3)]
}

/// Failing cases are kept in, and replayed from, `tests/<this file>.proptest-regressions`:
/// named here because proptest's default (a `proptest-regressions` folder beside the
/// nearest `lib.rs`) finds no `lib.rs` above `tests/` and only falls back to it with a warning.
fn regressions() -> Option<Box<dyn proptest::test_runner::FailurePersistence>> {
    Some(Box::new(
        proptest::test_runner::FileFailurePersistence::WithSource("proptest-regressions"),
    ))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 192, failure_persistence: regressions(), ..ProptestConfig::default() })]

    #[test]
    fn littmann_is_odd_bounded_monotone(a in -10.0..10.0f64, b in -10.0..10.0f64) {
        let (lo, hi) = (a.min(b), a.max(b));
        prop_assert!(littmann_ratio(lo) <= littmann_ratio(hi));
        prop_assert!(littmann_ratio(a).abs() <= 1.0);
        prop_assert_eq!(littmann_ratio(-a), -littmann_ratio(a));
    }

    #[test]
    fn coulomb_reduction_bounded_and_monotone_in_amplitude(
        mu in 0.0..1.0f64, w in log_uniform(1e-3, 5e4), zeta in -10.0..10.0f64,
        x1 in 0.0..50e-6f64, x2 in 0.0..50e-6f64, f in frequency()) {
        // zeta is the velocity ratio at the smaller amplitude; the larger one lowers |zeta|.
        let v = zeta * 2.0 * PI * f * x1.min(x2);
        let run = |x_a: f64| eval_with("coulomb_avg_friction", &[&[("mu", mu), ("W", w), ("v", v), ("x_a", x_a), ("f", f)]], &[]);
        if let (Ok(small), Ok(large)) = (run(x1.min(x2)), run(x1.max(x2))) {
            prop_assert!((0.0..=100.0).contains(&small["reduction_pct"]));
            prop_assert!(small["reduction_pct"] <= large["reduction_pct"]);
            prop_assert!(large["F_avg"].abs() <= mu * w * (1.0 + 1e-15));
        }
    }

    #[test]
    fn dahl_steady_between_its_limits_and_monotone_in_amplitude(
        w in log_uniform(1e-3, 5e4), k_t in log_uniform(1.0, 1e10), zeta in -10.0..10.0f64,
        x1 in 0.0..50e-6f64, x2 in 0.0..50e-6f64, f in frequency()) {
        let v = zeta * 2.0 * PI * f * x1.min(x2);
        let run = |x_a: f64| eval_with("dahl_steady", &[&[("mu", 0.2), ("W", w), ("k_t", k_t), ("v", v), ("v_a", 2.0 * PI * f * x_a), ("f", f)]], &[]);
        let (small, large) = (run(x1.min(x2)), run(x1.max(x2)));
        for outputs in [&small, &large].into_iter().flatten() {
            prop_assert!(outputs.values().all(|value| value.is_finite()));
            let zeta = outputs["zeta"].abs().min(1.0);
            let (coulomb, soft) = (littmann_ratio(zeta), if zeta < 1.0 { travel_limit(zeta) } else { 1.0 });
            prop_assert!(outputs["ratio"] >= coulomb - 1e-9 && outputs["ratio"] <= soft + 1e-9);
        }
        if let (Ok(small), Ok(large)) = (small, large) {
            prop_assert!(small["reduction_pct"] <= large["reduction_pct"] + 1e-9);
        }
    }

    #[test]
    fn dahl_window_stays_within_the_coulomb_level(
        w in log_uniform(1e-3, 5e4), k_t in log_uniform(1.0, 1e10), v in -1.0..1.0f64,
        v_a in 0.0..1.0f64, tw in 1e-6..5e-4f64, f0 in -1.0..=1.0f64, f in frequency()) {
        let p = [("mu", 0.2), ("W", w), ("k_t", k_t), ("v", v), ("v_a", v_a), ("f", f), ("Tw", tw), ("f0", f0)];
        if let Ok(outputs) = eval_with("dahl_window", &[&p], &[]) {
            prop_assert!(outputs["F_avg"].abs() <= 0.2 * w * (1.0 + 1e-12));
        }
    }

    #[test]
    fn contact_is_exponential_in_load(load in log_uniform(1e-3, 5e4), ss in any::<bool>()) {
        let material = if ss { SS_SS } else { AL_SS };
        let at = |f_n: f64| eval("contact_ep", &[material, &[("F_n", f_n)]]);
        let (here, unit) = (at(load), at(1.0));
        prop_assert!(here["d"] > 0.0 && here["A_r_over_An"] <= 1.0);
        prop_assert!((here["p_c"] / unit["p_c"] - 1.0).abs() < 1e-12);
        prop_assert!((here["d"] - unit["d"] + 2e-6 * load.ln()).abs() < 1e-18 + 1e-12 * unit["d"]);
    }

    #[test]
    fn contact_of_small_separation_is_finite_or_refused(d in log_uniform(1e-300, 1e-4)) {
        match eval_with("contact_ep_of_d", &[AL_SS, &[("d", d)]], &[]) {
            Ok(outputs) => prop_assert!(outputs.values().all(|v| v.is_finite() && *v >= 0.0)),
            Err(error) => prop_assert!(!error.to_string().is_empty()),
        }
    }

    #[test]
    fn cube_bounded_monotone_in_b_and_frequency_free(
        load in log_uniform(1e-3, 5e4), a in 0.0..50e-6f64, b1 in 0.0..50e-6f64, b2 in 0.0..50e-6f64) {
        let run = |b: f64, f: f64| eval_with("cube_reduction", &[AL_SS, TEST_1, &[("F_n", load), ("A", a), ("B", b), ("f", f)]], &[]);
        if let (Ok(small), Ok(large), Ok(fast)) = (run(b1.min(b2), 20e3), run(b1.max(b2), 20e3), run(b1.min(b2), 60e3)) {
            prop_assert!(small["ratio"] > 0.0 && small["ratio"] <= 1.0 + 1e-14);
            prop_assert!(small["reduction_pct"] <= large["reduction_pct"] + 1e-9);
            prop_assert_eq!(small["ratio"], fast["ratio"]);
        }
    }

    #[test]
    fn eval_named_never_panics(
        model in 0..MODELS.len(), drop in any::<u64>(), scale in prop_oneof![
            Just(1.0), Just(-1.0), Just(0.0), Just(1e300), Just(-1e-300), Just(f64::NAN), Just(f64::INFINITY)],
        which in any::<u64>()) {
        let name = MODELS[model];
        let mut inputs = example_inputs(name).unwrap();
        let keys: Vec<String> = inputs.keys().cloned().collect();
        let target = &keys[(which % keys.len() as u64) as usize];
        if drop % 5 == 0 { inputs.remove(target); } else { inputs.insert(target.clone(), inputs[target] * scale); }
        if let Ok(outputs) = eval_named(name, &inputs, &BTreeMap::new()) {
            prop_assert!(outputs.values().all(|v| v.is_finite()), "{name}: {outputs:?}");
        }
    }
}
