//! `commission` on a scene's simulated rig before a run (a scene with `commission = true`):
//! the firmware's own sequence ([`sonolube::commission`], through [`Station::execute`]) on a
//! plant built from the scene, operated, idle, with the contact loaded and sliding as the
//! scene's profiles have it at t = 0.
//!
//! The rig's transducer samples its drive current (`bvd_envelope`: a rig that commissions has a
//! current sense), so its motional branch rings down with the scene's true Q and f0; everything
//! else is the scene's plant, with its noise seed. The run that follows is a new plant: the
//! commissioning rig stands for the bench session before it.
//!
//! [`Station::execute`]: sonolube::station::Station::execute

use sonolube::commission::CommissionResult;
use sonolube::protocol::Command;
use sonolube::scene::Scene;
use sonolube::station::CommissionReport;

use super::{ClosedLoop, SimError};

/// Longest commissioning on the simulated rig, s: each of its five steps may take one second
/// (`sonolube::commission`), and 0.5 s more covers the quiet step of the slowest Q.
const RIG_LIMIT_S: f64 = 5.5;

/// The scene of `scene`'s simulated rig: the scene, its transducer sampling its drive current,
/// no search at start, not itself commissioned.
pub fn rig_scene<'a>(scene: &Scene<'a>) -> Scene<'a> {
    let mut rig_scene = *scene;
    rig_scene.transducer.shift.bvd_envelope = true;
    rig_scene.transducer.shift.freq_auto = false;
    rig_scene.commission = false;
    rig_scene
}

/// Starts the sequence on `rig` ([`ClosedLoop::operated`] of [`rig_scene`], just built).
/// The QEMU board then steps it in its control loop; [`commission_rig`] steps it here.
pub fn start_rig_commission(rig: &mut ClosedLoop<'_>) -> Result<(), SimError> {
    rig.execute(&Command::Commission)
        .map_err(SimError::Resonance)
}

/// How the commissioning on `rig` ended: `None` while it runs.
pub fn rig_commission_outcome(rig: &ClosedLoop<'_>) -> Option<Result<CommissionResult, SimError>> {
    match rig.station().commission_report() {
        CommissionReport::Running(_) | CommissionReport::Never | CommissionReport::Restored(_) => {
            None
        }
        CommissionReport::Done(result) => Some(Ok(result)),
        CommissionReport::Refused(refusal) => {
            Some(Err(SimError::Commission(refusal.step, refusal.reason)))
        }
    }
}

/// Commissions `scene`'s simulated rig: the result the firmware's sequence accepted, or why it
/// refused ([`SimError::Commission`]). Never inlined: the rig's run (14 KB) lives in this
/// function's own frame, gone before the caller builds the scene's run.
#[inline(never)]
pub fn commission_rig(scene: &Scene<'_>) -> Result<CommissionResult, SimError> {
    let mut rig = ClosedLoop::operated(&rig_scene(scene))?;
    start_rig_commission(&mut rig)?;
    let limit = libm::ceil(RIG_LIMIT_S * scene.control_rate_hz) as u32;
    for _ in 0..limit {
        rig.step();
        if let Some(outcome) = rig_commission_outcome(&rig) {
            return outcome;
        }
    }
    Err(SimError::Commission(
        sonolube::commission::Step::Natural,
        "the sequence did not end",
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::scene::find;

    /// The simulated rig's truth: f0, Q and the plant's mu at the scene's start.
    fn truth(scene: &Scene<'_>) -> (f64, f64, f64) {
        let speed = scene
            .sliding_velocity_m_per_s
            .first()
            .map_or(0.0, |p| p.value);
        (
            scene.transducer.resonance_hz,
            scene.transducer.quality_factor,
            scene.plant.natural_coefficient(libm::fabs(speed)),
        )
    }

    #[test]
    fn commissioning_measures_the_rigs_true_resonance_q_and_mu0_within_their_errors() {
        for name in ["reference", "resonance-search"] {
            let scene = find(name).expect("built in");
            let result = commission_rig(scene).expect("commissioned");
            let (f0, q, mu0) = truth(scene);
            std::println!("{name}: {result:?}");
            let within = |m: sonolube::commission::Measured, truth: f64, floor: f64| {
                (m.value - truth).abs() <= 4.0 * m.standard_error + floor
            };
            assert!(within(result.resonance_hz, f0, 1.0), "{name} f0 {result:?}");
            assert!(within(result.quality_factor, q, 0.0), "{name} Q {result:?}");
            // mu0's standard error is the scatter of its samples; the cells' `tare` and `cal`
            // (256 samples each, `COMMISSIONING_SAMPLES`) leave each cell's zero and gain off by
            // its noise / 16 (zero) and that over the known load (gain, half full scale), a
            // bias the samples cannot see: the tolerance adds it.
            let load = scene.normal_load_n.first().map_or(1.0, |p| p.value);
            let cell_bias = |cell: &sonolube::scene::LoadCell, force: f64| {
                let noise_n = cell.noise_rms_pct_fs / 100.0 * cell.full_scale_n / 16.0;
                libm::hypot(noise_n / force, noise_n / (0.5 * cell.full_scale_n))
            };
            let bias = mu0
                * libm::hypot(
                    cell_bias(&scene.normal_cell, load),
                    cell_bias(&scene.tangential_cell, mu0 * load),
                );
            let tolerance = 4.0 * libm::hypot(result.natural_coefficient.standard_error, bias);
            assert!(
                (result.natural_coefficient.value - mu0).abs() <= tolerance,
                "{name} mu0 {result:?} tolerance {tolerance}"
            );
        }
    }
}

#[cfg(test)]
mod console {
    use super::*;
    use sonolube::control::{Config, tuned};
    use sonolube::fx::Q2_30;
    use sonolube::scene::find;

    /// The console's `commission` (the station's own path, not a scene's `commission = true`)
    /// puts every value it measured into the loop: the envelope's time constant, f0 (drive
    /// and current ceiling), mu0 (the natural coefficient's prior, the estimate restarted
    /// there, the contact's relaxation lag scaled with it), both cells' measured noise, and
    /// the gains by the tuning rule on all of them. Each assertion fails when its value is
    /// dropped from `commissioned_settings` or `apply_commission`.
    #[test]
    fn a_console_commission_runs_the_loop_on_every_measured_value() {
        let scene = find("resonance-search").expect("built in");
        let mut rig = ClosedLoop::operated(&rig_scene(scene)).expect("operated");
        let declared = *rig.station().settings();
        assert_eq!(rig.station().commissioned(), None);
        start_rig_commission(&mut rig).expect("started");
        let limit = libm::ceil(RIG_LIMIT_S * scene.control_rate_hz) as u32;
        let mut outcome = None;
        for _ in 0..limit {
            rig.step();
            outcome = rig_commission_outcome(&rig);
            if outcome.is_some() {
                break;
            }
        }
        let result = outcome.expect("ended").expect("accepted");
        let station = rig.station();
        let s = *station.settings();
        assert_eq!(station.commissioned(), Some(result));
        assert_eq!(s.envelope_time_constant_s, result.time_constant_s.value);
        assert_eq!(s.actuator.drive_frequency_hz, result.resonance_hz.value);
        let chz = libm::round(result.resonance_hz.value * 100.0) as u32;
        assert!(
            station.drive_freq_chz().abs_diff(chz) <= 1,
            "{}",
            station.drive_freq_chz()
        );
        // mu0: the prior, the estimate restarted at it, the contact's lag scaled with it.
        let mu0 = result.natural_coefficient.value;
        assert_eq!(s.natural_prior, mu0);
        assert_ne!(declared.natural_prior, mu0);
        let natural = station.controller().natural_coefficient();
        assert_eq!(
            natural,
            Q2_30::from_f64(mu0).expect("in range"),
            "{natural:?}"
        );
        assert_eq!(
            s.contact_lag_s,
            declared.contact_lag_s * (mu0 / declared.natural_prior)
        );
        // The cells' noise as their tare measured it (the simulated rig tares both).
        let normal_noise = result.normal.noise_rms_n.expect("normal cell tared");
        let tangential_noise = result
            .tangential
            .noise_rms_n
            .expect("tangential cell tared");
        assert_eq!(s.normal_noise_n, normal_noise);
        assert_eq!(s.tangential_noise_n, tangential_noise);
        // The gains by the rule on these values, and the controller running them.
        assert_eq!(tuned(&s), Ok(s));
        assert_eq!(
            station.controller().config(),
            &Config::new(&s).expect("accepted")
        );
    }
}

#[cfg(test)]
mod console_mismatch {
    use super::*;
    use sonolube::control::Settings;
    use sonolube::scene::find;

    /// The declared and the console-commissioned settings of `scene`'s rig.
    fn console_commissioned(scene: &Scene<'_>) -> (Settings, Settings) {
        let mut rig = ClosedLoop::operated(&rig_scene(scene)).expect("operated");
        let declared = *rig.station().settings();
        start_rig_commission(&mut rig).expect("started");
        let limit = libm::ceil(RIG_LIMIT_S * scene.control_rate_hz) as u32;
        for _ in 0..limit {
            rig.step();
            if let Some(outcome) = rig_commission_outcome(&rig) {
                outcome.expect("accepted");
                return (declared, *rig.station().settings());
            }
        }
        panic!("the sequence did not end");
    }

    /// The console's `commission` keeps the mismatch the scene declares (commissioning does
    /// not measure the model's error) and the scene's 5 % overshoot criterion, so its steps are
    /// staged by them as the declared tuning's are (`(1 + 0.05) / (1 + m)` of a step at once:
    /// 0.875 at the default 20 %, 0.75 at a declared 40 %), and its lead on the measured
    /// envelope is the declared tuning's rule (`drive_lead_s`; the console path ran the
    /// baseline's 0.25 ms before, whatever the criterion). The fast gain keeps its cap
    /// `(1 - m - kp) / T`.
    #[test]
    fn a_console_commission_designs_for_the_declared_mismatch() {
        let reference = find("reference").expect("built in");
        for (declared_mismatch, expected_mismatch) in [(None, 0.2), (Some(0.4), 0.4)] {
            let scene = Scene {
                model_mismatch: declared_mismatch,
                ..*reference
            };
            let (declared, s) = console_commissioned(&scene);
            assert_eq!(declared.model_mismatch, expected_mismatch);
            assert_eq!(s.model_mismatch, expected_mismatch);
            assert_eq!(s.step_overshoot, Some(0.05));
            assert_eq!(
                s.response_time_constant_s,
                sonolube::control::drive_lead_s(&s, Some(0.05)),
                "{declared_mismatch:?}"
            );
            assert_eq!(
                s.response_time_constant_s,
                declared.response_time_constant_s
            );
            assert!(
                s.ki_fast_per_s <= (1.0 - expected_mismatch - s.kp_fast) / s.period_s + 1e-9,
                "{}",
                s.ki_fast_per_s
            );
        }
    }
}

#[cfg(test)]
mod refusals {
    use super::*;
    use sonolube::commission::Step;
    use sonolube::protocol::{ProtocolError, SupervisorState};
    use sonolube::scene::{Breakpoint, find};

    #[test]
    fn a_rig_that_does_not_sample_its_current_cannot_commission() {
        let scene = find("reference").expect("built in");
        let mut run = ClosedLoop::operated(scene).expect("operated");
        assert!(matches!(
            run.execute(&Command::Commission),
            Err(ProtocolError::Unavailable { .. })
        ));
        assert_eq!(run.station().commission_report(), CommissionReport::Never);
    }

    #[test]
    fn while_commissioning_the_loop_refuses_its_commands_and_stop_ends_it() {
        let scene = find("reference").expect("built in");
        let mut rig = ClosedLoop::operated(&rig_scene(scene)).expect("operated");
        start_rig_commission(&mut rig).expect("started");
        for _ in 0..20 {
            rig.step();
        }
        assert_eq!(rig.station().state(), SupervisorState::Tuning);
        assert!(matches!(
            rig.execute(&Command::Start),
            Err(ProtocolError::WrongState {
                state: SupervisorState::Tuning,
                ..
            })
        ));
        assert!(matches!(
            rig.execute(&Command::Commission),
            Err(ProtocolError::WrongState { .. })
        ));
        rig.execute(&Command::Stop).expect("stop ends it");
        match rig.station().commission_report() {
            CommissionReport::Refused(refusal) => assert_eq!(refusal.reason, "stopped"),
            other => panic!("{other:?}"),
        }
        assert_ne!(rig.station().state(), SupervisorState::Tuning);
    }

    #[test]
    fn a_contact_that_does_not_slide_gives_no_mu0() {
        static STILL: [Breakpoint; 1] = [Breakpoint {
            t_s: 0.0,
            value: 0.0,
        }];
        let mut scene = *find("reference").expect("built in");
        scene.sliding_velocity_m_per_s = &STILL;
        assert_eq!(
            commission_rig(&scene),
            Err(SimError::Commission(Step::Natural, "not sliding with load"))
        );
    }
}
