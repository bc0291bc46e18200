//! Unit tests of the cube model against paper numbers (physics-notes §4) and an independent
//! brute-force f64 evaluation of seed 000 eq 15 written here from the equations.

use super::*;
use crate::model::contact::ln_load_from_si;

/// Seed 000 Table 1 test 1 at the node (mu = 0.54, A = 11.46 um, B = 1.1 um, 20 kHz).
pub(crate) fn test_1(position: f64) -> CubeParams {
    CubeParams {
        contact: ContactParams::SEED_000_TABLE_2_AL_ON_SS,
        friction_coefficient: 0.54,
        longitudinal_amplitude: 11.46e-6,
        vertical_amplitude: 1.1e-6,
        position,
        horn_length: 0.127,
        frequency: 20e3,
    }
}

fn ratio(params: &CubeParams, options: &CubeOptions, load: f64) -> Sat<Q8_24> {
    let scene = CubeScene::new(params, options).unwrap();
    let point = scene.prepare(ln_load_from_si(load).unwrap()).unwrap();
    scene.evaluate(&point, Q2_30::ONE).unwrap()
}

/// Seed 000 eq 15 over eq 11 by a 20000-point midpoint sum in f64, with d and A_r from the
/// scene's f64 constants: (1/|W|) int_W e^(-2 lambda v/R_q) (d/(d+v))^3 (1 + u/delta) dtheta.
fn brute_force(params: &CubeParams, options: &CubeOptions, load: f64) -> f64 {
    let scene = CubeScene::new(params, options).unwrap();
    let s = *scene.contact().scene();
    let d = s.roughness_rq / s.distribution_lambda * (s.ln_force_constant - load.ln());
    let area = load / s.mean_pressure;
    let stiffness = s.e_star * area * area / (d * d * d);
    let delta = params.friction_coefficient * load / stiffness;
    let shape = PI * params.position / params.horn_length;
    let (big_v, big_u) = (
        params.vertical_amplitude * shape.cos(),
        params.longitudinal_amplitude * shape.sin(),
    );
    let (start, end) = match options.window {
        SlipWindow::SurfacesApart => (-0.5 * PI, 0.5 * PI),
        SlipWindow::LiteralCos => (0.0, PI),
    };
    let n = 20_000;
    let mut sum = 0.0;
    for i in 0..n {
        let theta = start + (end - start) * (i as f64 + 0.5) / n as f64;
        let v = big_v * theta.cos();
        let time = match options.u_phase {
            UPhase::InPhase => theta.cos(),
            UPhase::Quadrature => theta.sin(),
        };
        let g = (-2.0 * s.distribution_lambda * v / s.roughness_rq).exp() * (d / (d + v)).powi(3);
        sum += g * (1.0 + big_u * time / delta);
    }
    sum / n as f64
}

#[test]
fn seed000_cube_reductions_at_the_node() {
    // physics-notes §4: 51.94 % (40 N) and 52.97 % (240 N) for test 1, about flat with load;
    // the literal cos window increases friction by 46.0 % at 40 N.
    let o = CubeOptions::default();
    let pct = |load: f64, options: &CubeOptions| {
        100.0 * (1.0 - ratio(&test_1(0.0), options, load).value.to_f64())
    };
    assert!(
        (pct(40.0, &o) - 51.937_745).abs() < 1e-3,
        "{}",
        pct(40.0, &o)
    );
    assert!(
        (pct(240.0, &o) - 52.968_936).abs() < 1e-3,
        "{}",
        pct(240.0, &o)
    );
    let literal = CubeOptions {
        window: SlipWindow::LiteralCos,
        ..o
    };
    assert!(
        (pct(40.0, &literal) + 46.005_609).abs() < 1e-3,
        "{}",
        pct(40.0, &literal)
    );
}

#[test]
fn agrees_with_brute_force_on_and_off_the_node() {
    let cases: &[(f64, f64, UPhase, SlipWindow)] = &[
        (0.0, 1e-3, UPhase::InPhase, SlipWindow::SurfacesApart),
        (0.0, 40.0, UPhase::InPhase, SlipWindow::SurfacesApart),
        (0.0, 5e4, UPhase::InPhase, SlipWindow::SurfacesApart),
        (2e-9, 40.0, UPhase::InPhase, SlipWindow::SurfacesApart),
        (-2e-9, 40.0, UPhase::InPhase, SlipWindow::SurfacesApart),
        (0.01, 240.0, UPhase::Quadrature, SlipWindow::SurfacesApart),
        (0.0, 140.0, UPhase::InPhase, SlipWindow::LiteralCos),
        (1e-8, 140.0, UPhase::Quadrature, SlipWindow::LiteralCos),
    ];
    for &(x, load, u_phase, window) in cases {
        let options = CubeOptions {
            u_phase,
            window,
            ..CubeOptions::default()
        };
        let got = ratio(&test_1(x), &options, load);
        let want = brute_force(&test_1(x), &options, load);
        assert!(!got.saturated);
        let err = (got.value.to_f64() - want).abs();
        assert!(
            err < 2e-6 * want.abs().max(1.0),
            "x {x} F {load}: {} vs {want}",
            got.value
        );
    }
}

#[test]
fn frequency_never_enters_and_zero_amplitude_is_exactly_one() {
    let o = CubeOptions::default();
    let at = |f: f64| {
        ratio(
            &CubeParams {
                frequency: f,
                ..test_1(1e-9)
            },
            &o,
            140.0,
        )
    };
    assert_eq!(at(20e3), at(60e3));
    let scene = CubeScene::new(&test_1(0.01), &o).unwrap();
    let point = scene.prepare(ln_load_from_si(40.0).unwrap()).unwrap();
    assert_eq!(
        scene.evaluate(&point, Q2_30::ZERO).unwrap(),
        Sat::exact(Q8_24::ONE)
    );
}

#[test]
fn quadrature_phase_u_cancels_in_the_default_window() {
    // Odd integrand on the symmetric window: identical to the same scene without u (A = 0).
    let o = CubeOptions {
        u_phase: UPhase::Quadrature,
        ..CubeOptions::default()
    };
    let with_u = ratio(&test_1(0.02), &o, 100.0);
    let without = ratio(
        &CubeParams {
            longitudinal_amplitude: 0.0,
            ..test_1(0.02)
        },
        &o,
        100.0,
    );
    assert_eq!(with_u, without);
}

#[test]
fn ratio_falls_with_amplitude_at_the_node() {
    let scene = CubeScene::new(&test_1(0.0), &CubeOptions::default()).unwrap();
    for load in [1e-3, 1.0, 40.0, 1e4] {
        let point = scene.prepare(ln_load_from_si(load).unwrap()).unwrap();
        let mut previous = Q8_24::MAX;
        for step in 0..=64 {
            let a = Q2_30::from_bits(((1i64 << 30) * step / 64) as i32);
            let r = scene.evaluate(&point, a).unwrap();
            assert!(!r.saturated && r.value <= previous && r.value > Q8_24::ZERO);
            previous = r.value;
        }
    }
}

#[test]
fn off_node_saturates_with_a_flag_and_guards_are_typed() {
    let o = CubeOptions::default();
    // u/delta ~ 1e8 at x = 3 cm: F'/F far above 128, flagged, not wrapped.
    let far = ratio(&test_1(0.03), &o, 240.0);
    assert_eq!(far, Sat::clamped(Q8_24::MAX));
    let below = ratio(&test_1(-0.03), &o, 240.0);
    assert_eq!(below, Sat::clamped(Q8_24::MIN));
    let scene = CubeScene::new(&test_1(0.0), &o).unwrap();
    let point = scene.prepare(ln_load_from_si(40.0).unwrap()).unwrap();
    assert!(scene.evaluate(&point, Q2_30::from_bits(-1)).is_err());
    assert!(
        scene
            .evaluate(&point, Q2_30::from_bits((1 << 30) + 1))
            .is_err()
    );
    assert!(scene.ratio_q2_30(&point, Q2_30::ONE).is_ok());
    let far_scene = CubeScene::new(&test_1(0.03), &o).unwrap();
    let far_point = far_scene.prepare(ln_load_from_si(240.0).unwrap()).unwrap();
    assert!(far_scene.ratio_q2_30(&far_point, Q2_30::ONE).is_err());
    // Literal window with B >= d: interpenetration.
    let literal = CubeOptions {
        window: SlipWindow::LiteralCos,
        ..o
    };
    let deep = CubeParams {
        vertical_amplitude: 20e-6,
        ..test_1(0.0)
    };
    let s = CubeScene::new(&deep, &literal).unwrap();
    let p = s.prepare(ln_load_from_si(40.0).unwrap()).unwrap();
    assert!(matches!(
        s.evaluate(&p, Q2_30::ONE),
        Err(ModelError::OutOfDomain { input: "B", .. })
    ));
    // Bad scene inputs.
    let bad = |p: CubeParams| CubeScene::new(&p, &o).is_err();
    assert!(bad(CubeParams {
        friction_coefficient: 0.0,
        ..test_1(0.0)
    }));
    assert!(bad(CubeParams {
        frequency: f64::NAN,
        ..test_1(0.0)
    }));
    assert!(bad(CubeParams {
        vertical_amplitude: 1e-3,
        ..test_1(0.0)
    }));
    assert!(bad(test_1(0.07)));
    assert!(
        CubeScene::new(
            &test_1(0.0),
            &CubeOptions {
                quadrature_points: 0,
                ..o
            }
        )
        .is_err()
    );
    assert!(scene.prepare(ln_load_from_si(1e5).unwrap()).is_err());
}
