use super::*;
use crate::scene::find;

fn measured(value: f64, standard_error: f64) -> Measured {
    Measured {
        value,
        standard_error,
    }
}

/// The reference stack's values, each with a small error.
fn good() -> CommissionResult {
    let zero = CellZero {
        zero_n: 0.01,
        noise_rms_n: None,
    };
    CommissionResult {
        resonance_hz: measured(40_000.0, 1.0),
        time_constant_s: measured(0.796e-3, 1e-6),
        quality_factor: measured(100.0, 0.2),
        natural_coefficient: measured(0.24, 1e-4),
        ring_down_points: 24,
        normal: zero,
        tangential: zero,
    }
}

#[test]
fn values_in_their_ranges_are_accepted() {
    assert_eq!(check(&good()), Ok(()));
}

/// Puts one value of a result out of its range.
type Spoil = fn(&mut CommissionResult);

#[test]
fn each_value_outside_its_physical_range_is_refused_with_its_reason() {
    let cases: [(Spoil, Step, &str); 7] = [
        (
            |r| r.resonance_hz.value = 19_000.0,
            Step::Resonance,
            "f0 outside the drive band 20-60 kHz",
        ),
        (
            |r| r.resonance_hz.value = 61_000.0,
            Step::Resonance,
            "f0 outside the drive band 20-60 kHz",
        ),
        (
            |r| r.quality_factor.value = 4.9,
            Step::RingDown,
            "Q outside [5, 5000]",
        ),
        (
            |r| r.quality_factor.value = 5_001.0,
            Step::RingDown,
            "Q outside [5, 5000]",
        ),
        (
            |r| r.time_constant_s.standard_error = f64::NAN,
            Step::RingDown,
            "Q outside [5, 5000]",
        ),
        (
            |r| r.natural_coefficient.value = 0.0,
            Step::Natural,
            "mu0 outside (0, 2]",
        ),
        (
            |r| r.natural_coefficient.value = 2.01,
            Step::Natural,
            "mu0 outside (0, 2]",
        ),
    ];
    for (spoil, step, reason) in cases {
        let mut result = good();
        spoil(&mut result);
        let refusal = check(&result).expect_err("refused");
        assert_eq!((refusal.step, refusal.reason), (step, reason), "{result:?}");
    }
    // The edges of the ranges are physical.
    let mut edge = good();
    edge.natural_coefficient.value = 2.0;
    edge.quality_factor.value = 5.0;
    edge.resonance_hz.value = 60_000.0;
    assert_eq!(check(&edge), Ok(()));
}

#[test]
fn a_commissioned_scene_takes_the_measured_resonance_q_and_mu0_and_keeps_its_plant() {
    let scene = find("resonance-search").expect("built in");
    let mut result = good();
    result.resonance_hz.value = 40_010.0;
    result.quality_factor.value = 90.0;
    let commissioned = commissioned_scene(scene, &result);
    assert_eq!(commissioned.transducer.resonance_hz, 40_010.0);
    assert_eq!(commissioned.transducer.drive_hz, 40_010.0);
    assert_eq!(commissioned.transducer.quality_factor, 90.0);
    assert!(!commissioned.transducer.shift.freq_auto);
    assert!((commissioned.controller.mu - 0.24).abs() < 1e-15);
    assert_eq!(commissioned.plant, scene.plant);
    assert_eq!(commissioned.normal_cell, scene.normal_cell);
    // The envelope time constant the controller settings take is the measured one.
    let tau = commissioned.transducer.envelope_time_constant_s();
    assert!((tau - 90.0 / (core::f64::consts::PI * 40_010.0)).abs() < 1e-15);
}
