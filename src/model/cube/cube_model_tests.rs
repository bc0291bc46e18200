//! Unit tests of the cube model as a `FrictionModel`: ratio, Newton inversion vs bisection.

use super::*;
use crate::fx::{Q8_24, Q16_16};
use crate::model::cube::tests::test_1;

fn model(position: f64) -> CubeModel {
    CubeModel::new(&test_1(position), &CubeOptions::default()).unwrap()
}

fn point(load: i32) -> OperatingPoint {
    OperatingPoint {
        normal_force: Q16_16::from_int(load).unwrap(),
        sliding_velocity: Q8_24::from_f64(0.005).unwrap(),
    }
}

#[test]
fn ratio_at_full_scale_is_the_paper_reduction() {
    let r = model(0.0).ratio(&point(40), Q1_31::MAX).unwrap();
    assert!((r.to_f64() - (1.0 - 0.519_377_45)).abs() < 1e-5, "{r:?}");
    assert_eq!(model(0.0).ratio(&point(40), Q1_31::ZERO), Ok(Q2_30::ONE));
    let zero_load = OperatingPoint {
        normal_force: Q16_16::ZERO,
        ..point(1)
    };
    assert!(model(0.0).ratio(&zero_load, Q1_31::MAX).is_err());
}

#[test]
fn newton_inversion_agrees_with_bisection() {
    let m = model(0.0);
    for load in [1, 40, 240, 20_000] {
        let p = point(load);
        for target in [0.49, 0.5, 0.6, 0.75, 0.9, 0.99, 0.999_9] {
            let target = Q2_30::from_f64(target).unwrap();
            let newton = m.invert(&p, target).unwrap();
            let bisection = invert(&m, &p, target, 24).unwrap();
            assert_eq!(newton.reach, bisection.reach, "{load} N, {target:?}");
            // The returned ratio is the model's at the returned amplitude.
            assert_eq!(m.ratio(&p, newton.amplitude), Ok(newton.ratio));
            if newton.reach == Reach::Reached {
                assert!((newton.ratio.to_f64() - target.to_f64()).abs() <= 2.4e-7);
                let gap = (newton.amplitude.to_f64() - bisection.amplitude.to_f64()).abs();
                assert!(
                    gap < 1e-6,
                    "{load} N, {target:?}: {newton:?} vs {bisection:?}"
                );
            }
        }
    }
}

#[test]
fn inversion_limits_and_warm_start() {
    let m = model(0.0);
    let p = point(40);
    let natural = m.invert(&p, Q2_30::ONE).unwrap();
    assert_eq!(
        (natural.reach, natural.amplitude),
        (Reach::AboveNatural, Q1_31::ZERO)
    );
    let floor = m.invert(&p, Q2_30::from_f64(0.3).unwrap()).unwrap();
    assert_eq!(
        (floor.reach, floor.amplitude),
        (Reach::BelowMinimum, Q1_31::MAX)
    );
    assert_eq!(Ok(floor.ratio), m.ratio(&p, Q1_31::MAX));
    let target = Q2_30::from_f64(0.7).unwrap();
    let cold = m.invert(&p, target).unwrap();
    for start in [0.0, 0.2, 0.9, 0.999] {
        let warm = m
            .invert_from(&p, target, Q1_31::from_f64(start).unwrap())
            .unwrap();
        assert!((warm.amplitude.to_f64() - cold.amplitude.to_f64()).abs() < 1e-7);
    }
}

#[test]
fn scenes_with_an_active_u_term_fall_back_to_bisection() {
    // 1 nm from the node the u-term is small but present: the default bisection answers.
    let m = model(1e-9);
    let p = point(40);
    let target = Q2_30::from_f64(0.7).unwrap();
    assert_eq!(
        m.invert(&p, target),
        invert(&m, &p, target, BISECTION_STEPS)
    );
}

/// A horn that does not vibrate (A = B = 0, allowed by `CubeParams`) leaves the friction at
/// its natural value at every amplitude: W0 = 1 and its slope is 0 everywhere. A target below
/// 1 is then out of reach: the inversion reports it at full scale, as the bisection does,
/// instead of taking a Newton step through the zero slope.
#[test]
fn a_horn_that_does_not_vibrate_cannot_reduce_friction() {
    let still = CubeParams {
        longitudinal_amplitude: 0.0,
        vertical_amplitude: 0.0,
        ..test_1(0.0)
    };
    let m = CubeModel::new(&still, &CubeOptions::default()).unwrap();
    let p = point(40);
    assert_eq!(m.ratio(&p, Q1_31::MAX), Ok(Q2_30::ONE));
    for target in [0.5, 0.9, 0.999] {
        let target = Q2_30::from_f64(target).unwrap();
        let inversion = m.invert(&p, target).unwrap();
        assert_eq!(
            (inversion.reach, inversion.amplitude, inversion.ratio),
            (Reach::BelowMinimum, Q1_31::MAX, Q2_30::ONE),
            "{target:?}"
        );
        assert_eq!(inversion.reach, invert(&m, &p, target, 24).unwrap().reach);
    }
}
