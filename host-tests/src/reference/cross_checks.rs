//! Cross-checks of the string-keyed entry point against independent formulas and brute-force
//! quadrature, and of its error reporting (unit tests; the property tests and the Dahl / contact
//! cross-checks are in `tests/reference_props.rs`).

use std::collections::BTreeMap;
use std::f64::consts::PI;

use super::{MODELS, Outputs, RefError, eval_named};
use crate::papers::{AL_SS, TEST_1};

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

#[test]
fn elastic_model_is_seed_001_eqs_13_14_and_the_ep_limit() {
    let (rq, rs, an, eta, c, lam): (f64, f64, f64, f64, f64, f64) =
        (6e-6, 1.7e-6, 1e-4, 47e9, 17.0, 3.0);
    for (rule, e_star) in [
        (
            "seed000",
            1.0 / ((1.0 - 0.33f64.powi(2)) / 73e9 + (1.0 - 0.29f64.powi(2)) / 200e9),
        ),
        ("seed001", 1.0 / (1.0 / 73e9 + 1.0 / 200e9)),
    ] {
        for load in [0.01, 40.0, 240.0, 3e4] {
            let el = eval_with(
                "contact_el",
                &[AL_SS, &[("F_n", load)]],
                &[("E_star_rule", rule)],
            )
            .unwrap();
            let argument = c * PI.sqrt() * eta * an * e_star * rq.powf(1.5) * rs.sqrt()
                / (lam.powf(2.5) * load);
            assert!((el["d"] / (rq / lam * argument.ln()) - 1.0).abs() < 1e-13);
            let area = load / e_star * (PI * lam * rs / rq).sqrt();
            assert!((el["A_r"] / area - 1.0).abs() < 1e-13);
            // Elastic-plastic with an enormous yield strength (X -> infinity) is the elastic model.
            let hard = eval_with(
                "contact_ep",
                &[AL_SS, &[("F_n", load), ("Y0", 1e14)]],
                &[("E_star_rule", rule)],
            )
            .unwrap();
            assert!((hard["d"] / el["d"] - 1.0).abs() < 1e-13);
        }
    }
}

/// Brute-force midpoint average of the eq 15 integrand built from `horn_kinematics` outputs.
fn cube_brute_force(x: f64, phase: &str, window: &str) -> (f64, f64) {
    let load = [("F_n", 90.0), ("x", x)];
    let variant = [("u_phase", phase), ("window", window)];
    let cube = eval_with("cube_reduction", &[AL_SS, TEST_1, &load], &variant).unwrap();
    let (d, delta, f) = (cube["d"], cube["delta"], 20e3);
    let (start, span) = if window == "vpos" {
        (-0.25, 0.5)
    } else {
        (0.0, 0.5)
    };
    let n = 100_000;
    let mut sum = 0.0;
    for k in 0..n {
        let t = (start + span * (k as f64 + 0.5) / n as f64) / f;
        let horn = [
            ("x", x),
            ("t", t),
            ("A", 11.46e-6),
            ("B", 1.1e-6),
            ("f", f),
            ("L", 0.127),
        ];
        let uv = eval_with("horn_kinematics", &[&horn], &[("u_phase", phase)]).unwrap();
        let scale = d / (d + uv["v"]);
        sum += (-2.0 * 3.0 * uv["v"] / 6e-6).exp() * scale.powi(3) * (1.0 + uv["u"] / delta);
    }
    (cube["ratio"], sum / n as f64)
}

#[test]
fn cube_average_matches_brute_force_quadrature() {
    for (x, phase, window) in [
        (0.0, "inphase", "vpos"),
        (0.0, "inphase", "literal_cos"),
        (2e-9, "inphase", "vpos"),
        (2e-9, "quadrature", "literal_cos"),
        (0.02, "quadrature", "vpos"),
    ] {
        let (adaptive, brute) = cube_brute_force(x, phase, window);
        assert!(
            (adaptive - brute).abs() <= 1e-9 * adaptive.abs().max(1.0),
            "{x} {phase} {window}: {adaptive} vs {brute}"
        );
    }
}

#[test]
fn errors_name_the_problem() {
    let message = |model: &str, groups: &[Pairs<'_>], variant: &[(&str, &str)]| {
        eval_with(model, groups, variant)
            .expect_err("must fail")
            .to_string()
    };
    assert!(message("nope", &[], &[]).contains("unknown model"));
    assert!(message("littmann_mu_i", &[], &[]).contains("`zeta`"));
    assert!(message("littmann_mu_i", &[&[("zeta", 0.1), ("zeta2", 1.0)]], &[]).contains("zeta2"));
    assert!(message("littmann_mu_i", &[&[("zeta", f64::NAN)]], &[]).contains("not a finite"));
    assert!(
        message("littmann_mu_i", &[&[("zeta", 0.1)]], &[("window", "vpos")])
            .contains("unknown variant key")
    );
    assert!(message("contact_ep", &[AL_SS, &[("F_n", -1.0)]], &[]).contains("`F_n`"));
    assert!(message("contact_ep", &[AL_SS, &[("F_n", 1e7)]], &[]).contains("validity"));
    assert!(
        message(
            "contact_ep",
            &[AL_SS, &[("F_n", 1.0)]],
            &[("E_star_rule", "x")]
        )
        .contains("seed001")
    );
    let cube = [AL_SS, TEST_1, &[("F_n", 40.0)]];
    assert!(
        message("cube_reduction", &cube, &[("quadrature_points", "0")])
            .contains("quadrature_points")
    );
    assert!(
        eval_with(
            "cube_reduction",
            &cube,
            &[("quadrature_points", "64"), ("contact", "el")]
        )
        .is_ok()
    );
    assert!(
        message(
            "cube_reduction",
            &[AL_SS, TEST_1, &[("F_n", 40.0), ("x", 1.0)]],
            &[]
        )
        .contains("L/2")
    );
    let still = [
        ("mu", 0.2),
        ("W", 1.0),
        ("k_t", 1e4),
        ("v", 0.0),
        ("v_a", 0.0),
        ("f", 40e3),
    ];
    assert!(message("dahl_steady", &[&still], &[]).contains("no relative motion"));
    let window = [
        ("mu", 0.2),
        ("W", 1.0),
        ("k_t", 1e4),
        ("v", 0.1),
        ("v_a", 0.1),
        ("f", 40e3),
        ("Tw", 1e-3),
        ("f0", 1.5),
    ];
    assert!(message("dahl_window", &[&window], &[]).contains("`f0`"));
}

#[test]
fn every_model_has_exactly_its_documented_outputs() {
    let contact = "E_star A_r K_t d ln_KF";
    let expected = [
        ("littmann_mu_i", "mu_i".to_string()),
        (
            "coulomb_avg_friction",
            "F_avg F_novib reduction_pct v_a zeta".into(),
        ),
        ("coulomb_sampled_avg_sign", "mean_sign reduction_pct".into()),
        (
            "dahl_steady",
            "F_avg F_novib kxa ratio reduction_pct x_a zeta".into(),
        ),
        ("dahl_window", "F_avg reduction_pct".into()),
        ("dahl_delta_transient", "delta delta_ss".into()),
        ("contact_el", contact.into()),
        (
            "contact_ep",
            format!("{contact} A_e A_p A_r_over_An F_e F_p X omega_c p_c"),
        ),
        (
            "contact_ep_of_d",
            "A_e A_p A_r A_r_over_An F_e F_n F_p K_t".into(),
        ),
        (
            "cube_reduction",
            "A_r Ft0 Ft_prime K_t d delta ratio reduction_pct u_over_delta".into(),
        ),
        ("horn_kinematics", "u v".into()),
        ("B_from_A", "B".into()),
        ("exp_coulomb_law", "F_f".into()),
        ("actuator", "I V_limit v_a within_limits x_a".into()),
        ("motor_force", "F_t kappa phi v_face".into()),
    ];
    assert_eq!(expected.len(), MODELS.len());
    for (model, keys) in expected {
        let inputs = super::example_inputs(model).unwrap();
        let outputs = eval_named(model, &inputs, &BTreeMap::new()).unwrap();
        let mut want: Vec<&str> = keys.split(' ').collect();
        want.sort_unstable();
        assert_eq!(outputs.keys().copied().collect::<Vec<_>>(), want, "{model}");
        assert!(outputs.values().all(|v| v.is_finite()), "{model}");
    }
}
