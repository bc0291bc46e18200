//! Resonance search and tracking: keeps the half-bridge on the stack's motional resonance.
//!
//! # The chain
//!
//! 1. The current-sense ADC samples the drive current at `f_s` (any rate with at least 3
//!    samples per turn of the aliased drive phase; the tests use 1 MSPS and 250 kSPS). Each
//!    reading, normalised to a Q1.31 fraction of full scale ([`crate::sense::AdcFormat`],
//!    offset and all), goes to [`LockIn::push`].
//! 2. Every window of whole drive periods (4 by default: 100 us at 40 kHz) the lock-in returns
//!    the current's fundamental relative to the drive voltage ([`Demodulated`], a [`Phasor`]).
//! 3. [`Search`] (at start-up, at low amplitude) turns windows into drive settings
//!    ([`Tuning`]: a TIM1 period from [`crate::drive::PwmPeriod`] and the frequency it really
//!    produces) until [`SearchStep::Locked`] or [`SearchStep::Failed`].
//! 4. [`Tracker`] (in operation, at any amplitude) keeps the drive on the resonance as it
//!    drifts, with a bounded correction rate, or reports a [`ResonanceFault`].
//!
//! After every window the caller writes the new period to the timer and calls
//! [`LockIn::retune`] with the tuning's frequency (boards that know the drive phase at the
//! next sample also call [`LockIn::set_drive_phase`]).
//!
//! # Criterion
//!
//! The Butterworth-Van Dyke model puts C0 in parallel with the motional branch; the vibration
//! peaks at the motional (series) resonance, where the motional current is in phase with the
//! voltage and the conductance `Re(I/V)` peaks. The V-I phase zero of the *total* current is
//! not there: C0's quadrature current moves it 48 Hz (0.12 %) above f0 for the reference stack,
//! or removes it when `w C0 R1 > 1/2`. So:
//! - the coarse sweep looks for the peak of the conductance (in-phase current), which C0
//!   cannot touch because its current is purely in quadrature ([`Sweep`]);
//! - the phase loop zeroes the motional current's phase, `I - j w C0 V` with C0 from the
//!   stack's data ([`ClampedCapacitance`]); a C0 wrong by 10 % biases it by 4.7 Hz.
//!
//! Both are the same point of the model; the sweep needs no C0 and survives its transients,
//! the loop needs no sweep and reads the frequency error directly: the detuning
//! `x = -Im/Re = Q (f/f0 - f0/f)` of the motional current ([`detuning`]).
//!
//! # Formats
//!
//! | quantity                          | type, format                | unit, range                        |
//! |-----------------------------------|-----------------------------|------------------------------------|
//! | current sample                    | `Q1_31`                     | full scale, [-1, 1)                |
//! | drive phase, reference            | `u32` turns                 | 2^32 = one turn, wraps             |
//! | lock-in sums                      | `i64`, Q2.30 and Q1.31      | window <= 2^20 samples, < 2^52     |
//! | [`Phasor`] components             | `Q2_30`                     | full scale, [-2, 2)                |
//! | [`Polar`] amplitude / [`Angle`]   | `Q2_30` / `i32` binary angle| [0, 2) / [-pi, pi), 1.46e-9 rad    |
//! | detuning                          | `Q8_24`                     | half-bandwidths, +-16              |
//! | frequencies                       | [`crate::drive::Frequency`] | mHz, `u32`                         |
//! | loop gains, rate bound            | Q2.30, Q16.48, Q.16         | per window, per sample             |
//!
//! Per sample: one `sin_cos`, two multiply-highs, five 64-bit adds, no division (about 55
//! instructions estimated from `fx`'s measured 36 for `sin_cos`; not yet measured on the
//! target: at 1 MSPS that is a third of the 170 MHz Cortex-M4, at 250 kSPS a twelfth, which
//! is why the tests also run at 250 kSPS). Per window: a CORDIC, one `sin_cos`, one division (the detuning), a few
//! 128-bit products and [`Tuning::nearest`]'s division. Floating point only in the `new`
//! functions of the settings.
//!
//! # Numbers
//!
//! Lock times, lock accuracy and tracking error against the simulated transducer, with the
//! command that measures them: `docs/resonance.md`.

mod error;
mod follow;
mod lockin;
mod motional;
mod phasor;
mod ringdown;
mod search;
mod stack;
mod sweep;
#[cfg(test)]
mod testkit;
mod tracker;
mod tuning;

pub use error::{ResonanceError, ResonanceFault};
pub use follow::{
    LOST_WINDOWS, LockState, ResonanceLoop, ResonanceReport, ResonanceSettings,
    SYNCHRONOUS_FIRST_PHASE, SYNCHRONOUS_PHASE_STEP, current_sample,
};
pub use lockin::{Demodulated, Demodulator, LockIn, LockInConfig, LockInSums, MAX_WINDOW_SAMPLES};
pub use motional::{ClampedCapacitance, MAX_DETUNING, detuning};
pub use phasor::{Angle, Phasor, Polar};
pub use ringdown::{
    MIN_RING_DOWN_POINTS, MIN_RING_DOWN_START_LSB, RING_DOWN_FLOOR_LSB,
    RING_DOWN_SPAN_TIME_CONSTANTS, RingDownError, RingDownFit, RingDownSums, fit_ring_down,
    group_amplitude_lsb, group_amplitude_squared,
};
pub use search::{
    Lock, SWEEP_LAG_BANDWIDTHS, Search, SearchConfig, SearchSettings, SearchStep, pull_in_time_s,
};
pub use stack::{StackModel, StackSettings};
pub use sweep::{Sweep, SweepPlan, SweepPoint, SweepProgress, SweepResult};
pub use tracker::{
    LOOP_DAMPING, TrackStatus, TrackWindow, Tracker, TrackerConfig, TrackerSettings, TrackerState,
    TrackingLoop,
};
pub use tuning::Tuning;
