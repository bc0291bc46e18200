//! The controller's one tuning, and the settings a scene's controller runs with.
//!
//! [`controller_settings`] is the tuning: [`Settings::REFERENCE`] (the baseline the unit tests
//! run against the test plant) with what a scene fixes and the four departures below. Every
//! board and the simulation build their controller through it, so the firmware on a real rig
//! runs the tuning the scene runs were judged with. The departures were found on the scene runs
//! (`sonolube scene --all`, 12 noise seeds), each with a physical reason.

use super::config::Settings;
use super::limits::ActuatorRatings;
use crate::scene::{LoadCell, Scene};

/// Bandwidth of both force filters, Hz.
///
/// The coefficient is F_t / F_n of the two filtered forces; with different filters a load
/// change shows as a coefficient change of (tau_n - tau_t) (dF_n/dt) / F_n, which the loop
/// answers with drive: `horn-al-ss`'s 40 N steps in 1 ms pulled the friction up to 7 % below
/// the target for 5 ms with a 200 Hz normal and an 800 Hz tangential filter, outside its
/// +-3 % band. Equal filters make F_t / F_n follow a load change exactly; at 250 Hz they pass
/// 0.36 of the per-sample noise of either cell (the normal cell's noise enters the coefficient
/// one for one). The prediction goes through the same filter, so the slower view does not delay
/// the loop's verdict on the model error: the reference step settles in 1.4 ms and overshoots
/// 1.9 % at 250 Hz, against 4.3 ms and 6.8 % with both filters at 800 Hz.
pub const FORCE_FILTER_HZ: f64 = 250.0;

/// Weight of the scene's coefficient as the prior of mu0, samples.
///
/// The scene's coefficient is known to +-20 % (the acceptance mismatch), one sample of the
/// natural coefficient to 1-2 %: the prior is worth far less than one sample, and 1 is the least
/// the learner takes. With 4, the 5 ms of natural friction before the reference step left mu0
/// 1.5 % low (0.2365 for the plant's 0.24), and as the reduction target is relative to mu0, the
/// steady error was 1.8 % RMS (limit 1 %).
pub const NATURAL_PRIOR_WEIGHT: u32 = 1;

/// Sliding debounce, s.
///
/// mu0 is learned only once sliding is confirmed; 1 ms more of learning before the reference
/// step (against a 2 ms debounce) takes the prior's share of mu0 from 1/31 to 1/41. A velocity
/// glitch of up to 10 samples at 10 kHz is still ignored.
pub const SLIDING_DEBOUNCE_S: f64 = 1e-3;

/// Steady-state PI gains: proportional (ratio per ratio) and integral (1/s).
///
/// The model error the integral holds moves with the operating point: in `seatbelt` load and
/// speed triple in 0.3 s, and with kp 0, ki 150 /s the integral's lag put the friction 2-3 %
/// below the target early in the rise (largest error 3.3 %, limit 3 %). With kp 0.1 and ki
/// 300 /s (at 10 kHz poles 0.973 and -0.103, a 3.6 ms time constant; see "Tuning by pole
/// placement" in [`crate::control`]) it stays within 2 % there (largest 2.6 %), and the
/// reference scene's steady RMS error goes from 0.68 % to 0.69 %.
pub const STEADY_GAINS: (f64, f64) = (0.1, 300.0);

/// The controller's settings for `scene`: [`Settings::REFERENCE`] with the tuning's four
/// departures ([`FORCE_FILTER_HZ`] for both force filters, [`NATURAL_PRIOR_WEIGHT`],
/// [`SLIDING_DEBOUNCE_S`], [`STEADY_GAINS`]) and what the scene fixes: the control period, the
/// actuator ratings at the drive frequency, the controller's natural coefficient as the prior of
/// mu0, plausible ranges of the readings (1.1 x each cell's full scale, twice the fastest
/// sliding speed but at least 5 m/s), and the envelope the controller predicts through.
/// The fast gains, the boost, the lead, the slew and the ramps keep their reference values.
///
/// **Envelope time constant = transducer + tangential cell** (0.796 + 0.080 ms in the
/// reference scene). The PI compares the measured friction with the model's prediction at the
/// estimated envelope; the measurement also passes the cell's own first-order lag, which the
/// prediction lacks. Over a transient the PI integrates the difference, whose area is the lag
/// times the change of the ratio (0.8 periods x 0.5 in the reference step), and the fast
/// integral turns it into a correction that drives the friction past the target: 6.7 % of the
/// step without this term (limit 5 %), 1.9 % with it. Two lags in series have the step-response
/// area of one lag of their summed time constant, so the prediction with the summed constant
/// has the measurement's area and the integral sees no net transient error.
///
/// Configuration, `f64`, once per scene.
pub fn controller_settings(scene: &Scene<'_>) -> Settings {
    let reference = Settings::REFERENCE;
    let start_speed = scene
        .sliding_velocity_m_per_s
        .first()
        .map_or(0.0, |p| libm::fabs(p.value));
    let top_speed = libm::fmax(
        libm::fabs(scene.contents.velocity_min_m_per_s),
        libm::fabs(scene.contents.velocity_max_m_per_s),
    );
    // Q16.16 newtons and Q8.24 m/s hold the ranges below these.
    let force_range = |cell: &LoadCell| libm::fmin(1.1 * cell.full_scale_n, 32_000.0);
    let cell_lag_s = 1.0 / (core::f64::consts::TAU * scene.tangential_cell.bandwidth_hz);
    let envelope = scene.transducer.envelope_time_constant_s() + cell_lag_s;
    let (kp, ki_per_s) = STEADY_GAINS;
    Settings {
        period_s: scene.control_period_s(),
        normal_bandwidth_hz: FORCE_FILTER_HZ,
        tangential_bandwidth_hz: FORCE_FILTER_HZ,
        normal_force_range_n: force_range(&scene.normal_cell),
        tangential_force_range_n: force_range(&scene.tangential_cell),
        velocity_range_m_s: libm::fmin(
            libm::fmax(reference.velocity_range_m_s, 2.0 * top_speed),
            120.0,
        ),
        sliding_debounce_s: SLIDING_DEBOUNCE_S,
        natural_prior: scene.controller.natural_coefficient(start_speed),
        natural_prior_weight: NATURAL_PRIOR_WEIGHT,
        envelope_time_constant_s: envelope,
        // The lead cannot make the envelope slower than it is.
        response_time_constant_s: libm::fmin(reference.response_time_constant_s, envelope),
        kp,
        ki_per_s,
        actuator: ActuatorRatings {
            max_voltage_v: scene.actuator.max_voltage_v,
            max_current_a: scene.actuator.max_current_a,
            capacitance_f: scene.transducer.clamped_capacitance_f,
            drive_frequency_hz: scene.transducer.drive_hz,
            full_scale_voltage_v: scene.actuator.full_scale_voltage_v,
        },
        ..reference
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::find;

    #[test]
    fn the_reference_scene_fixes_its_numbers_and_keeps_the_tuning() {
        let scene = find("reference").expect("built in");
        let s = controller_settings(scene);
        assert_eq!(s.period_s, 1e-4);
        assert_eq!(s.natural_prior, 0.2);
        // 0.7958 ms of envelope and 79.6 us of the 2 kHz tangential cell.
        assert!((s.envelope_time_constant_s - 0.000_875_4).abs() < 1e-7);
        assert_eq!(
            (s.normal_bandwidth_hz, s.tangential_bandwidth_hz),
            (FORCE_FILTER_HZ, FORCE_FILTER_HZ)
        );
        assert_eq!((s.kp, s.ki_per_s), STEADY_GAINS);
        assert_eq!(s.natural_prior_weight, NATURAL_PRIOR_WEIGHT);
        assert_eq!(s.sliding_debounce_s, SLIDING_DEBOUNCE_S);
        assert_eq!(
            (s.kp_fast, s.ki_fast_per_s, s.boost_time_constant_s),
            (0.3, 4_000.0, 3e-3)
        );
        assert!((s.tangential_force_range_n - 2.2).abs() < 1e-12);
        assert_eq!(s.velocity_range_m_s, 5.0);
        assert!(crate::control::Config::new(&s).is_ok());
    }

    #[test]
    fn every_scene_gives_settings_the_controller_accepts() {
        for scene in crate::scene::SCENES {
            let settings = controller_settings(scene);
            assert!(
                crate::control::Config::new(&settings).is_ok(),
                "{}",
                scene.name
            );
        }
    }
}
