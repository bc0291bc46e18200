//! The judge on hand-made observations: each criterion's measured value and verdict.

use super::*;
use crate::quantity::{Judged, Quantity};
use sonolube::scene::{Channel, FaultEvent, FaultKind, Rail, find};

const PERIOD_S: f32 = 1e-4;

fn scene_with<'a>(criteria: &'a [Criterion], faults: &'a [FaultEvent]) -> Scene<'a> {
    Scene {
        criteria,
        faults,
        ..*find("reference").expect("built in")
    }
}

/// The natural friction of the hand-made observations, N: a ratio target `r` asks for `r` x it.
const NATURAL_N: f32 = 2.0;

fn observe(judge: &mut Judge, step: u32, target: f32, actual: f32, target_step: bool) {
    judge.observe(&Observation {
        step,
        time_s: step as f32 * PERIOD_S,
        judged: Some(Judged {
            quantity: Quantity::Ratio,
            target,
            actual,
        }),
        friction_n: Some((target * NATURAL_N, actual * NATURAL_N)),
        target_step,
        at_limit: false,
        load_ramping: false,
        state: SupervisorState::Running,
        drive_zero: false,
    });
}

const STEP_CRITERIA: [Criterion; 3] = [
    Criterion::Settle {
        band_pct: 2.0,
        within_s: 0.003,
    },
    Criterion::Overshoot { max_pct: 5.0 },
    Criterion::Settle {
        band_pct: 10.0,
        within_s: 0.0005,
    },
];

#[test]
fn a_step_is_judged_for_settling_and_overshoot() {
    let scene = scene_with(&STEP_CRITERIA, &[]);
    let mut judge = Judge::new(&scene).expect("fits");
    for step in 1..=10 {
        observe(&mut judge, step, 1.0, 1.0, false);
    }
    // Step to 0.5 at step 11 (1.1 ms); the response dips to 0.46 (8 % of the 0.5 step), is
    // inside +-10 % from step 14 (0.3 ms after the step) and inside +-2 % from step 16 (0.5 ms).
    let response = [1.0, 0.8, 0.6, 0.46, 0.47, 0.495, 0.5, 0.5, 0.505, 0.5];
    for (k, actual) in response.iter().enumerate() {
        observe(&mut judge, 11 + k as u32, 0.5, *actual, k == 0);
    }
    let summary = judge.summary();
    assert_eq!(summary.steps, 20);
    assert_eq!(summary.segments.len(), 2);
    assert_eq!(summary.segments[0].origin, Origin::Start);
    let step = summary.segments[1];
    assert_eq!(step.origin, Origin::Step);
    assert!((step.metrics.start_s - 0.0011).abs() < 1e-7, "{step:?}");
    let v = &summary.verdicts;
    assert!(matches!(v[0].measured, Measured::Seconds(s) if (s - 0.0005).abs() < 1e-7));
    assert!(v[0].passed);
    assert!(matches!(v[1].measured, Measured::Percent(p) if (p - 8.0).abs() < 1e-3));
    assert!(!v[1].passed);
    // +-10 %: 0.46 and 0.47 are inside; 0.5 ms allowed.
    assert!(matches!(v[2].measured, Measured::Seconds(s) if (s - 0.0003).abs() < 1e-7));
    assert!(v[2].passed);
    assert!(!summary.passed());
}

#[test]
fn a_step_to_another_kind_of_target_is_judged_for_overshoot_in_newtons() {
    let scene = scene_with(&STEP_CRITERIA, &[]);
    let mut judge = Judge::new(&scene).expect("fits");
    // Natural friction held (ratio 1, 2 N at a 4 N load), then a coefficient target of 0.25
    // (1 N): a 1 N step down. The friction dips to 0.94 N, 6 % of the step past the target.
    for step in 1..=10 {
        observe(&mut judge, step, 1.0, 1.0, false);
    }
    let load_n = 4.0;
    let response = [2.0, 1.5, 1.1, 0.94, 0.97, 1.0, 1.0, 1.005, 1.0, 1.0];
    for (k, actual_n) in response.iter().enumerate() {
        judge.observe(&Observation {
            step: 11 + k as u32,
            time_s: (11 + k) as f32 * PERIOD_S,
            judged: Some(Judged {
                quantity: Quantity::Coefficient,
                target: 0.25,
                actual: actual_n / load_n,
            }),
            friction_n: Some((1.0, *actual_n)),
            target_step: k == 0,
            at_limit: false,
            load_ramping: false,
            state: SupervisorState::Running,
            drive_zero: false,
        });
    }
    let summary = judge.summary();
    let step = summary.segments[1];
    assert!(!step.same_quantity);
    assert!((step.metrics.overshoot_pct - 6.0).abs() < 1e-3, "{step:?}");
    assert!(
        matches!(summary.verdicts[1].measured, Measured::Percent(p) if (p - 6.0).abs() < 1e-3),
        "{:?}",
        summary.verdicts[1]
    );
    assert!(!summary.verdicts[1].passed);
}

#[test]
fn a_run_without_a_step_or_still_moving_at_the_end_fails_its_step_criteria() {
    let scene = scene_with(&STEP_CRITERIA, &[]);
    let mut quiet = Judge::new(&scene).expect("fits");
    for step in 1..=30 {
        observe(&mut quiet, step, 0.5, 0.5, false);
    }
    let summary = quiet.summary();
    assert!(
        summary
            .verdicts
            .iter()
            .all(|v| v.measured == Measured::Nothing)
    );
    assert!(!summary.passed());
    let mut late = Judge::new(&scene).expect("fits");
    observe(&mut late, 1, 1.0, 1.0, false);
    for step in 2..=30 {
        observe(&mut late, step, 0.5, 0.7, step == 2);
    }
    assert_eq!(late.summary().verdicts[0].measured, Measured::Never);
}

#[test]
fn ramp_increments_are_neither_stored_nor_judged_as_steps() {
    let scene = scene_with(&STEP_CRITERIA, &[]);
    let mut judge = Judge::new(&scene).expect("fits");
    observe(&mut judge, 1, 1.0, 1.0, false);
    // A ramp of the target from 1.0 down to 0.9, the plant lagging 0.05 behind.
    for k in 1..=10 {
        let target = 1.0 - 0.01 * k as f32;
        observe(&mut judge, 1 + k, target, target + 0.05, false);
    }
    let summary = judge.summary();
    assert_eq!(summary.segments.len(), 1);
    assert!(
        summary
            .verdicts
            .iter()
            .all(|v| v.measured == Measured::Nothing)
    );
}

#[test]
fn windows_give_the_rms_and_the_largest_error_and_refuse_undefined_values() {
    let criteria = [
        Criterion::SteadyRmsError {
            max_pct: 1.5,
            from_s: 0.001,
            to_s: 0.002,
        },
        Criterion::TrackingError {
            max_pct: 2.5,
            from_s: 0.001,
            to_s: 0.002,
        },
        Criterion::TrackingError {
            max_pct: 50.0,
            from_s: 0.0025,
            to_s: 0.003,
        },
    ];
    let scene = scene_with(&criteria, &[]);
    let mut judge = Judge::new(&scene).expect("fits");
    for step in 1..=30 {
        // +-1 % alternating, with one 3 % sample at 1.5 ms; undefined after 2.5 ms.
        let error = match step {
            15 => 0.03,
            s if s >= 25 => f32::NAN,
            s if s % 2 == 0 => 0.01,
            _ => -0.01,
        };
        observe(&mut judge, step, 0.5, 0.5 * (1.0 + error), false);
    }
    let v = judge.summary().verdicts;
    // 11 samples (1.0 to 2.0 ms): ten of 1 % and one of 3 %.
    let rms = 100.0 * ((10.0 * 1e-4 + 9e-4) / 11.0f32).sqrt();
    assert!(matches!(v[0].measured, Measured::Percent(p) if (p - rms).abs() < 1e-3));
    assert!(v[0].passed);
    assert!(matches!(v[1].measured, Measured::Percent(p) if (p - 3.0).abs() < 1e-3));
    assert!(!v[1].passed);
    assert_eq!(v[2].measured, Measured::Undefined);
    assert!(!v[2].passed);
}

#[test]
fn a_fault_is_timed_from_its_onset_sample_to_fault_with_zero_drive() {
    let criteria = [
        Criterion::FaultReaction { within_periods: 1 },
        Criterion::FaultReaction { within_periods: 3 },
    ];
    let faults = [FaultEvent {
        // On the grid: the sample of step 5.
        at_s: 0.0005,
        channel: Channel::Tangential,
        kind: FaultKind::Disconnected { rail: Rail::High },
        duration_s: None,
    }];
    let scene = scene_with(&criteria, &faults);
    let run = |react_at: Option<u32>| {
        let mut judge = Judge::new(&scene).expect("fits");
        for step in 1..=10 {
            let faulted = react_at.is_some_and(|at| step >= at);
            judge.observe(&Observation {
                step,
                time_s: step as f32 * PERIOD_S,
                judged: None,
                friction_n: None,
                target_step: false,
                at_limit: false,
                load_ramping: false,
                // In fault from step 2 in name only: the drive is still on until `react_at`.
                state: if step >= 2 {
                    SupervisorState::Fault
                } else {
                    SupervisorState::Running
                },
                drive_zero: faulted,
            });
        }
        judge.summary()
    };
    let prompt = run(Some(5));
    assert_eq!(prompt.faults[0].onset_step, 5);
    assert_eq!(prompt.faults[0].periods, Some(1));
    assert!(prompt.passed());
    let slow = run(Some(7));
    assert_eq!(slow.verdicts[0].measured, Measured::Periods(3));
    assert_eq!(
        (slow.verdicts[0].passed, slow.verdicts[1].passed),
        (false, true)
    );
    let never = run(None);
    assert_eq!(never.verdicts[1].measured, Measured::Never);
    assert!(!never.passed());
}

#[test]
fn too_many_criteria_do_not_fit() {
    let many = [Criterion::Overshoot { max_pct: 5.0 }; MAX_CRITERIA + 1];
    assert!(Judge::new(&scene_with(&many, &[])).is_none());
    assert!(Judge::new(&scene_with(&many[..MAX_CRITERIA], &[])).is_some());
}
