//! Unit tests of the motor model against closed forms (the f64 reference of host-tests checks
//! it everywhere else): phi = -sgn(x) L0(k) / I0(k) for a held block with the elliptical locus.

use super::horn::{HornShape, UPhase};
use super::motor::{
    ALUMINIUM_HORN_REGIONS, MAX_DECAY, MotorParams, MotorPoint, MotorScene, STAINLESS_HORN_REGIONS,
};
use crate::fx::{Q1_31, Q8_24, Q16_16};

/// Seed 000 Table 1 test 1 (Al horn, SS block) and Table 2; mu 0.55 (seed 001 §3.3).
fn seed_params() -> MotorParams {
    MotorParams::SEED_001_AL_HORN_SS_BLOCK
}

/// I0(k) and L0(k) by their power series (k <= 16: 80 terms are far past convergence).
fn bessel_i0_struve_l0(k: f64) -> (f64, f64) {
    let (mut i0, mut term_i) = (1.0, 1.0);
    let half = 0.5 * k;
    let mut l0 = 0.0;
    // L0(k) = sum_m (k/2)^(2m+1) / Gamma(m + 3/2)^2
    let mut term_l = half / (0.25 * core::f64::consts::PI); // Gamma(3/2)^2 = pi / 4
    for m in 0..80 {
        if m > 0 {
            term_i *= half * half / (m as f64 * m as f64);
            i0 += term_i;
            let g = m as f64 + 0.5;
            term_l *= half * half / (g * g);
        }
        l0 += term_l;
    }
    (i0, l0)
}

fn point(x: f64, load: f64, velocity: f64) -> MotorPoint {
    MotorPoint {
        shape: HornShape::new(x, 0.127).unwrap(),
        normal_force: Q16_16::from_f64(load).unwrap(),
        block_velocity: Q8_24::from_f64(velocity).unwrap(),
    }
}

#[test]
fn held_block_is_driven_towards_the_centreline_by_l0_over_i0() {
    let scene = MotorScene::new(&seed_params(), UPhase::Quadrature).unwrap();
    for &x in &[
        -0.0381, -0.0254, -0.01, -0.002, 0.002, 0.00635, 0.0254, 0.0381,
    ] {
        let k = 3.0 * 1.1 / 6.0 * (core::f64::consts::PI * x / 0.127).cos();
        let (i0, l0) = bessel_i0_struve_l0(k);
        let want = -x.signum() * l0 / i0;
        let out = scene.force(&point(x, 100.0, 0.0), Q1_31::MAX).unwrap();
        let phi = out.drive_ratio.to_f64();
        assert!((phi - want).abs() < 2e-7, "x {x}: {phi} vs {want}");
        assert!(phi * x < 0.0, "towards the centreline at x {x}");
        assert!((out.force.to_f64() - want * 0.55 * 100.0).abs() < 1e-4);
    }
    // At the horn's end the face moves only along x (cos(pi x/L) = 0): a straight stroke again.
    let end = scene.force(&point(0.0635, 100.0, 0.0), Q1_31::MAX).unwrap();
    assert!(end.drive_ratio.to_f64().abs() < 1e-8);
}

#[test]
fn closed_form_holds_up_to_the_largest_accepted_decay() {
    for &b in &[0.0, 0.3e-6, 4e-6, 10e-6, MAX_DECAY * 2e-6] {
        let params = MotorParams {
            vertical_amplitude: b,
            ..seed_params()
        };
        let scene = MotorScene::new(&params, UPhase::Quadrature).unwrap();
        let x = 0.02;
        let k = 3.0 * b / 6e-6 * (core::f64::consts::PI * x / 0.127).cos();
        let (i0, l0) = bessel_i0_struve_l0(k);
        let phi = scene
            .force(&point(x, 50.0, 0.0), Q1_31::MAX)
            .unwrap()
            .drive_ratio
            .to_f64();
        assert!((phi + l0 / i0).abs() < 1e-6, "B {b}: {phi} vs {}", -l0 / i0);
    }
    let beyond = MotorParams {
        vertical_amplitude: 2.01e-6 * MAX_DECAY,
        ..seed_params()
    };
    assert!(MotorScene::new(&beyond, UPhase::Quadrature).is_err());
}

#[test]
fn no_tangential_motion_gives_no_drive() {
    let scene = MotorScene::new(&seed_params(), UPhase::Quadrature).unwrap();
    // At the node, and at zero amplitude: nothing on a held block, plain friction on a slider.
    for (x, amplitude) in [(0.0, Q1_31::MAX), (0.03, Q1_31::ZERO)] {
        let held = scene.force(&point(x, 120.0, 0.0), amplitude).unwrap();
        assert_eq!(held.force, Q16_16::ZERO);
        let sliding = scene.force(&point(x, 120.0, 0.005), amplitude).unwrap();
        assert_eq!(sliding.drive_ratio.to_f64(), -1.0);
        assert!((sliding.force.to_f64() + 0.55 * 120.0).abs() < 1e-4);
    }
}

#[test]
fn straight_stroke_of_eqs_16_17_drives_nothing() {
    let scene = MotorScene::new(&seed_params(), UPhase::InPhase).unwrap();
    for &x in &[-0.03, -0.01, 0.01, 0.03] {
        let phi = scene
            .force(&point(x, 100.0, 0.0), Q1_31::MAX)
            .unwrap()
            .drive_ratio
            .to_f64();
        assert!(phi.abs() < 1e-8, "x {x}: {phi}");
    }
}

#[test]
fn force_is_linear_in_the_load_and_unloaded_surfaces_exert_nothing() {
    let scene = MotorScene::new(&seed_params(), UPhase::Quadrature).unwrap();
    let at = |load: f64| {
        scene
            .force(&point(-0.0254, load, 0.0), Q1_31::MAX)
            .unwrap()
            .force
            .to_f64()
    };
    assert_eq!(at(0.0), 0.0); // apart over the whole cycle
    let slope = at(60.0) / 60.0;
    for load in [60.0, 120.0, 180.0, 240.0] {
        assert!((at(load) - slope * load).abs() < 2e-4, "{load}");
    }
    assert!(slope > 0.0, "at -1 in the block is pushed towards +x");
    let negative = MotorPoint {
        normal_force: Q16_16::from_f64(-1.0).unwrap(),
        ..point(0.01, 1.0, 0.0)
    };
    assert!(scene.force(&negative, Q1_31::MAX).is_err());
    // |F_t| would exceed Q16.16: reported, never wrapped (mu 1.9, 30000 N, away from the node
    // with the block outrunning the face: |F_t| = 57000 N).
    let grippy = MotorScene::new(
        &MotorParams {
            friction_coefficient: 1.9,
            ..seed_params()
        },
        UPhase::Quadrature,
    )
    .unwrap();
    assert!(grippy.force(&point(0.0, 30000.0, 1.0), Q1_31::MAX).is_err());
}

#[test]
fn a_block_faster_than_the_face_feels_plain_friction() {
    let scene = MotorScene::new(&seed_params(), UPhase::Quadrature).unwrap();
    // Face speed at x: A omega sin(pi x / L) = 1.44 m/s * 0.0247 = 35.6 mm/s at 1 mm.
    let x = 0.001;
    let face =
        11.46e-6 * 2.0 * core::f64::consts::PI * 20e3 * (core::f64::consts::PI * x / 0.127).sin();
    let faster = scene
        .force(&point(x, 100.0, 1.01 * face), Q1_31::MAX)
        .unwrap();
    assert_eq!(faster.drive_ratio.to_f64(), -1.0);
    let slower = scene
        .force(&point(x, 100.0, 0.5 * face), Q1_31::MAX)
        .unwrap();
    assert!(slower.drive_ratio.to_f64() > -1.0);
}

#[test]
fn table_1_regions_in_metres() {
    assert!(ALUMINIUM_HORN_REGIONS.in_transition(0.0));
    assert!(ALUMINIUM_HORN_REGIONS.in_transition(0.00635));
    assert!(!ALUMINIUM_HORN_REGIONS.in_transition(0.0064));
    assert!(!STAINLESS_HORN_REGIONS.in_transition(0.0));
    assert!(STAINLESS_HORN_REGIONS.in_transition(0.003));
    assert!((ALUMINIUM_HORN_REGIONS.motor_outer.1 - 0.0381).abs() < 1e-12);
}

#[test]
fn bad_scene_inputs_are_reported() {
    let bad = [
        MotorParams {
            friction_coefficient: 0.0,
            ..seed_params()
        },
        MotorParams {
            friction_coefficient: 2.5,
            ..seed_params()
        },
        MotorParams {
            longitudinal_amplitude: -1e-6,
            ..seed_params()
        },
        MotorParams {
            roughness_rq: f64::NAN,
            ..seed_params()
        },
        MotorParams {
            longitudinal_amplitude: 2e-3, // 251 m/s face speed
            ..seed_params()
        },
    ];
    for params in bad {
        assert!(
            MotorScene::new(&params, UPhase::Quadrature).is_err(),
            "{params:?}"
        );
    }
}

#[test]
fn model_choice_follows_table_1() {
    use super::motor::HornRegion;
    let al = ALUMINIUM_HORN_REGIONS;
    assert_eq!(al.region(0.0).unwrap(), HornRegion::Transition);
    assert_eq!(al.region(-0.006).unwrap(), HornRegion::Transition);
    assert_eq!(al.region(-0.0254).unwrap(), HornRegion::Motor);
    assert_eq!(al.region(0.007).unwrap(), HornRegion::Motor);
    assert_eq!(al.region(0.05).unwrap(), HornRegion::BeyondMeasured);
    // The stainless horn's transition region is off centre: the centre itself is a motor point.
    assert_eq!(
        STAINLESS_HORN_REGIONS.region(0.0).unwrap(),
        HornRegion::Motor
    );
    assert!(al.region(f64::NAN).is_err());
}

#[test]
fn holding_a_block_against_an_external_load() {
    use super::Reach;
    let scene = MotorScene::new(&seed_params(), UPhase::Quadrature).unwrap();
    // Block held at -1 in (seed 001 Fig. 4a) under 120 N, pulled outwards (-x) by 10 N: the
    // drive must push +10 N towards the centre for a net force of zero.
    let held = point(-0.0254, 120.0, 0.0);
    let external = 10.0;
    let out = scene
        .amplitude_for_force(&held, Q16_16::from_f64(-(-external)).unwrap())
        .unwrap();
    assert_eq!(out.reach, Reach::Reached);
    let net = out.force.force.to_f64() - external;
    assert!(net.abs() < 2e-3, "net {net}");
    // The amplitude found is the model's: the force there, recomputed, is the same.
    let again = scene.force(&held, out.amplitude).unwrap();
    assert_eq!(again, out.force);
    // More than the full-amplitude motor force (18.2 N): full drive, flagged.
    let too_much = scene
        .amplitude_for_force(&held, Q16_16::from_f64(25.0).unwrap())
        .unwrap();
    assert_eq!(too_much.reach, Reach::BelowMinimum);
    assert_eq!(too_much.amplitude, Q1_31::MAX);
    // A pull towards the outside would need the drive to push away from the centre: the
    // vibration cannot, amplitude 0 (no vibration: the external load meets static friction).
    let outward = scene
        .amplitude_for_force(&held, Q16_16::from_f64(-5.0).unwrap())
        .unwrap();
    assert_eq!(outward.reach, Reach::AboveNatural);
    assert_eq!(outward.amplitude, Q1_31::ZERO);
    // A block moving away from the centre: answered on the motor's rising branch, above
    // the least force (about 4.3 N at 120 N and 5 mm/s, near a tenth of full drive:
    // `sonolube eval motor_force ... v_b=-0.005`), with the branch's foot for a target below.
    let away = point(-0.0254, 120.0, -0.005);
    let rising = scene
        .amplitude_for_force(&away, Q16_16::from_f64(14.0).unwrap())
        .unwrap();
    assert_eq!(rising.reach, Reach::Reached);
    assert!((rising.force.force.to_f64() - 14.0).abs() < 2e-3);
    let least = scene
        .amplitude_for_force(&away, Q16_16::from_f64(3.0).unwrap())
        .unwrap();
    assert_eq!(least.reach, Reach::AboveNatural);
    assert!(least.amplitude < rising.amplitude);
    // The foot is the least force over a dense scan, and the force rises beyond it.
    let at = |bits: i64| {
        scene
            .force(&away, Q1_31::from_bits(bits as i32))
            .unwrap()
            .force
            .to_f64()
    };
    let max = Q1_31::MAX.to_bits() as i64;
    let foot = least.amplitude.to_bits() as i64;
    let scan_min = (0..=512)
        .map(|k| at(k * max / 512))
        .fold(f64::INFINITY, f64::min);
    assert!(
        least.force.force.to_f64() <= scan_min + 2e-3,
        "foot {} vs scan {scan_min}",
        least.force.force.to_f64()
    );
    let mut last = least.force.force.to_f64();
    for k in 1..=64 {
        let f = at(foot + (max - foot) * k / 64);
        assert!(f >= last - 1e-4, "not rising beyond the foot at {k}");
        last = f;
    }
    // Moving towards the centre at 5 mm/s: monotone, reachable.
    let inward = scene
        .amplitude_for_force(
            &point(-0.0254, 120.0, 0.005),
            Q16_16::from_f64(10.0).unwrap(),
        )
        .unwrap();
    assert_eq!(inward.reach, Reach::Reached);
    assert!((inward.force.force.to_f64() - 10.0).abs() < 2e-3);
}

#[test]
fn force_towards_the_centre_grows_with_the_amplitude() {
    let scene = MotorScene::new(&seed_params(), UPhase::Quadrature).unwrap();
    for (x, v_b) in [
        (-0.0254, 0.0),
        (0.0254, 0.0),
        (-0.0254, 0.005),
        (0.01, -0.005),
    ] {
        let p = point(x, 120.0, v_b);
        let mut last = f64::NEG_INFINITY;
        for step in 0..=64 {
            let a = Q1_31::from_bits(((step as i64 * Q1_31::MAX.to_bits() as i64) / 64) as i32);
            let towards = -x.signum() * scene.force(&p, a).unwrap().force.to_f64();
            assert!(towards >= last - 1e-4, "x {x} v {v_b} step {step}");
            last = towards;
        }
    }
}
