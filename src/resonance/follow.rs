//! The resonance loop of a running station: `freq auto` (search, then track) or `freq HZ`
//! (pinned), fed by current samples taken synchronously to the drive's PWM.
//!
//! # Samples
//!
//! One current sample per PWM period, its trigger's phase within the period advancing a
//! quarter turn from one period to the next ([`SYNCHRONOUS_PHASE_STEP`]): the phases repeat
//! `1/8, 3/8, 5/8, 7/8` of the period (an eighth off the period's start, where the high side
//! switches on). This is what TIM1 can trigger on the G474 (one ADC conversion per period on
//! TRGO2 = OC4REF, CCR4 rewritten each period from a four-entry table), and what the QEMU
//! board's simulated plant gives (`sonolube_sim::plant`). The reference phase of sample `k` is
//! `k / 4` turn whatever the drive frequency, so a frequency change never disturbs it
//! ([`LockIn::synchronous`]); a window of one reference turn is four samples (100 us at
//! 40 kHz), the window the search and the tracker were tuned for.
//!
//! Samples are Q1.31 fractions of the current sense's full scale, mid-scale removed
//! ([`current_sample`] converts 12-bit codes).
//!
//! # Modes
//!
//! - **Pinned** (`freq HZ`, the default): the drive stays where it is set; every window still
//!   measures the motional current's detuning, so `status` reports how far off resonance
//!   the pinned frequency is.
//! - **Searching** ([`ResonanceLoop::search`]): the [`Search`] runs at its own low amplitude
//!   ([`ResonanceLoop::search_amplitude`]) until it locks; then
//! - **Tracking**: the operating [`Tracker`] follows the resonance at whatever amplitude the
//!   friction loop drives.
//! - **Lost**: the search failed, the tracker faulted, or the tracker stayed unlocked for
//!   [`LOST_WINDOWS`] windows in a row; the station latches the supervisor's
//!   `resonance-lost` fault and the drive holds its last frequency.
//!
//! # Cost
//!
//! Per sample one `sin_cos` and a few multiply-adds ([`LockIn::push`]); per window (every
//! fourth sample) a CORDIC, one division and [`Tuning::nearest`]'s division; a retune of the
//! synchronous lock-in only clears its sums. Measured in the control step on QEMU (README).

use super::error::{ResonanceError, ResonanceFault};
use super::lockin::{Demodulated, LockIn, LockInConfig};
use super::motional::detuning;
use super::phasor::{Angle, Phasor};
use super::search::{Search, SearchConfig, SearchSettings, SearchStep};
use super::stack::{StackModel, StackSettings};
use super::tracker::{Tracker, TrackerConfig, TrackerSettings};
use super::tuning::Tuning;
use crate::drive::{Amplitude, Frequency, TimerClock};
use crate::fx::{Q1_31, Q8_24};

/// Advance of the sampling phase per PWM period, turns x 2^32: a quarter turn.
pub const SYNCHRONOUS_PHASE_STEP: u32 = 1 << 30;

/// Samples (PWM periods) per turn of the synchronous reference.
const SYNCHRONOUS_SAMPLES_PER_TURN: u32 = 4;

/// Phase of the first sample within its PWM period, turns x 2^32: an eighth of a period.
pub const SYNCHRONOUS_FIRST_PHASE: u32 = 1 << 29;

/// Consecutive unlocked tracking windows that count as a lost resonance (20 ms at 40 kHz).
pub const LOST_WINDOWS: u16 = 200;

/// The Q1.31 sample of a 12-bit current-sense code (mid-scale 2048 is zero current; a code
/// above 4095 is clamped to full scale, since a converter cannot produce it).
pub const fn current_sample(code: u16) -> Q1_31 {
    let code = if code > 4095 { 4095 } else { code };
    Q1_31::from_bits((code as i32 - 2048) << 20)
}

/// How the station runs its resonance loop (set-up, f64).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResonanceSettings {
    /// The stack and the current sense.
    pub stack: StackSettings,
    /// The search of `freq auto`.
    pub search: SearchSettings,
    /// The tracker in operation.
    pub tracker: TrackerSettings,
}

impl ResonanceSettings {
    /// For `stack`: search over its f0 +- 10 % with one window per coarse point, track with
    /// the operating loop over the same band at a correction rate of up to 500 kHz/s (50 Hz
    /// per window: a load step moving f0 by 0.5 %, 200 Hz, is caught up in 4 windows; at
    /// 50 kHz/s the `resonance-drift` scene's RMS friction error was 1.57 % instead of 0.61 %).
    pub fn around(stack: &StackSettings) -> Self {
        let search = SearchSettings {
            settle_windows: 0,
            ..SearchSettings::around(stack, 0.1)
        };
        let tracker = TrackerSettings {
            min_hz: search.min_hz,
            max_hz: search.max_hz,
            integral_per_s: TrackerSettings::OPERATION
                .on_resonator(stack.resonance_hz, stack.quality_factor)
                .integral_per_s,
            max_rate_hz_per_s: 500_000.0,
            ..TrackerSettings::OPERATION
        };
        Self {
            stack: *stack,
            search,
            tracker,
        }
    }

    /// The search's configuration as [`ResonanceLoop::new`] builds it: its dwell, overrun
    /// and hold reckoned in synchronous windows of four PWM periods at the nominal f0.
    fn search_config(&self) -> Result<SearchConfig, ResonanceError> {
        let nominal_hz = libm::round(self.stack.resonance_hz) as u32;
        let windows_in_periods = LockInConfig {
            sample_rate_hz: nominal_hz,
            periods_per_window: SYNCHRONOUS_SAMPLES_PER_TURN as u16,
            sense_delay_ns: 0,
        };
        SearchConfig::new(&self.search, &self.stack, &windows_in_periods)
    }

    /// The time `freq auto`'s search takes to lock by its rule, s, for any f0 in its band
    /// ([`SearchConfig::lock_bound_s`]). Errors: those of [`ResonanceLoop::new`].
    pub fn search_lock_bound_s(&self) -> Result<f64, ResonanceError> {
        Ok(self.search_config()?.lock_bound_s())
    }
}

/// What the loop is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LockState {
    /// `freq HZ`: the frequency is pinned.
    Pinned,
    /// `freq auto`: searching.
    Searching,
    /// `freq auto`: tracking, not (yet) locked.
    Tracking,
    /// `freq auto`: tracking and locked.
    Locked,
    /// `freq auto`: the resonance was lost (the fault says how).
    Lost(ResonanceFault),
}

impl LockState {
    /// The protocol word (`status` and telemetry).
    pub const fn name(self) -> &'static str {
        match self {
            LockState::Pinned => "pinned",
            LockState::Searching => "searching",
            LockState::Tracking => "tracking",
            LockState::Locked => "locked",
            LockState::Lost(_) => "lost",
        }
    }
}

/// The last window's measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResonanceReport {
    /// The mode and lock.
    pub state: LockState,
    /// The drive frequency in force.
    pub frequency: Frequency,
    /// The motional current relative to the voltage, full scale; its phase is the phase error
    /// (zero on resonance, [`Self::phase`]); `None` before the first window with current.
    pub motional: Option<Phasor>,
    /// The motional detuning `(f - f0) / (f0 / 2Q)`, half-bandwidths; `None` as `phase`.
    pub detuning: Option<Q8_24>,
}

impl ResonanceReport {
    /// The phase error: the motional current's phase to the voltage (a CORDIC, for reports);
    /// `None` when no window with current was measured.
    pub fn phase(&self) -> Option<Angle> {
        self.motional.map(|m| m.polar().phase)
    }
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum Stage {
    Pinned,
    Searching(Search),
    Tracking { tracker: Tracker, unlocked: u16 },
    Lost(ResonanceFault),
}

/// The loop: lock-in, stage and the last report.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ResonanceLoop {
    stack: StackModel,
    search: SearchConfig,
    tracker: TrackerConfig,
    clock: TimerClock,
    lock_in: LockIn,
    stage: Stage,
    tuning: Tuning,
    report: ResonanceReport,
}

impl ResonanceLoop {
    /// A pinned loop at `start` on a timer clocked at `clock`. Errors: a setting refused.
    pub fn new(
        settings: &ResonanceSettings,
        start: Frequency,
        clock: TimerClock,
    ) -> Result<Self, ResonanceError> {
        let stack = StackModel::new(&settings.stack)?;
        // One sample per PWM period at the nominal f0: the rate the gains are scaled for.
        let nominal_hz = libm::round(settings.stack.resonance_hz) as u32;
        let lock_in = LockInConfig {
            sample_rate_hz: nominal_hz,
            periods_per_window: 1,
            sense_delay_ns: 0,
        };
        // The search reckons its dwell, overrun and lock hold in windows of
        // `periods_per_window` drive periods: a synchronous window of one reference turn is
        // four PWM periods.
        let search = settings.search_config()?;
        let tracker = TrackerConfig::new(&settings.tracker, stack, nominal_hz)?;
        let tuning = Tuning::nearest(start, clock)?;
        let mut lock_in = LockIn::synchronous(lock_in, tuning.frequency, SYNCHRONOUS_PHASE_STEP)?;
        lock_in.set_drive_phase(SYNCHRONOUS_FIRST_PHASE);
        Ok(Self {
            stack,
            search,
            tracker,
            clock,
            lock_in,
            stage: Stage::Pinned,
            tuning,
            report: ResonanceReport {
                state: LockState::Pinned,
                frequency: tuning.frequency,
                motional: None,
                detuning: None,
            },
        })
    }

    /// `freq HZ`: pins the drive at the timer's nearest to `frequency`. Error: the timer
    /// cannot make it (nothing changes).
    pub fn pin(&mut self, frequency: Frequency) -> Result<(), ResonanceError> {
        let tuning = Tuning::nearest(frequency, self.clock)?;
        self.lock_in.retune(tuning.frequency)?;
        self.tuning = tuning;
        self.stage = Stage::Pinned;
        self.report = ResonanceReport {
            state: LockState::Pinned,
            frequency: tuning.frequency,
            motional: None,
            detuning: None,
        };
        Ok(())
    }

    /// `freq auto`: starts a search from its first coarse point. Error: the timer cannot make
    /// it (nothing changes).
    pub fn search(&mut self) -> Result<(), ResonanceError> {
        let search = Search::new(self.search, self.clock)?;
        let tuning = search.tuning();
        self.lock_in.retune(tuning.frequency)?;
        self.tuning = tuning;
        self.stage = Stage::Searching(search);
        self.report = ResonanceReport {
            state: LockState::Searching,
            frequency: tuning.frequency,
            motional: None,
            detuning: None,
        };
        Ok(())
    }

    /// Whether a search runs (the drive must then be [`Self::search_amplitude`]).
    pub fn is_searching(&self) -> bool {
        matches!(self.stage, Stage::Searching(_))
    }

    /// The drive amplitude of the search.
    pub fn search_amplitude(&self) -> Amplitude {
        self.search.amplitude()
    }

    /// The drive setting in force.
    pub const fn tuning(&self) -> Tuning {
        self.tuning
    }

    /// The last report.
    pub const fn report(&self) -> ResonanceReport {
        self.report
    }

    /// Takes the current samples of one control period, measured with the drive at
    /// `amplitude` (the amplitude applied over that period). Returns the fault when the
    /// resonance is lost in this call (once; the loop then stays lost until `freq`).
    pub fn push(&mut self, samples: &[Q1_31], amplitude: Amplitude) -> Result<(), ResonanceFault> {
        for &sample in samples {
            if let Some(window) = self.lock_in.push(sample) {
                self.window(&window, amplitude)?;
            }
        }
        Ok(())
    }

    fn window(&mut self, window: &Demodulated, amplitude: Amplitude) -> Result<(), ResonanceFault> {
        let next = match &mut self.stage {
            Stage::Lost(_) => return Ok(()),
            Stage::Pinned => {
                self.measure(window, amplitude);
                return Ok(());
            }
            Stage::Searching(search) => match search.update(window) {
                SearchStep::Drive(tuning) => {
                    self.report.state = LockState::Searching;
                    Ok(tuning)
                }
                SearchStep::Locked(lock) => {
                    match Tracker::new(self.tracker, lock.tuning.frequency, self.clock) {
                        Ok(tracker) => {
                            let tuning = tracker.tuning();
                            self.stage = Stage::Tracking {
                                tracker,
                                unlocked: 0,
                            };
                            self.report.state = LockState::Locked;
                            Ok(tuning)
                        }
                        // The tracker's band is the search's: it takes any lock.
                        Err(_) => Err(ResonanceFault::NoResonance),
                    }
                }
                SearchStep::Failed(fault) => Err(fault),
            },
            Stage::Tracking { tracker, unlocked } => match tracker.update(window, amplitude) {
                Ok(status) => {
                    // With the drive off nothing is measured and the frequency holds: such
                    // windows do not count toward a lost resonance (the friction loop may ask
                    // for no vibration for as long as it likes after the search locked;
                    // before, 200 such windows latched `resonance-lost`).
                    *unlocked = if status.locked {
                        0
                    } else if amplitude == Amplitude::ZERO {
                        *unlocked
                    } else {
                        unlocked.saturating_add(1)
                    };
                    self.report.state = if status.locked {
                        LockState::Locked
                    } else {
                        LockState::Tracking
                    };
                    if amplitude != Amplitude::ZERO {
                        self.report.motional = Some(status.motional);
                        self.report.detuning = Some(status.detuning);
                    }
                    if *unlocked >= LOST_WINDOWS {
                        Err(ResonanceFault::PullInTimeout)
                    } else {
                        Ok(status.tuning)
                    }
                }
                Err(fault) => Err(fault),
            },
        };
        match next {
            Ok(tuning) => {
                if tuning != self.tuning {
                    // The synchronous lock-in's reference does not depend on the frequency:
                    // a retune only starts a new window, and cannot fail.
                    let _ = self.lock_in.retune(tuning.frequency);
                    self.tuning = tuning;
                    self.report.frequency = tuning.frequency;
                }
                Ok(())
            }
            Err(fault) => {
                self.stage = Stage::Lost(fault);
                self.report.state = LockState::Lost(fault);
                Err(fault)
            }
        }
    }

    /// Pinned: the motional current's phase and detuning, for the report only.
    fn measure(&mut self, window: &Demodulated, amplitude: Amplitude) {
        if amplitude == Amplitude::ZERO || window.phasor.is_below(self.stack.min_current(amplitude))
        {
            return;
        }
        let motional =
            self.stack
                .capacitance()
                .motional(window.phasor, self.tuning.frequency, amplitude);
        self.report.motional = Some(motional);
        self.report.detuning = Some(detuning(motional));
    }
}

#[cfg(test)]
#[path = "follow_tests.rs"]
mod tests;
