//! Feasibility while running (issue 26): whether the target is out of the drive's reach, what
//! the full drive reaches now, and whether the drive frequency is far from the resonance.
//!
//! - **target-unreachable**: the drive has been at its limit (the actuator ceiling, or the
//!   model's full amplitude) for a whole watch window with the tracking error (measured friction
//!   ratio against the target's) not falling: not halved over the window. The window is three times the time the drive takes to act on the
//!   measured friction: the transducer's envelope, the cell's lag and the force filter's time
//!   constant in series (4.5 ms in the reference scene). A reachable target at the limit halves
//!   its error well within it (the envelope reaches 95 % in three time constants); an
//!   unreachable one sits at its floor.
//! - **reachable value**: the controller's model at the present estimate (filtered load and
//!   speed, learned natural coefficient) and the drive's ceiling times the transducer's gain at
//!   the drive frequency `1 / sqrt(1 + x^2)`, in the target's kind.
//! - **resonance distance**: `x = 2 Q (f - f0) / f0`, measured by the resonance loop where the
//!   board samples the current (its motional detuning), else from the scene's nominal f0: the
//!   motional conductance over the resonance's is `1 / (1 + x^2)`, `far` below one half.
//!
//! Configuration and reports in `f64` (not per step); the per-step watch is integer.

use crate::control::{FrictionEstimate, Output};
use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
use crate::model::{FrictionModel, OperatingPoint};
use crate::protocol::{ReachState, ResonanceDistance, SupervisorState, Target};

/// The watch over the drive's limit and the loop's error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct ReachWatch {
    /// Control periods of one watch window, >= 1.
    window_periods: u32,
    /// Periods at the limit in the present window.
    periods: u32,
    /// |error| (Q2.30 bits) at the window's start.
    error_at_start: u32,
    /// The last full window at the limit did not halve the error.
    unreachable: bool,
}

impl ReachWatch {
    /// A watch of `window_s` seconds at a control period of `period_s` (both > 0).
    pub(super) fn new(window_s: f64, period_s: f64) -> Self {
        let periods = libm::ceil(window_s / period_s);
        Self {
            // At least one period; the schema bounds the rate and the time constants.
            window_periods: if (1.0..1e9).contains(&periods) {
                periods as u32
            } else {
                1
            },
            periods: 0,
            error_at_start: 0,
            unreachable: false,
        }
    }

    /// The watch window of a controller: 3 x (envelope + cell lag + force filter) time
    /// constants, s.
    pub(super) fn window_s(settings: &crate::control::Settings) -> f64 {
        let filter_s = 1.0 / (core::f64::consts::TAU * settings.tangential_bandwidth_hz);
        3.0 * (settings.envelope_time_constant_s + settings.sensor_lag_s + filter_s)
    }

    /// Takes one control period's output.
    pub(super) fn update(&mut self, output: &Output) {
        let at_limit = output.state == SupervisorState::Running
            && (output.saturation.actuator || output.saturation.model);
        if !at_limit {
            *self = Self::new_like(self);
            return;
        }
        // The tracking error, measured ratio against the target's (the PI's own error is the
        // model's prediction against the measurement: near zero at the limit, whatever the
        // target).
        let Some(target) = output.target_ratio else {
            *self = Self::new_like(self);
            return;
        };
        let error = output
            .measured_ratio
            .to_bits()
            .wrapping_sub(target.to_bits())
            .unsigned_abs();
        if self.periods == 0 {
            self.error_at_start = error;
        }
        self.periods += 1;
        if self.periods >= self.window_periods {
            self.unreachable = error > self.error_at_start / 2;
            self.periods = 0;
        }
    }

    fn new_like(other: &Self) -> Self {
        Self {
            window_periods: other.window_periods,
            periods: 0,
            error_at_start: 0,
            unreachable: false,
        }
    }

    /// The state the watch reports.
    pub(super) fn state(&self) -> ReachState {
        if self.unreachable {
            ReachState::TargetUnreachable
        } else {
            ReachState::Ok
        }
    }

    /// Control periods of one window.
    #[cfg(test)]
    pub(super) fn window_periods(&self) -> u32 {
        self.window_periods
    }
}

/// The transducer's vibration gain at a detuning of `x` half-bandwidths: `1 / sqrt(1 + x^2)`.
pub(super) fn detuning_gain(half_bandwidths: f64) -> f64 {
    1.0 / libm::sqrt(1.0 + half_bandwidths * half_bandwidths)
}

/// Detuning of `drive_hz` from `resonance_hz` in half-bandwidths: `2 Q (f - f0) / f0`.
pub(super) fn nominal_detuning(drive_hz: f64, resonance_hz: f64, quality_factor: f64) -> f64 {
    2.0 * quality_factor * (drive_hz - resonance_hz) / resonance_hz
}

/// A measured detuning (Q8.24 half-bandwidths) in `f64`.
pub(super) fn measured_detuning(detuning: Q8_24) -> f64 {
    detuning.to_f64()
}

/// The distance of a detuning.
pub(super) fn distance(half_bandwidths: f64) -> ResonanceDistance {
    ResonanceDistance::of_detuning(half_bandwidths)
}

/// What the controller's model says about `target` at the estimate `estimate` (learned natural
/// coefficient `natural`, Q2.30) with the drive's vibration at `drive` (fraction of full
/// scale, the ceiling times the detuning gain): `Some(reachable)` (the nearest value the drive
/// gives, in the target's kind) when the target asks for less friction than that, `None` when
/// it is within reach or nothing can be said (no load, no sliding, a model error).
/// `load_scale` is the factor the controller applies to the load for a model whose load enters
/// as a Coulomb force (mu0 / mu of the model; 1 otherwise).
pub(super) fn beyond_reach<M: FrictionModel + ?Sized>(
    model: &M,
    target: Target,
    estimate: &FrictionEstimate,
    natural: Q2_30,
    drive: f64,
    load_scale: f64,
) -> Option<Target> {
    let load_n = estimate.normal_force.to_f64();
    let speed = libm::fabs(estimate.sliding_velocity.to_f64());
    let mu0 = natural.to_f64();
    if !estimate.load_ok || speed <= 0.0 || mu0 <= 0.0 || load_n <= 0.0 {
        return None;
    }
    let point = OperatingPoint {
        normal_force: Q16_16::from_f64_saturating(load_n * load_scale).value,
        sliding_velocity: Q8_24::from_f64_saturating(speed).value,
    };
    let amplitude = Q1_31::from_f64_saturating(drive).value;
    let reachable = model.ratio(&point, amplitude).ok()?.to_f64();
    let needed = match target {
        Target::Reduction { reduction_mpct } => 1.0 - f64::from(reduction_mpct) * 1e-5,
        Target::Coef { coef_ppm } => f64::from(coef_ppm) * 1e-6 / mu0,
        Target::Force { force_mn } => f64::from(force_mn) * 1e-3 / (mu0 * load_n),
        // A net force is not a friction ratio; the motor hold reports its own reach.
        Target::NetForce { .. } => return None,
    };
    if needed >= reachable {
        return None;
    }
    // Rounded toward what the drive can do (less reduction, more friction).
    Some(match target {
        Target::Reduction { .. } => Target::Reduction {
            reduction_mpct: libm::floor((1.0 - reachable) * 1e5).max(0.0) as u32,
        },
        Target::Coef { .. } => Target::Coef {
            coef_ppm: libm::ceil(reachable * mu0 * 1e6).min(2e6) as u32,
        },
        Target::Force { .. } | Target::NetForce { .. } => Target::Force {
            force_mn: libm::ceil(reachable * mu0 * load_n * 1e3).min(5e7) as u32,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::Saturation;

    /// An output at (or off) the limit whose measured ratio is `error` above a target of 0.2.
    fn output(at_limit: bool, error: f64) -> Output {
        // A real step's output, then the fields the watch reads.
        let scene = crate::scene::find("reference").expect("built in");
        let model = crate::variant::select(scene).build(scene).expect("model");
        let settings = crate::control::controller_settings(scene);
        let mut controller =
            crate::control::Controller::new(crate::control::Config::new(&settings).expect("ok"));
        let inputs = crate::control::Inputs {
            normal_force: Q16_16::from_f64_saturating(4.0).value,
            tangential_force: Q16_16::from_f64_saturating(0.8).value,
            sliding_velocity: Q8_24::from_f64_saturating(0.038).value,
            sensor_fault: None,
        };
        let mut output = controller.step(&inputs, &model);
        output.state = SupervisorState::Running;
        output.saturation = Saturation {
            actuator: at_limit,
            ..output.saturation
        };
        output.target_ratio = Some(Q2_30::from_f64_saturating(0.2).value);
        output.measured_ratio = Q2_30::from_f64_saturating(0.2 + error).value;
        output
    }

    #[test]
    fn a_limit_with_a_falling_error_is_not_unreachable() {
        let mut watch = ReachWatch::new(1e-3, 1e-4);
        assert_eq!(watch.window_periods(), 10);
        // The error halves every 3 periods: reachable, the drive is catching up.
        for k in 0..40 {
            watch.update(&output(true, 0.4 * libm::pow(0.5, f64::from(k) / 3.0)));
            assert_eq!(watch.state(), ReachState::Ok, "period {k}");
        }
    }

    #[test]
    fn a_limit_with_a_stuck_error_is_unreachable_until_the_drive_leaves_it() {
        let mut watch = ReachWatch::new(1e-3, 1e-4);
        for _ in 0..9 {
            watch.update(&output(true, 0.3));
            assert_eq!(watch.state(), ReachState::Ok);
        }
        watch.update(&output(true, 0.3));
        assert_eq!(watch.state(), ReachState::TargetUnreachable);
        watch.update(&output(false, 0.3));
        assert_eq!(watch.state(), ReachState::Ok);
    }

    #[test]
    fn the_gain_and_distance_follow_the_detuning() {
        // `freq 20000` on the 40 kHz, Q = 100 stack.
        let x = nominal_detuning(20_000.0, 40_000.0, 100.0);
        assert_eq!(x, -100.0);
        assert!((detuning_gain(x) - 0.0099995).abs() < 1e-6);
        assert_eq!(distance(x), ResonanceDistance::Far);
        assert_eq!(
            distance(nominal_detuning(40_100.0, 40_000.0, 100.0)),
            ResonanceDistance::Near
        );
    }
}
