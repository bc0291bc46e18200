//! Resonance search: a coarse conductance sweep brackets f0, then the phase loop pulls in on
//! the zero of the motional current's phase and declares lock.
//!
//! 1. **Coarse** ([`Sweep`]): at low amplitude the drive steps up through the band, from one
//!    step below it (steps of one local bandwidth, `f / Q`, so some point is within half a
//!    bandwidth of f0) and on past it for one envelope time constant; the interpolated peak of the conductance brackets f0,
//!    late by the envelope's lag (60-180 Hz on the simulated plant, 360-570 Hz on a complex
//!    envelope, at one bandwidth per 0.2 ms). A mean current over the sweep below the stack's
//!    admittance threshold is [`ResonanceFault::NoCurrent`] (the mean, because the total
//!    current legitimately dips near the parallel resonance, where the motional current
//!    cancels C0's: to 0.017 S for the reference stack, less during a transient); a peak at
//!    either end of the sweep or below that threshold is [`ResonanceFault::NoResonance`]
//!    (except at the last point when 60 kHz cut the overrun short: then the pull-in decides,
//!    and a resonance above 60 kHz ends in [`ResonanceFault::AtFrequencyLimit`]).
//! 2. **Fine** ([`Tracker`] with the pull-in settings): from the bracket, the rate-bounded PI
//!    loop on the motional detuning converges on `x = 0`, which is where both the motional
//!    phase is zero and the conductance peaks (the BVD series resonance). It respects the
//!    envelope's settling: lock is declared only after the detuning has stayed within
//!    `lock_detuning` for one envelope time constant (8 windows at 40 kHz; a lagging phase can
//!    cross zero while the frequency still overshoots). Not locked within the time-out:
//!    [`ResonanceFault::PullInTimeout`].
//!
//! A fine stepped sweep was not used because it cannot respect settling in the time budget:
//! in one direction its peak lags by the sweep rate times `tau`, and dwelling `3 tau` per
//! point takes 2.4 ms a point at 40 kHz. The phase loop needs no bracket finer than a few
//! bandwidths and no knowledge of the lag.

use super::error::{ResonanceError, ResonanceFault};
use super::lockin::{Demodulated, LockInConfig};
use super::stack::{StackModel, StackSettings};
use super::sweep::{Sweep, SweepPlan, SweepProgress, SweepResult};
use super::tracker::{Tracker, TrackerConfig, TrackerSettings};
use super::tuning::Tuning;
use crate::drive::{Amplitude, Frequency, TimerClock};
use crate::fx::Q2_30;

/// How to search (set-up, f64).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SearchSettings {
    /// Lowest frequency f0 may have, Hz (20-60 kHz).
    pub min_hz: f64,
    /// Highest frequency f0 may have, Hz (20-60 kHz, above `min_hz`).
    pub max_hz: f64,
    /// Drive amplitude during the search, fraction of full scale, (0, 1].
    pub amplitude: f64,
    /// Spacing of the coarse points relative to the frequency, in (0, 0.1]: `1 / Q` puts
    /// them one local bandwidth apart.
    pub relative_step: f64,
    /// Lock-in windows discarded at each coarse point.
    pub settle_windows: u16,
    /// Lock-in windows averaged at each coarse point, >= 1.
    pub measure_windows: u16,
    /// End the coarse sweep this many points past its best point once the conductance has
    /// fallen to half the best ([`SweepPlan::stop_past_peak`]); 0 sweeps the whole band.
    pub stop_past_peak: u16,
    /// The pull-in loop; its frequency limits are replaced by the band.
    pub pull_in: TrackerSettings,
    /// Longest pull-in before [`ResonanceFault::PullInTimeout`], s, > 0.
    pub pull_in_timeout_s: f64,
}

impl SearchSettings {
    /// A search for `stack` over f0 `(1 +- relative_band)` (clamped to 20-60 kHz) at a tenth
    /// of full amplitude, coarse points one bandwidth apart (`1 / Q`), at least one window
    /// settled and one measured per point (more on a slow envelope: [`SearchConfig::new`]),
    /// ending two points past the conductance's peak once it has halved, pull-in with
    /// [`TrackerSettings::PULL_IN`] with its gains from the envelope
    /// ([`TrackerSettings::on_resonator`]) for at most twice the pull-in the loop predicts
    /// ([`pull_in_time_s`]).
    pub fn around(stack: &StackSettings, relative_band: f64) -> Self {
        let f0 = stack.resonance_hz;
        let pull_in = TrackerSettings::PULL_IN.on_resonator(f0, stack.quality_factor);
        Self {
            min_hz: (f0 * (1.0 - relative_band)).max(20_000.0),
            max_hz: (f0 * (1.0 + relative_band)).min(60_000.0),
            amplitude: 0.1,
            relative_step: 1.0 / stack.quality_factor,
            settle_windows: 1,
            measure_windows: 1,
            stop_past_peak: 2,
            pull_in,
            pull_in_timeout_s: 2.0 * pull_in_time_s(&pull_in, stack),
        }
    }
}

/// The coarse sweep's lag behind the resonance, bandwidths `f0 / Q`, that
/// [`SearchConfig::new`] allows: the sweep's rate times the envelope time constant.
///
/// Swept at a rate `rho` (Hz/s) the envelope lags the drive by `tau` and the conductance's
/// peak comes `rho tau` late (the quasi-static lag of a first-order envelope). The pull-in
/// starts there, `2 x 2 = 4` half-bandwidths from f0: well inside the range the detuning reads
/// ([`crate::resonance::MAX_DETUNING`], 16) and where the motional phase (76 degrees at `x = 4`) still
/// grows with the error, so the loop's first correction has the right sign and size. A lag of
/// one bandwidth per `tau / 2` of dwell: the sweep takes `Q tau / 2` per unit of relative
/// band (2.4 ms a bandwidth at 20 kHz, Q 300; 0.4 ms at 40 kHz, Q 100). The docs
/// (docs/resonance.md) give the diagnosis that led here: one 4-period window a bandwidth
/// lags `Q / (4 pi)` bandwidths, 24 at Q 300, beyond what the detuning can read.
pub const SWEEP_LAG_BANDWIDTHS: f64 = 2.0;

/// The time the pull-in loop `pull_in` takes on `stack`'s resonator, s: from the sweep's lag
/// ([`SWEEP_LAG_BANDWIDTHS`], `2 x 2` half-bandwidths) to `lock_detuning` at the loop's decay
/// rate ([`TrackerSettings::decay_rate_per_s`]), then the hold of one envelope time
/// constant ([`SearchConfig::new`]).
pub fn pull_in_time_s(pull_in: &TrackerSettings, stack: &StackSettings) -> f64 {
    let tau_s = stack.quality_factor / (core::f64::consts::PI * stack.resonance_hz);
    let start = 2.0 * SWEEP_LAG_BANDWIDTHS;
    let decay = libm::log(start / pull_in.lock_detuning).max(0.0) / pull_in.decay_rate_per_s(tau_s);
    decay + tau_s
}

/// [`SearchSettings`] in fixed point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SearchConfig {
    plan: SweepPlan,
    /// 60 kHz cut the overrun short: a peak at the sweep's last point may then be f0 arriving
    /// late, and the pull-in is allowed to find out.
    overrun_cut: bool,
    amplitude: Amplitude,
    pull_in: TrackerConfig,
    pull_in_timeout_samples: u64,
    /// [`Self::lock_bound_s`] in microseconds.
    lock_bound_us: u32,
}

impl SearchConfig {
    /// The search for `stack` with the lock-in `lock_in`. The sweep starts one step below the
    /// band (so that a resonance at its bottom is a peak with a neighbour on each side) and
    /// ends one nominal envelope time constant of points above it (capped to 20-60 kHz).
    ///
    /// Errors: `Band` for a band outside 20-60 kHz, a relative step outside (0, 0.1] or more
    /// than 10 000 points; `Setting` for an amplitude, dwell or time-out out of range; those of
    /// [`TrackerConfig::new`].
    pub fn new(
        settings: &SearchSettings,
        stack: &StackSettings,
        lock_in: &LockInConfig,
    ) -> Result<Self, ResonanceError> {
        let s = settings;
        let model = StackModel::new(stack)?;
        let band = 20_000.0..=60_000.0;
        let band_ok = band.contains(&s.min_hz) && band.contains(&s.max_hz) && s.min_hz < s.max_hz;
        let step_ok = s.relative_step > 1e-5 && s.relative_step <= 0.1;
        if !(band_ok && step_ok) {
            return Err(ResonanceError::Band);
        }
        let timeout_ok = s.pull_in_timeout_s.is_finite() && s.pull_in_timeout_s > 0.0;
        if !(s.amplitude > 0.0 && s.amplitude <= 1.0) || s.measure_windows == 0 || !timeout_ok {
            return Err(ResonanceError::Setting);
        }
        let fraction = Q2_30::from_f64(s.amplitude).map_err(|_| ResonanceError::Setting)?;
        let amplitude = Amplitude::new(fraction)?;
        let tau_s = stack.quality_factor / (core::f64::consts::PI * stack.resonance_hz);
        let window_s = f64::from(lock_in.periods_per_window) / stack.resonance_hz;
        // Dwell: the sweep's lag, `relative_step Q` bandwidths per point times `tau / point`,
        // at most SWEEP_LAG_BANDWIDTHS; the extra windows settle.
        let lag_dwell_s = s.relative_step * stack.quality_factor * tau_s / SWEEP_LAG_BANDWIDTHS;
        let lag_windows = libm::ceil(lag_dwell_s / window_s - 1e-9).min(f64::from(u16::MAX));
        let settle_windows = s
            .settle_windows
            .max((lag_windows as u16).saturating_sub(s.measure_windows));
        // Overrun: the points swept during one envelope time constant at nominal f0.
        let windows = f64::from(settle_windows) + f64::from(s.measure_windows);
        let point_s = windows * window_s;
        let overrun = libm::ceil(tau_s / point_s);
        let growth = libm::log(1.0 + s.relative_step);
        let start = (s.min_hz / (1.0 + s.relative_step)).max(20_000.0);
        let span = libm::ceil(libm::log(s.max_hz / start) / growth);
        let fit = libm::floor(libm::log(60_000.0 / start) / growth);
        let points = (span + overrun).min(fit) + 1.0;
        let overrun_cut = span + overrun > fit;
        if points > 10_000.0 {
            return Err(ResonanceError::Band);
        }
        let plan = SweepPlan {
            start_mhz: libm::round(start * 1000.0) as u32,
            relative_step_q32: libm::round(s.relative_step * 4_294_967_296.0) as u32,
            points: points as u16,
            settle_windows,
            measure_windows: s.measure_windows,
            stop_past_peak: s.stop_past_peak,
            start_up: overrun.min(f64::from(u16::MAX)) as u16,
            min_peak: model.min_current(amplitude),
        };
        // Lock must hold for one envelope time constant: a lagging motional phase can pass
        // through zero while the frequency is still overshooting.
        let hold = libm::ceil(tau_s / window_s).min(f64::from(u16::MAX)) as u16;
        let pull_in = TrackerSettings {
            min_hz: s.min_hz,
            max_hz: s.max_hz,
            lock_windows: s.pull_in.lock_windows.max(hold),
            ..s.pull_in
        };
        // The rule's time: every point (the lowest frequency's windows are the longest),
        // then the pull-in and its hold.
        let sweep_s = points * windows * f64::from(lock_in.periods_per_window) / start;
        let hold_s = f64::from(hold) * window_s;
        let lock_bound_s = sweep_s + pull_in_time_s(&pull_in, stack) - tau_s + hold_s;
        let pull_in = TrackerConfig::new(&pull_in, model, lock_in.sample_rate_hz)?;
        Ok(Self {
            lock_bound_us: libm::ceil(lock_bound_s * 1e6).min(f64::from(u32::MAX)) as u32,
            plan,
            overrun_cut,
            amplitude,
            pull_in,
            pull_in_timeout_samples: libm::round(
                s.pull_in_timeout_s * f64::from(lock_in.sample_rate_hz),
            ) as u64,
        })
    }

    /// The coarse sweep's points and dwell.
    pub const fn plan(&self) -> SweepPlan {
        self.plan
    }

    /// The drive amplitude during the search.
    pub const fn amplitude(&self) -> Amplitude {
        self.amplitude
    }

    /// The time the search takes to lock by its own rule, s, whichever f0 in the band:
    /// every point of the sweep at its dwell (f0 at the band's top; f0 lower ends the sweep
    /// sooner), then the pull-in from the sweep's lag to the lock band at the loop's decay
    /// rate and the hold of one envelope time constant ([`pull_in_time_s`]). A scene's
    /// target must not ask for vibration before it (`crate::scene::feasibility`).
    pub fn lock_bound_s(&self) -> f64 {
        f64::from(self.lock_bound_us) * 1e-6
    }
}

/// A finished search.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Lock {
    /// The drive setting on resonance (hand it to the operating [`Tracker`]).
    pub tuning: Tuning,
    /// f0 estimated from the last window: the drive frequency minus the measured detuning
    /// times the half-bandwidth, mHz (biased by whatever envelope transient that
    /// window still held: up to about 0.1 half-bandwidth).
    pub resonance: Frequency,
    /// Samples from the start of the search to the lock.
    pub elapsed_samples: u64,
    /// The coarse sweep's result.
    pub sweep: SweepResult,
}

/// What the search asks for after a window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SearchStep {
    /// Drive at this tuning and [`Search::amplitude`] (retune the lock-in if it changed).
    Drive(Tuning),
    /// On resonance.
    Locked(Lock),
    /// No frequency: the fault says why.
    Failed(ResonanceFault),
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum Stage {
    Sweeping(Sweep),
    PullIn {
        tracker: Tracker,
        sweep: SweepResult,
        started: u64,
    },
    Finished(SearchStep),
}

/// A search in progress.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Search {
    config: SearchConfig,
    clock: TimerClock,
    stage: Stage,
    tuning: Tuning,
    elapsed_samples: u64,
    /// Sum over the sweep of |I| (Q2.30 bits) times window samples.
    current_sum: i64,
}

impl Search {
    /// A search at its first coarse point. Error: the timer cannot make a point.
    pub fn new(config: SearchConfig, clock: TimerClock) -> Result<Self, ResonanceError> {
        let sweep = Sweep::new(config.plan, clock)?;
        Ok(Self {
            config,
            clock,
            tuning: sweep.tuning(),
            stage: Stage::Sweeping(sweep),
            elapsed_samples: 0,
            current_sum: 0,
        })
    }

    /// The drive setting to use now (after a fault: the last one; the drive should be off).
    pub const fn tuning(&self) -> Tuning {
        self.tuning
    }

    /// The drive amplitude to use during the search.
    pub const fn amplitude(&self) -> Amplitude {
        self.config.amplitude
    }

    /// Takes a window measured at [`Self::tuning`] and [`Self::amplitude`]. After a lock or
    /// a fault it keeps returning that outcome.
    pub fn update(&mut self, window: &Demodulated) -> SearchStep {
        self.elapsed_samples += u64::from(window.samples);
        let amplitude = self.config.amplitude;
        let stack = self.config.pull_in.stack();
        let mut swept = None;
        let mut step = match &mut self.stage {
            Stage::Finished(step) => return *step,
            Stage::Sweeping(sweep) => {
                // Saturating: only a sweep of more than 2^32 full-scale samples could reach
                // it, and a saturated sum still says "current".
                let weighted = i64::from(window.phasor.polar().amplitude.to_bits())
                    * i64::from(window.samples);
                self.current_sum = self.current_sum.saturating_add(weighted);
                match sweep.update(window).1 {
                    SweepProgress::Drive(tuning) => SearchStep::Drive(tuning),
                    SweepProgress::Done(result) => {
                        swept = Some(result);
                        SearchStep::Drive(sweep.tuning())
                    }
                }
            }
            Stage::PullIn {
                tracker,
                sweep,
                started,
            } => match tracker.update(window, amplitude) {
                Err(fault) => SearchStep::Failed(fault),
                Ok(status) if status.locked => {
                    let error_mhz = (i64::from(status.detuning.to_bits())
                        * i64::from(stack.half_bandwidth_mhz(status.tuning.frequency))
                        + (1 << 23))
                        >> 24;
                    let resonance = i64::from(status.tuning.frequency.millihertz()) - error_mhz;
                    SearchStep::Locked(Lock {
                        tuning: status.tuning,
                        resonance: Frequency::from_millihertz(resonance.max(0) as u32),
                        elapsed_samples: self.elapsed_samples,
                        sweep: *sweep,
                    })
                }
                Ok(_) if self.elapsed_samples - *started > self.config.pull_in_timeout_samples => {
                    SearchStep::Failed(ResonanceFault::PullInTimeout)
                }
                Ok(status) => SearchStep::Drive(status.tuning),
            },
        };
        if let Some(result) = swept {
            step = self.start_pull_in(result, stack);
        }
        match step {
            SearchStep::Drive(tuning) => self.tuning = tuning,
            SearchStep::Locked(lock) => {
                self.tuning = lock.tuning;
                self.stage = Stage::Finished(step);
            }
            SearchStep::Failed(_) => self.stage = Stage::Finished(step),
        }
        step
    }

    fn start_pull_in(&mut self, result: SweepResult, stack: StackModel) -> SearchStep {
        // A connected stack draws at least C0's current nearly everywhere: a mean current
        // below the threshold means nothing is connected.
        let samples = self.elapsed_samples.max(1) as i64;
        let mean_current = self.current_sum / samples;
        if mean_current < i64::from(stack.min_current(self.config.amplitude).to_bits()) {
            return SearchStep::Failed(ResonanceFault::NoCurrent);
        }
        let last = result.best_index + 1 == result.points;
        let interior = result.best_index > 0 && (!last || self.config.overrun_cut);
        if !interior || result.best.conductance < stack.min_current(self.config.amplitude) {
            return SearchStep::Failed(ResonanceFault::NoResonance);
        }
        match Tracker::new(self.config.pull_in, result.peak, self.clock) {
            Ok(tracker) => {
                let tuning = tracker.tuning();
                self.stage = Stage::PullIn {
                    tracker,
                    sweep: result,
                    started: self.elapsed_samples,
                };
                SearchStep::Drive(tuning)
            }
            // The pull-in limits are in band: the timer can make any clamped frequency.
            Err(_) => SearchStep::Failed(ResonanceFault::NoResonance),
        }
    }
}

#[cfg(test)]
#[path = "search_tests.rs"]
mod tests;
