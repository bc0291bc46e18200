//! The cases of issue 26 that were accepted in silence and failed the run, each refused now;
//! and every shipped scene still accepted.

use super::*;
use crate::scene::{Breakpoint, Contents, LoadCell, SCENES, TargetPoint, find};
use crate::variant::select;
use std::format;
use std::string::ToString;
use std::vec::Vec;

fn judge(scene: &Scene<'_>) -> Feasibility {
    let model = select(scene).build(scene).expect("the controller's model");
    check(scene, &model)
}

fn reference() -> Scene<'static> {
    *find("reference").expect("built in")
}

/// The reference scene with its second target replaced.
fn with_target(target: Target, points: &mut Vec<TargetPoint>) -> Scene<'_> {
    let scene = reference();
    points.extend_from_slice(scene.target);
    points[1].target = target;
    Scene {
        target: points,
        ..scene
    }
}

fn refused_at(feasibility: &Feasibility, field: &str) -> std::string::String {
    let refusal = feasibility
        .refusal()
        .unwrap_or_else(|| panic!("not refused: {:?}", feasibility.findings()));
    assert_eq!(refusal.field, field, "{refusal}");
    refusal.to_string()
}

#[test]
fn every_shipped_scene_is_accepted() {
    for scene in SCENES {
        let feasibility = judge(scene);
        assert!(
            feasibility.refusal().is_none(),
            "{}: {}",
            scene.name,
            feasibility
                .refusal()
                .map(|f| f.to_string())
                .unwrap_or_default()
        );
    }
}

#[test]
fn a_reduction_the_full_drive_cannot_reach_is_refused_with_the_reachable_value() {
    let mut points = Vec::new();
    let scene = with_target(
        Target::Reduction {
            reduction_mpct: 99_000,
        },
        &mut points,
    );
    let message = refused_at(&judge(&scene), "profiles.target.reduction_pct");
    assert!(
        message.contains("profiles.target[1].reduction_pct = 99"),
        "{message}"
    );
    // The reference's Coulomb ratio at v / v_a = 0.038 / 0.1195 and full drive: 0.62 of the
    // natural friction (Littmann: 2/pi asin(v / v_a) = 0.206, so reduction at most ~79 %).
    let Some(Finding {
        cause: Cause::TargetOutOfReach {
            reachable_ratio, ..
        },
        ..
    }) = judge(&scene).refusal().copied()
    else {
        panic!("not a reach finding");
    };
    let littmann = 2.0 / core::f64::consts::PI
        * libm::asin(0.038 / (core::f64::consts::TAU * 40e3 * 0.4756e-6));
    assert!(
        (reachable_ratio - littmann).abs() < 0.01,
        "{reachable_ratio} vs {littmann}"
    );
}

#[test]
fn a_one_millinewton_force_target_is_refused() {
    let mut points = Vec::new();
    let scene = with_target(Target::Force { force_mn: 1 }, &mut points);
    refused_at(&judge(&scene), "profiles.target.force_n");
}

#[test]
fn a_target_above_the_natural_friction_is_refused() {
    let mut points = Vec::new();
    // mu = 0.2: a coefficient of 0.3 needs more friction than the contact has.
    let scene = with_target(Target::Coef { coef_ppm: 300_000 }, &mut points);
    let message = refused_at(&judge(&scene), "profiles.target.coef");
    assert!(message.contains("only lowers friction"), "{message}");
}

#[test]
fn a_speed_near_the_vibration_velocity_leaves_no_reduction_to_hold() {
    let scene = reference();
    // v_a = 2 pi 40 kHz 0.4756 um = 0.1195 m/s: at 0.119 m/s the Littmann ratio is 0.97.
    let speed = [Breakpoint {
        t_s: 0.0,
        value: 0.119,
    }];
    let scene = Scene {
        sliding_velocity_m_per_s: &speed,
        contents: Contents {
            velocity_min_m_per_s: 0.119,
            velocity_max_m_per_s: 0.119,
            ..scene.contents
        },
        ..scene
    };
    refused_at(&judge(&scene), "profiles.target.reduction_pct");
}

#[test]
fn a_drive_far_from_resonance_is_refused_through_its_gain() {
    let scene = reference();
    // 20 kHz on the 40 kHz stack with Q = 100: gain 1 / sqrt(1 + 100^2) = 0.01.
    let scene = Scene {
        transducer: crate::scene::Transducer {
            drive_hz: 20_000.0,
            ..scene.transducer
        },
        ..scene
    };
    assert!((drive_gain(&scene, 0.0) - 1.0 / libm::sqrt(1.0 + 1e4)).abs() < 1e-9);
    refused_at(&judge(&scene), "profiles.target.reduction_pct");
}

#[test]
fn a_speed_below_the_sliding_threshold_is_refused() {
    let scene = reference();
    let speed = [Breakpoint {
        t_s: 0.0,
        value: 0.0008,
    }];
    let scene = Scene {
        sliding_velocity_m_per_s: &speed,
        contents: Contents {
            velocity_min_m_per_s: 0.0008,
            velocity_max_m_per_s: 0.0008,
            ..scene.contents
        },
        ..scene
    };
    let message = refused_at(&judge(&scene), "profiles.sliding_velocity_m_per_s");
    assert!(
        message.contains("at most 0.000800 m/s") && message.contains("0.001 m/s"),
        "{message}"
    );
}

#[test]
fn a_window_with_a_reversal_is_a_warning_not_a_refusal() {
    let scene = reference();
    let speed = [
        Breakpoint {
            t_s: 0.0,
            value: 0.038,
        },
        Breakpoint {
            t_s: 0.02,
            value: -0.038,
        },
    ];
    let scene = Scene {
        sliding_velocity_m_per_s: &speed,
        contents: Contents {
            velocity_min_m_per_s: -0.038,
            velocity_max_m_per_s: 0.038,
            ..scene.contents
        },
        ..scene
    };
    let feasibility = judge(&scene);
    let warning = feasibility
        .warnings()
        .find(|f| f.field == "profiles.sliding_velocity_m_per_s")
        .expect("a warning");
    assert!(format!("{warning}").starts_with("warning: "));
}

#[test]
fn cell_noise_as_large_as_the_friction_is_refused() {
    let scene = reference();
    // 0.1 N of load: 0.02 N of natural friction, 0.01 N against 0.5 % of the 2 N cell.
    let load = [Breakpoint {
        t_s: 0.0,
        value: 0.1,
    }];
    let scene = Scene {
        normal_load_n: &load,
        contents: Contents {
            load_min_n: 0.1,
            load_max_n: 0.1,
            ..scene.contents
        },
        ..scene
    };
    let message = refused_at(&judge(&scene), "sensors.tangential.noise_rms_pct_fs");
    assert!(message.contains("accuracy.friction_pct = 1 %"), "{message}");
}

#[test]
fn a_quiet_cell_on_the_same_scene_passes_the_noise_check() {
    let scene = reference();
    let quiet = LoadCell {
        noise_rms_pct_fs: 0.0,
        adc_bits: 16,
        ..scene.tangential_cell
    };
    let scene = Scene {
        tangential_cell: quiet,
        normal_cell: LoadCell {
            noise_rms_pct_fs: 0.0,
            adc_bits: 16,
            ..scene.normal_cell
        },
        ..scene
    };
    assert!(
        judge(&scene)
            .findings()
            .iter()
            .all(|f| !matches!(f.cause, Cause::Noise { .. }))
    );
}

#[test]
fn the_filter_gain_is_the_first_order_low_pass_variance_share() {
    // alpha small: variance share alpha / 2 = pi f_c / f_s for a -3 dB bandwidth f_c.
    let gain = filter_rms_gain(10.0, 1e6);
    assert!(
        (gain * gain - core::f64::consts::PI * 10.0 / 1e6).abs() < 1e-8,
        "{gain}"
    );
}

/// The reference with its 50 % step made `reduction_pct` (milli-percent) or a coefficient target.
fn step_findings(target: Target) -> Vec<Finding> {
    let mut points = Vec::new();
    let scene = with_target(target, &mut points);
    judge(&scene)
        .findings()
        .iter()
        .filter(|f| matches!(f.cause, Cause::StepBelowResolution { .. }))
        .copied()
        .collect()
}

#[test]
fn a_reduction_step_near_what_the_cells_resolve_is_warned_with_its_chance() {
    // The reference's cells (0.5 % FS of 2 N and 10 N) at 4.155 N: one sample of the coefficient
    // is known to about 1.7 %, 40 samples to 0.27 %; at a 2 % step that holds the friction about
    // 13 % of the step off its target, against the 5 % overshoot criterion: past it in about
    // 35 % of runs (one-sided normal tail at 5 / 13 standard errors).
    let small = step_findings(Target::Reduction {
        reduction_mpct: 2_000,
    });
    assert_eq!(small.len(), 1, "{small:?}");
    assert_eq!(small[0].severity, Severity::Warn);
    assert_eq!(small[0].field, "profiles.target");
    let Cause::StepBelowResolution {
        point,
        step_pct,
        natural_error_pct,
        samples,
        offset_pct_of_step,
        overshoot_pct,
        chance_past,
    } = small[0].cause
    else {
        unreachable!()
    };
    assert_eq!((point, samples, overshoot_pct), (1, 40.0, 5.0));
    assert!((step_pct - 2.0).abs() < 1e-9, "{step_pct}");
    assert!(
        (0.25..0.30).contains(&natural_error_pct),
        "{natural_error_pct}"
    );
    let expected = 98.0 * natural_error_pct / 2.0;
    assert!((offset_pct_of_step - expected).abs() < 1e-9);
    // Phi(-5 / 13.1) = 0.351.
    assert!((0.34..0.36).contains(&chance_past), "{chance_past}");
    let text = small[0].to_string();
    assert!(text.contains("profiles.target[1].reduction_pct") && text.contains("40 samples"));
    // An 8 % step: 3.1 % of the step against 5 %, still above half the criterion (warned,
    // past it in about 5 % of runs); a 12 % step is below half of it (2.1 %): nothing to say.
    let middle = step_findings(Target::Reduction {
        reduction_mpct: 8_000,
    });
    assert_eq!(middle.len(), 1, "{middle:?}");
    assert_eq!(middle[0].severity, Severity::Warn);
    assert!(
        step_findings(Target::Reduction {
            reduction_mpct: 12_000
        })
        .is_empty()
    );
    // The reference's own 50 % step is far above it.
    assert!(
        step_findings(Target::Reduction {
            reduction_mpct: 50_000
        })
        .is_empty()
    );
}

#[test]
fn a_coefficient_step_does_not_depend_on_mu0() {
    // 2 % below the controller's mu0 of 0.2, as an absolute coefficient: mu0's error does not
    // move it, so the check has nothing to say.
    assert!(step_findings(Target::Coef { coef_ppm: 196_000 }).is_empty());
}
