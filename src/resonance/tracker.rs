//! Keeps the drive on the motional resonance: a rate-bounded PI loop on the detuning.
//!
//! Each lock-in window gives the current's phasor; C0's current is subtracted
//! ([`ClampedCapacitance::motional`]) and the detuning `x = -Im / Re` of the motional current
//! ([`detuning`]) times the half-bandwidth `f / 2Q` estimates the frequency error
//! of the drive, hence f0; the loop's error `e` is its own fine frequency (mHz, finer than the
//! timer's grid) minus that estimate. The correction is a PI in velocity form,
//!
//! `df = -(Kp (e_k - e_(k-1)) + Ki T_k e_k)`, clamped to `|df| <= R T_k`,
//!
//! with `T_k` the window's duration and `R` the bounded correction rate (Hz/s), then the
//! frequency is clamped to its limits and rounded to what the timer can produce
//! ([`Tuning::nearest`]). Velocity form makes both clamps anti-windup by construction: a
//! clipped step is simply not taken. The integral term makes the loop follow a resonance
//! drifting at `rho` Hz/s with a constant error `rho / Ki` (0.13 Hz for 1 %/s at 40 kHz with
//! the default 3000/s).
//!
//! Gains are fractions of the estimated error, so they do not depend on Q or f0 except
//! through the half-bandwidth's accuracy. Two plants bound the choice: if the motional phase
//! follows the frequency at once (the simulated plant), `Kp` near 1 would ring; if it lags by
//! the envelope time constant `tau` (a real resonator), `Kp` well below 1 is slow. The
//! defaults, `Kp = 0.5`, `Ki = 3000/s` (chosen on a grid for the worst of both plants with
//! 100 us windows), bring errors of -800 to +1500 Hz within 10 Hz in 3.5 ms on both (tests).

use super::error::{ResonanceError, ResonanceFault};
use super::lockin::Demodulated;
use super::motional::{MAX_DETUNING, detuning};
use super::phasor::Phasor;
use super::stack::StackModel;
use super::tuning::Tuning;
use crate::control::SampleBlock;
use crate::drive::{Amplitude, Frequency, TimerClock};
use crate::fx::Q8_24;

/// Loop settings (set-up, f64).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackerSettings {
    /// Proportional gain `Kp`: fraction of a change of the estimated error corrected at once,
    /// 0 to 1.5.
    pub proportional: f64,
    /// Integral gain `Ki`: fraction of the estimated error corrected per second, 1/s, >= 0
    /// (the step gain `Ki T` is capped at 1).
    pub integral_per_s: f64,
    /// Bound on the correction rate `R`, Hz/s, > 0.
    pub max_rate_hz_per_s: f64,
    /// Lowest frequency the loop may command, Hz (20-60 kHz, below `max_hz`). The timer
    /// rounds the command to its grid, at most half a step (0.66 Hz) beyond.
    pub min_hz: f64,
    /// Highest frequency the loop may command, Hz (20-60 kHz), rounded likewise.
    pub max_hz: f64,
    /// |detuning| (half-bandwidths) at or below which a window counts as on resonance, in
    /// (0, 16].
    pub lock_detuning: f64,
    /// Consecutive on-resonance windows that make the loop locked, >= 1.
    pub lock_windows: u16,
    /// Consecutive windows pinned at a limit (and pushing past it) before
    /// [`ResonanceFault::AtFrequencyLimit`], >= 1.
    pub limit_windows: u16,
    /// Consecutive windows without current before [`ResonanceFault::NoCurrent`], >= 1.
    pub no_current_windows: u16,
}

impl TrackerSettings {
    /// Operation on the reference stack: 36-44 kHz (f0 +- 10 %), correction rate bounded to
    /// 4 kHz/s (ten times a drift of 1 %/s), locked within 0.1 half-bandwidth (20 Hz) over 5
    /// windows, 50 windows (5 ms) at a limit or 3 without current are faults.
    pub const OPERATION: Self = Self {
        proportional: 0.5,
        integral_per_s: 3000.0,
        max_rate_hz_per_s: 4000.0,
        min_hz: 36_000.0,
        max_hz: 44_000.0,
        lock_detuning: 0.1,
        lock_windows: 5,
        limit_windows: 50,
        no_current_windows: 3,
    };

    /// Pull-in after the coarse sweep: the same loop with the rate bound raised to 5 MHz/s
    /// (500 Hz per 100 us window) so that the lag of the sweep's peak is caught up in a few
    /// windows, and 20 windows (2 ms) of low current before a fault: on its way the loop may
    /// cross the parallel resonance, where a connected stack draws little current (0.004 S
    /// for the reference stack at 20 kHz, settled).
    pub const PULL_IN: Self = Self {
        max_rate_hz_per_s: 5.0e6,
        no_current_windows: 20,
        ..Self::OPERATION
    };

    /// These settings with the integral gain and the rate bound derived from the resonator's
    /// envelope (f0 `resonance_hz`, `quality_factor`; both in range for [`StackModel`]), the
    /// proportional gain kept.
    ///
    /// The motional phase, hence the measured error `e`, follows the drive frequency through
    /// the envelope's lag `1 / (1 + s tau)`, `tau = Q / (pi f0)` (physics-notes section 7).
    /// The velocity-form PI, `df/dt = -Kp de/dt - Ki e`, closes the loop
    /// `tau s^2 + (1 + Kp) s + Ki = 0`: the error decays at `(1 + Kp) / (2 tau)` and the
    /// damping ratio is `(1 + Kp) / (2 sqrt(tau Ki))`. [`LOOP_DAMPING`] gives
    /// `Ki = (1 + Kp)^2 / (4 zeta^2 tau)`: 1,410 /s at 40 kHz, Q 100; 235 /s at 20 kHz,
    /// Q 300; 7,070 /s at 60 kHz, Q 30. A fixed `Ki` (3,000 /s before) is a damping ratio of
    /// 0.48 at 40 kHz, Q 100 but 0.20 at 20 kHz, Q 300: the loop rings for many `tau` and
    /// its detuning never stays within the lock band for the hold (docs/resonance.md).
    ///
    /// The rate bound lets the loop cross the whole range the detuning reads,
    /// [`MAX_DETUNING`] half-bandwidths, in one `tau`: `R = 16 (f0 / 2Q) / tau = 8 pi f0^2 /
    /// Q^2` (4.0 MHz/s at 40 kHz, Q 100; 112 kHz/s at 20 kHz, Q 300). Faster than that
    /// the envelope cannot follow and the measured detuning is a transient's.
    pub fn on_resonator(self, resonance_hz: f64, quality_factor: f64) -> Self {
        let tau_s = quality_factor / (core::f64::consts::PI * resonance_hz);
        let half_bandwidth_hz = resonance_hz / (2.0 * quality_factor);
        let kp = self.proportional;
        Self {
            integral_per_s: (1.0 + kp) * (1.0 + kp) / (4.0 * LOOP_DAMPING * LOOP_DAMPING * tau_s),
            max_rate_hz_per_s: MAX_DETUNING.to_f64() * half_bandwidth_hz / tau_s,
            ..self
        }
    }

    /// The rate, 1/s, at which the loop of [`Self::on_resonator`] shrinks an error on a
    /// resonator of envelope time constant `tau_s`: `(1 + Kp) / (2 tau)`.
    pub fn decay_rate_per_s(&self, tau_s: f64) -> f64 {
        (1.0 + self.proportional) / (2.0 * tau_s)
    }
}

/// The damping ratio [`TrackerSettings::on_resonator`] designs for, `1 / sqrt 2` (overshoot
/// 4.3 %): every ratio below 1 decays at the same `(1 + Kp) / (2 tau)`, a smaller one
/// overshoots more, and one above 1 splits the poles, the slower decaying slower.
pub const LOOP_DAMPING: f64 = core::f64::consts::FRAC_1_SQRT_2;

/// [`TrackerSettings`] in fixed point, with the stack model it works on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackerConfig {
    stack: StackModel,
    /// Kp, Q2.30.
    proportional_q30: i32,
    /// Ki / f_s: integral gain per sample, Q16.48.
    integral_per_sample_q48: u64,
    /// R / f_s: rate bound per sample, mHz x 2^16 (resolution 15 mHz/s at 1 MSPS).
    rate_per_sample_q16: u64,
    min: Frequency,
    max: Frequency,
    lock_detuning: Q8_24,
    lock_windows: u16,
    limit_windows: u16,
    no_current_windows: u16,
}

impl TrackerConfig {
    /// The loop for `stack`, fed by a lock-in sampling at `sample_rate_hz`. Error `Setting`
    /// or `Band` for values outside the ranges of [`TrackerSettings`].
    pub fn new(
        settings: &TrackerSettings,
        stack: StackModel,
        sample_rate_hz: u32,
    ) -> Result<Self, ResonanceError> {
        let s = settings;
        let fs = f64::from(sample_rate_hz);
        let gains_ok = (0.0..=1.5).contains(&s.proportional)
            && s.integral_per_s.is_finite()
            && s.integral_per_s >= 0.0
            && s.max_rate_hz_per_s.is_finite()
            && s.max_rate_hz_per_s > 0.0
            && s.lock_detuning > 0.0
            && s.lock_detuning <= MAX_DETUNING.to_f64()
            && s.lock_windows > 0
            && s.limit_windows > 0
            && s.no_current_windows > 0
            && sample_rate_hz > 0;
        if !gains_ok {
            return Err(ResonanceError::Setting);
        }
        let band = 20_000.0..=60_000.0;
        if !(band.contains(&s.min_hz) && band.contains(&s.max_hz) && s.min_hz < s.max_hz) {
            return Err(ResonanceError::Band);
        }
        let integral = libm::round(s.integral_per_s / fs * (1u64 << 48) as f64);
        let rate = libm::round(s.max_rate_hz_per_s * 1000.0 / fs * 65_536.0);
        // Both must leave room for the product with a window's sample count (< 2^21).
        if integral >= (1u64 << 63) as f64 || rate >= (1u64 << 43) as f64 || rate < 1.0 {
            return Err(ResonanceError::Setting);
        }
        let millihertz = |hz: f64| Frequency::from_millihertz(libm::round(hz * 1000.0) as u32);
        Ok(Self {
            stack,
            proportional_q30: libm::round(s.proportional * (1u64 << 30) as f64) as i32,
            integral_per_sample_q48: integral as u64,
            rate_per_sample_q16: rate as u64,
            min: millihertz(s.min_hz),
            max: millihertz(s.max_hz),
            lock_detuning: Q8_24::from_f64(s.lock_detuning).map_err(|_| ResonanceError::Setting)?,
            lock_windows: s.lock_windows,
            limit_windows: s.limit_windows,
            no_current_windows: s.no_current_windows,
        })
    }

    /// The stack model.
    pub const fn stack(&self) -> StackModel {
        self.stack
    }

    /// The largest frequency change over a window of `samples` samples, mHz.
    pub const fn max_step_mhz(&self, samples: u32) -> i64 {
        // rate < 2^43 and samples < 2^21: the product fits u64.
        ((self.rate_per_sample_q16 * samples as u64) >> 16) as i64
    }
}

/// What one control step decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackStatus {
    /// The drive setting to use from now on (unchanged when the step held).
    pub tuning: Tuning,
    /// The measured detuning, half-bandwidths (Q8.24): `(f - f0) / (f0 / 2Q)`.
    pub detuning: Q8_24,
    /// The motional current, full scale, relative to the voltage (its `polar()` phase is the
    /// phase error; not computed here: a CORDIC the loop itself does not need).
    pub motional: Phasor,
    /// On resonance for the configured number of windows.
    pub locked: bool,
    /// The step was clipped by the rate bound.
    pub rate_limited: bool,
}

/// The tracking loop as a block: its gains and limits and the timer clock its command is
/// rounded to. `Copy`, replaced whole by [`Tracker::reconfigure`] between two windows, never
/// changed by a window; the block of [`SampleBlock`] whose state is [`TrackerState`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrackingLoop {
    config: TrackerConfig,
    clock: TimerClock,
}

/// One lock-in window for the tracker: the current measured at the state's
/// [`TrackerState::tuning`] with drive `amplitude`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrackWindow {
    /// The lock-in's window.
    pub window: Demodulated,
    /// The drive amplitude during the window.
    pub amplitude: Amplitude,
}

/// The tracking loop's state: its fine frequency, the drive setting in force, the previous
/// error (velocity form) and the lock, limit and no-current counts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrackerState {
    /// The loop's frequency (finer than the timer's grid), mHz, within the loop's limits.
    command_mhz: i64,
    tuning: Tuning,
    previous_error_mhz: i64,
    in_lock: u16,
    at_limit: u16,
    without_current: u16,
}

impl TrackerState {
    /// The drive setting in force.
    pub const fn tuning(&self) -> Tuning {
        self.tuning
    }
}

/// The tracking loop: a [`TrackingLoop`] and the [`TrackerState`] it runs on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tracker {
    block: TrackingLoop,
    state: TrackerState,
}

impl Tracker {
    /// A loop starting at `start` (clamped to the limits). Error: the timer cannot produce the
    /// frequency (`Drive`).
    pub fn new(
        config: TrackerConfig,
        start: Frequency,
        clock: TimerClock,
    ) -> Result<Self, ResonanceError> {
        let command = clamp(i64::from(start.millihertz()), &config);
        let tuning = Tuning::nearest(Frequency::from_millihertz(command as u32), clock)?;
        Ok(Self {
            block: TrackingLoop { config, clock },
            state: TrackerState {
                command_mhz: command,
                tuning,
                previous_error_mhz: 0,
                in_lock: 0,
                at_limit: 0,
                without_current: 0,
            },
        })
    }

    /// Switches to `config` (for example from pull-in to operation) keeping the frequency
    /// (clamped to the new limits) and the lock count. Error as [`Self::new`].
    pub fn reconfigure(&mut self, config: TrackerConfig) -> Result<(), ResonanceError> {
        let state = &mut self.state;
        let command = clamp(state.command_mhz, &config);
        state.tuning =
            Tuning::nearest(Frequency::from_millihertz(command as u32), self.block.clock)?;
        state.command_mhz = command;
        self.block.config = config;
        Ok(())
    }

    /// The drive setting in force.
    pub const fn tuning(&self) -> Tuning {
        self.state.tuning
    }

    /// One control step from the window measured at [`Self::tuning`] with drive `amplitude`:
    /// the [`TrackingLoop`]'s [`SampleBlock::process`] on this tracker's state.
    pub fn update(
        &mut self,
        window: &Demodulated,
        amplitude: Amplitude,
    ) -> Result<TrackStatus, ResonanceFault> {
        let input = TrackWindow {
            window: *window,
            amplitude,
        };
        self.block.process(&mut self.state, input)
    }
}

/// One control step from a window. With zero amplitude nothing is measured and the frequency
/// holds. Fixed point: one division ([`detuning`]), a CORDIC, 128-bit products;
/// [`Tuning::nearest`] divides once.
///
/// Errors: `NoCurrent` after `no_current_windows` windows whose current stayed below the
/// stack's threshold; `AtFrequencyLimit` after `limit_windows` windows pinned at a limit.
impl SampleBlock<TrackWindow> for TrackingLoop {
    type State = TrackerState;
    type Output = Result<TrackStatus, ResonanceFault>;

    fn process(
        &self,
        state: &mut TrackerState,
        input: TrackWindow,
    ) -> Result<TrackStatus, ResonanceFault> {
        let stack = self.config.stack;
        let mut status = TrackStatus {
            tuning: state.tuning,
            detuning: Q8_24::ZERO,
            motional: Phasor::ZERO,
            locked: false,
            rate_limited: false,
        };
        if input.amplitude == Amplitude::ZERO {
            state.previous_error_mhz = 0;
            state.in_lock = 0;
            return Ok(status);
        }
        if input
            .window
            .phasor
            .is_below(stack.min_current(input.amplitude))
        {
            state.without_current = state.without_current.saturating_add(1);
            state.previous_error_mhz = 0;
            state.in_lock = 0;
            if state.without_current >= self.config.no_current_windows {
                return Err(ResonanceFault::NoCurrent);
            }
            return Ok(status);
        }
        state.without_current = 0;
        let motional = stack.capacitance().motional(
            input.window.phasor,
            state.tuning.frequency,
            input.amplitude,
        );
        let x = detuning(motional);
        // The error of the loop's own (fine) frequency: the measurement was made at the timer's
        // rounding of it, so estimate f0 = achieved - x f/2Q and compare the command with
        // that. Comparing the achieved frequency instead would feed the timer's grid steps
        // (0.6 Hz near 40 kHz) into the proportional term as a +-Kp step square wave, which
        // the rate bound clips symmetrically into a limit cycle that stops following a drift.
        // |x| <= 16 in Q8.24 and the half-bandwidth < 2^25 mHz: the product fits easily.
        let half_bandwidth = stack.half_bandwidth_mhz(state.tuning.frequency);
        let measured = (i64::from(x.to_bits()) * i64::from(half_bandwidth) + (1 << 23)) >> 24;
        let error = measured + state.command_mhz - i64::from(state.tuning.frequency.millihertz());
        let config = &self.config;
        let proportional =
            (i64::from(config.proportional_q30) * (error - state.previous_error_mhz) + (1 << 29))
                >> 30;
        // Ki T, capped at 1 (2^48): a larger step gain would overshoot every step.
        let gain = (config.integral_per_sample_q48 as u128 * u128::from(input.window.samples))
            .min(1 << 48) as i128;
        let integral = ((gain * i128::from(error) + (1 << 47)) >> 48) as i64;
        let wanted = -(proportional + integral);
        let max_step = config.max_step_mhz(input.window.samples);
        let step = wanted.clamp(-max_step, max_step);
        let target = state.command_mhz + step;
        let command = clamp(target, config);
        // Pinned: at a limit, with the loop asking to go further out.
        if command != target && (wanted > 0) == (target > command) {
            state.at_limit = state.at_limit.saturating_add(1);
        } else {
            state.at_limit = 0;
        }
        if state.at_limit >= config.limit_windows {
            return Err(ResonanceFault::AtFrequencyLimit);
        }
        if x.to_bits().unsigned_abs() <= config.lock_detuning.to_bits().unsigned_abs() {
            state.in_lock = state.in_lock.saturating_add(1);
        } else {
            state.in_lock = 0;
        }
        // The limits are in band, so the timer can always produce the clamped command.
        if let Ok(tuning) = Tuning::nearest(Frequency::from_millihertz(command as u32), self.clock)
        {
            state.tuning = tuning;
            state.command_mhz = command;
        }
        state.previous_error_mhz = error;
        status.tuning = state.tuning;
        status.detuning = x;
        status.motional = motional;
        status.locked = state.in_lock >= config.lock_windows;
        status.rate_limited = step != wanted;
        Ok(status)
    }
}

/// `millihertz` clamped to the loop's limits.
fn clamp(millihertz: i64, config: &TrackerConfig) -> i64 {
    millihertz.clamp(
        i64::from(config.min.millihertz()),
        i64::from(config.max.millihertz()),
    )
}

#[cfg(test)]
#[path = "tracker_tests.rs"]
mod tests;
