//! Lock-in demodulation of the sampled drive current at the drive frequency.
//!
//! Each current sample `x` (a Q1.31 fraction of the sensor's full scale, straight from
//! [`crate::sense::AdcFormat::normalize`], offset included) is multiplied by `cos` and `sin` of
//! the drive phase at its sampling instant, and the products are summed over a window of whole
//! turns of that phase. The drive phase is a `u32` turn accumulator (`2^32` = one turn) advanced
//! per sample by `round(2^32 f / f_s) mod 2^32`, so undersampled (equivalent-time) schemes work
//! the same way: only the aliased rotation per sample matters.
//!
//! # Formats and headroom
//!
//! | quantity                       | format, unit                     | bound                     |
//! |--------------------------------|----------------------------------|---------------------------|
//! | sample `x`                     | Q1.31, full scale                | [-1, 1)                   |
//! | `cos`, `sin` ([`fx::sin_cos`]) | Q1.31                            | [-1, 1)                   |
//! | product, rounded multiply-high | Q2.30 in an `i64` sum            | 2^30 per sample           |
//! | sums of `x`, `cos`, `sin`      | Q1.31 in `i64`                   | 2^31 per sample           |
//! | window                         | `N` <= 2^20 samples              | sums < 2^52 of 2^63       |
//! | result (2/N) sums              | Q2.30 [`Phasor`], full scale     | [-2, 2), at most 4/pi     |
//!
//! So no sequence of samples can overflow (tested with full-scale square waves of the longest
//! window). Per sample: one `sin_cos` (about 36 instructions), two rounded multiply-highs and
//! five 64-bit adds; no division. Per window: one more `sin_cos` and a few 128-bit products
//! with the precomputed `1/N`.
//!
//! # Accuracy
//!
//! - A DC offset (the mid-scale zero of a unipolar converter) is removed: the window's mean
//!   times the window's sums of `cos` and `sin` is subtracted, because a window that misses a
//!   whole number of turns by up to half a sample would otherwise leak up to `DC / N`.
//! - The `2f` products would leak up to `1/N` of the amplitude through the partial last
//!   sample; the window's sum of `exp(2 j theta)`, known in closed form, corrects them to
//!   first order (`finish`), leaving errors of order `1/N^2`. Harmonics up to the Nyquist
//!   rate leak about `1/N` of their own amplitude (not corrected: the output inductor keeps
//!   them small). The tests measure all of these.
//! - Harmonics of order `f_s/f +- 1` alias onto the fundamental: the sense chain's bandwidth
//!   (and the output inductor) must attenuate them.
//! - The sense chain's delay (amplifier, sample-and-hold) is compensated by delaying the
//!   reference by the same time; uncompensated it reads as a phase lag `2 pi f t_d`.

use super::error::ResonanceError;
use super::phasor::Phasor;
use crate::control::SampleBlock;
use crate::drive::Frequency;
use crate::fx::{self, Q1_31, Q2_30, mul_hi_round};

/// Longest demodulation window, samples (2^20: one second at 1 MSPS), which bounds the sums.
pub const MAX_WINDOW_SAMPLES: u32 = 1 << 20;

/// How the current is sampled and demodulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LockInConfig {
    /// Current-sense ADC sampling rate, Hz (> 0). At least 3 samples per turn of the aliased
    /// drive phase are needed.
    pub sample_rate_hz: u32,
    /// Whole turns of the reference phase per window, >= 1 (with `f < f_s/2`: drive periods).
    pub periods_per_window: u16,
    /// Delay of the current-sense chain (amplifier group delay, sample-and-hold), ns.
    pub sense_delay_ns: u32,
}

/// One finished window: the current's fundamental and how many samples it took.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Demodulated {
    /// The fundamental relative to the drive voltage, fraction of full scale.
    pub phasor: Phasor,
    /// Samples in the window (its duration is `samples / f_s`).
    pub samples: u32,
}

/// The lock-in's configuration at one drive frequency: what [`LockIn::retune`] derives from
/// the settings and the frequency. `Copy`, replaced whole at a retune (between two samples),
/// never changed by a sample; the block of [`SampleBlock`] whose state is [`LockInSums`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Demodulator {
    /// Drive phase advance per sample, turns x 2^32 (aliased).
    step: u32,
    /// Phase of the drive over the sense delay, turns x 2^32.
    delay: u32,
    /// Samples per window, 1 to [`MAX_WINDOW_SAMPLES`].
    window: u32,
    /// `round(2^62 / window)`.
    inv_window_q62: i64,
    /// `sin(N step) / sin(step)`, Q2.30 in [-1, 1]: the size of the window's sum of
    /// `exp(2 j theta)` (see `finish`).
    double_sum_q30: i64,
}

/// The lock-in's state: the drive phase and the running sums of the window under way.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LockInSums {
    /// Drive phase at the next sample, turns x 2^32.
    drive_phase: u32,
    /// Reference phase (drive minus delay) at the window's first sample, turns x 2^32.
    window_start: u32,
    /// Samples taken in this window, below the window's length.
    count: u32,
    /// Sums of the products, Q2.30, and of `x`, `cos`, `sin`, Q1.31 (bounds: module doc).
    sum_x_cos: i64,
    sum_x_sin: i64,
    sum_x: i64,
    sum_cos: i64,
    sum_sin: i64,
}

/// The lock-in demodulator: its settings, the [`Demodulator`] at the present frequency and
/// the [`LockInSums`] it runs on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LockIn {
    config: LockInConfig,
    /// PWM-synchronous sampling ([`Self::synchronous`]): the reference's advance per sample
    /// is this, whatever the drive frequency.
    fixed_step: Option<u32>,
    demodulator: Demodulator,
    sums: LockInSums,
}

impl LockIn {
    /// A demodulator for samples taken synchronously to the drive's PWM: one per PWM period,
    /// the trigger's phase within the period advancing by `phase_step` turns x 2^32 from one
    /// period to the next (the G474 plan: TIM1's CCR4 stepped through `0, 1/4, 1/2, 3/4` of
    /// the period, `phase_step = 2^30`). The drive phase then advances by exactly
    /// `phase_step` per sample at any drive frequency, so a window of `periods_per_window`
    /// turns of it is `periods_per_window 2^32 / phase_step` samples (4 at a quarter turn:
    /// four PWM periods, 100 us at 40 kHz). `config.sample_rate_hz` is then the nominal
    /// rate (one sample per period at the stack's nominal f0): the search and the tracker
    /// use it for their time constants, which are off by the ratio of the drive to the
    /// nominal frequency (at most 10 % over +-10 %). Errors: see [`Self::retune`]
    /// (`SamplingTooSlow` for a step of more than a third of a turn either way).
    pub fn synchronous(
        config: LockInConfig,
        drive: Frequency,
        phase_step: u32,
    ) -> Result<Self, ResonanceError> {
        Self::build(config, drive, Some(phase_step))
    }

    /// A demodulator for a drive at `drive` (the frequency the timer really produces), with
    /// the drive phase 0 at the first sample. Errors: see [`Self::retune`].
    pub fn new(config: LockInConfig, drive: Frequency) -> Result<Self, ResonanceError> {
        Self::build(config, drive, None)
    }

    fn build(
        config: LockInConfig,
        drive: Frequency,
        fixed_step: Option<u32>,
    ) -> Result<Self, ResonanceError> {
        let mut lock_in = Self {
            config,
            fixed_step,
            // Set by `retune`: `inv_window_q62 == 0` marks a demodulator not yet set up.
            demodulator: Demodulator {
                step: 0,
                delay: 0,
                window: 1,
                inv_window_q62: 0,
                double_sum_q30: 0,
            },
            sums: LockInSums::default(),
        };
        lock_in.retune(drive)?;
        Ok(lock_in)
    }

    /// Follows the drive to `drive` (the achieved frequency): a new [`Demodulator`]. Any
    /// partial window is discarded (it mixed two frequencies); the drive phase carries on, as
    /// the timer's does. On error nothing changes. A few 64/128-bit divisions: for a control
    /// step, not for every sample.
    ///
    /// Errors: `SamplingTooSlow` for fewer than 3 samples per turn of the aliased drive phase,
    /// `WindowLength` for zero periods or a window above [`MAX_WINDOW_SAMPLES`].
    pub fn retune(&mut self, drive: Frequency) -> Result<(), ResonanceError> {
        // Synchronous sampling without a sense delay: nothing depends on the frequency once
        // the window is set up (`inv_window_q62 != 0`), so a retune only starts a new window.
        if self.fixed_step.is_some()
            && self.config.sense_delay_ns == 0
            && self.demodulator.inv_window_q62 != 0
        {
            self.demodulator.clear(&mut self.sums);
            return Ok(());
        }
        self.demodulator = Demodulator::at(&self.config, self.fixed_step, drive)?;
        self.demodulator.clear(&mut self.sums);
        Ok(())
    }

    /// Sets the drive phase at the next sample (turns x 2^32, 0 = voltage maximum), for boards
    /// and simulations that know it, and discards any partial window.
    pub fn set_drive_phase(&mut self, turns: u32) {
        self.sums.drive_phase = turns;
        self.demodulator.clear(&mut self.sums);
    }

    /// Samples per window at the present frequency.
    pub const fn window_samples(&self) -> u32 {
        self.demodulator.window
    }

    /// The settings.
    pub const fn config(&self) -> LockInConfig {
        self.config
    }

    /// Takes one current sample (Q1.31 fraction of full scale); at the end of each window
    /// returns the fundamental and starts the next window: the [`Demodulator`]'s
    /// [`SampleBlock::process`] on this lock-in's sums. Fixed point, no division.
    #[inline]
    pub fn push(&mut self, sample: Q1_31) -> Option<Demodulated> {
        self.demodulator.process(&mut self.sums, sample)
    }
}

impl Demodulator {
    /// The demodulator of `config` for a drive at `drive` (the achieved frequency), the
    /// reference advancing by `fixed_step` per sample when given. Errors: see
    /// [`LockIn::retune`].
    fn at(
        config: &LockInConfig,
        fixed_step: Option<u32>,
        drive: Frequency,
    ) -> Result<Self, ResonanceError> {
        let rate = u128::from(config.sample_rate_hz) * 1000;
        if rate == 0 {
            return Err(ResonanceError::SamplingTooSlow);
        }
        let millihertz = u128::from(drive.millihertz());
        // Turns per sample x 2^32, rounded, reduced to the aliased rotation (or the fixed
        // advance of PWM-synchronous sampling).
        let step = match fixed_step {
            Some(step) => step,
            None => (((millihertz << 32) + rate / 2) / rate) as u32,
        };
        let rotation = u64::from((step as i32).unsigned_abs());
        if rotation == 0 || rotation * 3 > 1 << 32 {
            return Err(ResonanceError::SamplingTooSlow);
        }
        let turns = u64::from(config.periods_per_window);
        let window = ((turns << 32) + rotation / 2) / rotation;
        if turns == 0 || window > u64::from(MAX_WINDOW_SAMPLES) {
            return Err(ResonanceError::WindowLength);
        }
        // f t_d in turns x 2^32: mHz * ns * 2^32 / 1e12, rounded; f < 2^32 mHz and
        // t_d < 2^32 ns keep the product below 2^96.
        let delay_turns = (millihertz * u128::from(config.sense_delay_ns)) << 32;
        let delay = ((delay_turns + 500_000_000_000) / 1_000_000_000_000) as u32;
        // sin(N step) = sin(residual), |residual| <= step / 2, so the ratio is at most
        // 1 / (2 cos(step / 2)) <= 1 for step <= 2 pi / 3; sin(step) != 0 since rotation != 0
        // and < 1/3 turn.
        let sin_n_step = i64::from(fx::sin(step.wrapping_mul(window as u32)).to_bits());
        let sin_step = i64::from(fx::sin(step).to_bits());
        let ratio = (sin_n_step << 30) / sin_step;
        Ok(Self {
            step,
            delay,
            window: window as u32,
            inv_window_q62: (((1u64 << 62) + window / 2) / window) as i64,
            double_sum_q30: ratio.clamp(-(1 << 30), 1 << 30),
        })
    }

    /// Scales the window's sums into a phasor (once per window): the least-squares fit of
    /// `dc + a cos - b sin` to the window, to first order in `1/N`.
    ///
    /// With `C2 + j S2 = sum exp(2 j theta_k) = exp(j (2 theta_0 + (N - 1) step)) sin(N
    /// step) / sin(step)` (a geometric series, |C2 + j S2| <= 1), the normal equations are
    /// `X_c = a (N + C2) / 2 - b S2 / 2` and `X_s = a S2 / 2 - b (N - C2) / 2` for the
    /// offset-free sums `X_c`, `X_s`; their inverse to first order is
    /// `a = (2/N) (X_c - (C2 X_c + S2 X_s) / N)`, `b = -(2/N) (X_s + (C2 X_s - S2 X_c) / N)`.
    /// What is left is of order `1/N^2` (a window missing whole turns by half a sample errs by
    /// up to `1/N` without this).
    fn finish(&self, sums: &LockInSums) -> Demodulated {
        let inv = i128::from(self.inv_window_q62);
        let per_window = |v: i128| (v * inv + (1 << 61)) >> 62; // v / N
        // Window mean of x, Q1.31 bits (|mean| <= 2^31).
        let mean = per_window(i128::from(sums.sum_x));
        // Offset-free sums: the mean times the sum of cos is Q1.31 x Q1.31, brought to the
        // Q2.30 scale of the products by 2^-32.
        let x_cos =
            i128::from(sums.sum_x_cos) - ((mean * i128::from(sums.sum_cos) + (1 << 31)) >> 32);
        let x_sin =
            i128::from(sums.sum_x_sin) - ((mean * i128::from(sums.sum_sin) + (1 << 31)) >> 32);
        let angle = sums
            .window_start
            .wrapping_mul(2)
            .wrapping_add(self.step.wrapping_mul(self.window.wrapping_sub(1)));
        let (sin2, cos2) = fx::sin_cos(angle);
        let size = i128::from(self.double_sum_q30);
        // C2, S2 in Q2.30 (Q1.31 x Q2.30 >> 31).
        let c2 = (i128::from(cos2.to_bits()) * size + (1 << 30)) >> 31;
        let s2 = (i128::from(sin2.to_bits()) * size + (1 << 30)) >> 31;
        let a_sum = x_cos - per_window((c2 * x_cos + s2 * x_sin + (1 << 29)) >> 30);
        let b_sum = -x_sin - per_window((c2 * x_sin - s2 * x_cos + (1 << 29)) >> 30);
        // (2 / N) sum: inv is 2^62 / N, so shift by 61.
        let in_phase = saturate((a_sum * inv + (1 << 60)) >> 61);
        let quadrature = saturate((b_sum * inv + (1 << 60)) >> 61);
        Demodulated {
            phasor: Phasor::new(in_phase, quadrature),
            samples: sums.count,
        }
    }

    /// Starts a new window at the next sample.
    fn clear(&self, sums: &mut LockInSums) {
        sums.window_start = sums.drive_phase.wrapping_sub(self.delay);
        sums.count = 0;
        sums.sum_x_cos = 0;
        sums.sum_x_sin = 0;
        sums.sum_x = 0;
        sums.sum_cos = 0;
        sums.sum_sin = 0;
    }
}

/// The lock-in: one current sample (Q1.31 fraction of full scale) into the window's sums; at
/// the end of each window the fundamental, and the next window starts. Fixed point, no
/// division; never overflows (module doc).
impl SampleBlock<Q1_31> for Demodulator {
    type State = LockInSums;
    type Output = Option<Demodulated>;

    #[inline]
    fn process(&self, sums: &mut LockInSums, sample: Q1_31) -> Option<Demodulated> {
        let (sin, cos) = fx::sin_cos(sums.drive_phase.wrapping_sub(self.delay));
        let (x, sin, cos) = (sample.to_bits(), sin.to_bits(), cos.to_bits());
        sums.sum_x_cos += i64::from(mul_hi_round(x, cos));
        sums.sum_x_sin += i64::from(mul_hi_round(x, sin));
        sums.sum_x += i64::from(x);
        sums.sum_cos += i64::from(cos);
        sums.sum_sin += i64::from(sin);
        sums.drive_phase = sums.drive_phase.wrapping_add(self.step);
        sums.count += 1;
        if sums.count < self.window {
            return None;
        }
        let result = self.finish(sums);
        self.clear(sums);
        Some(result)
    }
}

/// A Q2.30 component, clamped (only a pathological window reaches +-2).
fn saturate(bits: i128) -> Q2_30 {
    Q2_30::from_bits(bits.clamp(i128::from(i32::MIN), i128::from(i32::MAX)) as i32)
}

#[cfg(test)]
#[path = "lockin_tests.rs"]
mod tests;
