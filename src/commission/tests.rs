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
    let mut result = CommissionResult {
        resonance_hz: measured(40_000.0, 1.0),
        time_constant_s: measured(0.0, 1e-6),
        quality_factor: measured(100.0, 0.2),
        natural_coefficient: measured(0.24, 1e-4),
        ring_down_points: 24,
        normal: zero,
        tangential: zero,
    };
    set_tau(&mut result);
    result
}

/// tau from f0 and Q, as the sequence relates them (`Q = pi f0 tau`).
fn set_tau(result: &mut CommissionResult) {
    result.time_constant_s.value =
        result.quality_factor.value / (core::f64::consts::PI * result.resonance_hz.value);
}

#[test]
fn values_in_their_ranges_are_accepted() {
    assert_eq!(check(&good()), Ok(()));
}

/// Sets one value of a result.
type Set = fn(&mut CommissionResult, f64);

/// Each range's edges, each with the value just inside (accepted) and just outside (refused
/// with the step and reason): (what, setter, inside, outside, step, reason).
fn edges() -> [(&'static str, Set, f64, f64, Step, &'static str); 22] {
    const F0: &str = "f0 outside the drive band 20-60 kHz";
    const Q: &str = "Q outside [5, 5000]";
    const MU0: &str = "mu0 outside (0, 2]";
    let f0: Set = |r, x| {
        r.resonance_hz.value = x;
        set_tau(r);
    };
    let q: Set = |r, x| {
        r.quality_factor.value = x;
        set_tau(r);
    };
    let mu0: Set = |r, x| r.natural_coefficient.value = x;
    let f0_se: Set = |r, x| r.resonance_hz.standard_error = x;
    let q_se: Set = |r, x| r.quality_factor.standard_error = x;
    let tau_se: Set = |r, x| r.time_constant_s.standard_error = x;
    let mu0_se: Set = |r, x| r.natural_coefficient.standard_error = x;
    let zero: Set = |r, x| r.normal.zero_n = x;
    let noise: Set = |r, x| r.tangential.noise_rms_n = Some(x);
    let tau_max = 5_000.0 / (core::f64::consts::PI * 20_000.0);
    let cell = CELL_RANGE_N;
    [
        (
            "f0 low",
            f0,
            20_000.0,
            20_000f64.next_down(),
            Step::Resonance,
            F0,
        ),
        (
            "f0 high",
            f0,
            60_000.0,
            60_000f64.next_up(),
            Step::Resonance,
            F0,
        ),
        ("f0 NaN", f0, 40_000.0, f64::NAN, Step::Resonance, F0),
        ("Q low", q, 5.0, 5f64.next_down(), Step::RingDown, Q),
        ("Q high", q, 5_000.0, 5_000f64.next_up(), Step::RingDown, Q),
        ("Q inf", q, 100.0, f64::INFINITY, Step::RingDown, Q),
        ("mu0 low", mu0, f64::MIN_POSITIVE, 0.0, Step::Natural, MU0),
        ("mu0 high", mu0, 2.0, 2f64.next_up(), Step::Natural, MU0),
        (
            "f0 se low",
            f0_se,
            0.0,
            -f64::MIN_POSITIVE,
            Step::Resonance,
            "f0 error outside [0, 40 kHz]",
        ),
        (
            "f0 se high",
            f0_se,
            40_000.0,
            40_000f64.next_up(),
            Step::Resonance,
            "f0 error outside [0, 40 kHz]",
        ),
        (
            "Q se low",
            q_se,
            0.0,
            -f64::MIN_POSITIVE,
            Step::RingDown,
            "Q error outside [0, 5000]",
        ),
        (
            "Q se high",
            q_se,
            5_000.0,
            5_000f64.next_up(),
            Step::RingDown,
            "Q error outside [0, 5000]",
        ),
        (
            "tau se low",
            tau_se,
            0.0,
            -f64::MIN_POSITIVE,
            Step::RingDown,
            "tau error outside [0, 80 ms]",
        ),
        (
            "tau se high",
            tau_se,
            tau_max,
            tau_max.next_up(),
            Step::RingDown,
            "tau error outside [0, 80 ms]",
        ),
        (
            "tau se NaN",
            tau_se,
            0.0,
            f64::NAN,
            Step::RingDown,
            "tau error outside [0, 80 ms]",
        ),
        (
            "mu0 se low",
            mu0_se,
            0.0,
            -f64::MIN_POSITIVE,
            Step::Natural,
            "mu0 error outside [0, 2]",
        ),
        (
            "mu0 se high",
            mu0_se,
            2.0,
            2f64.next_up(),
            Step::Natural,
            "mu0 error outside [0, 2]",
        ),
        (
            "zero low",
            zero,
            -cell,
            (-cell).next_down(),
            Step::Resonance,
            "normal zero outside +-32768 N",
        ),
        (
            "zero high",
            zero,
            cell,
            cell.next_up(),
            Step::Resonance,
            "normal zero outside +-32768 N",
        ),
        (
            "noise low",
            noise,
            0.0,
            -f64::MIN_POSITIVE,
            Step::Resonance,
            "tangential noise outside [0, 32768 N]",
        ),
        (
            "noise high",
            noise,
            cell,
            cell.next_up(),
            Step::Resonance,
            "tangential noise outside [0, 32768 N]",
        ),
        (
            "noise NaN",
            noise,
            0.0,
            f64::NAN,
            Step::Resonance,
            "tangential noise outside [0, 32768 N]",
        ),
    ]
}

#[test]
fn each_range_edge_is_accepted_and_the_next_value_out_refused_with_its_reason() {
    for (what, set, inside, outside, step, reason) in edges() {
        let mut result = good();
        set(&mut result, inside);
        assert_eq!(check(&result), Ok(()), "{what}: {inside} {result:?}");
        let mut result = good();
        set(&mut result, outside);
        let refusal = check(&result).expect_err(what);
        assert_eq!(
            (refusal.step, refusal.reason),
            (step, reason),
            "{what}: {result:?}"
        );
        // The refused value is reported (NaN compared by its bits).
        assert_eq!(refusal.value.to_bits(), outside.to_bits(), "{what}");
    }
}

#[test]
fn a_q_that_is_not_pi_f0_tau_and_a_short_ring_down_are_refused() {
    let mut result = good();
    result.time_constant_s.value *= 1.0 + 1e-6;
    let refusal = check(&result).expect_err("inconsistent");
    assert_eq!(
        (refusal.step, refusal.reason),
        (Step::RingDown, "Q is not pi f0 tau")
    );
    let mut result = good();
    result.ring_down_points = crate::resonance::MIN_RING_DOWN_POINTS as u32;
    assert_eq!(check(&result), Ok(()));
    result.ring_down_points -= 1;
    let refusal = check(&result).expect_err("short");
    assert_eq!(
        (refusal.step, refusal.reason),
        (Step::RingDown, "ring-down too short")
    );
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
    // (The scene takes f0 and Q; `check` needs tau to agree with them.)
    set_tau(&mut result);
    assert_eq!(check(&result), Ok(()));
}
