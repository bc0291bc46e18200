//! The coarse sweep: the drive steps upward through a band, dwelling at each point, and the
//! conductance (the in-phase current) is recorded; its peak, interpolated, brackets f0.
//!
//! The points are spaced by a constant *fraction* of the frequency (`f_(k+1) = f_k (1 + r)`),
//! because the resonance's bandwidth `f0 / Q` is proportional to f0: with `r = 1/Q` every
//! point is one local bandwidth from the next over any band (200 Hz at 20 kHz, 600 Hz at
//! 60 kHz), so some point is always within half a bandwidth of f0.
//!
//! Criterion: the peak of the *conductance* `Re I / V`, not of `|I|`. C0's current is purely
//! in quadrature, so the conductance is the motional branch's alone, `G0 / (1 + x^2)`, whose
//! peak is the series resonance whatever C0 is, even in a transient (the capacitive current
//! has no in-phase part at any instant). `|I|` would peak off f0 by C0's share.
//!
//! Settling: at each point the first `settle` lock-in windows are discarded and the next
//! `measure` windows averaged (a window is a whole number of drive periods, so its duration
//! follows the frequency: 100 us at 40 kHz for 4 periods). The envelope time constant `tau = 2Q / (2 pi f0)` (0.8 ms at 40 kHz,
//! Q 100) makes a fully settled sweep slow (3 tau per point, 50 ms for +-10 % at one
//! bandwidth per point), so the coarse sweep dwells less and its peak comes late, by 60-180 Hz
//! on `sonolube_sim::plant` (whose motional phase follows the frequency at once) and 360-570 Hz on a
//! complex envelope (a real series branch) at one bandwidth per 0.2 ms (tests). The sweep therefore runs on
//! past the band for one `tau` (the overrun) so that a resonance at the band's top still shows
//! a peak, and leaves the last word to the phase loop (`search`), which needs only a bracket.
//!
//! Memory: the peak and its two neighbours, not the whole curve (any number of points).

use super::lockin::Demodulated;
use super::tuning::Tuning;
use crate::drive::{DriveError, Frequency, TimerClock};
use crate::fx::Q2_30;

/// The points of a sweep and the dwell at each (fixed point).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SweepPlan {
    /// First point, mHz (in 20-60 kHz).
    pub start_mhz: u32,
    /// Spacing of the points relative to the frequency, `r` in Q0.32 (`2^32 / Q` for one
    /// bandwidth; > 0).
    pub relative_step_q32: u32,
    /// Number of points, >= 1. A point the timer cannot make (above 60 kHz) ends the sweep
    /// early.
    pub points: u16,
    /// Lock-in windows discarded after each change of frequency.
    pub settle_windows: u16,
    /// Lock-in windows averaged per point (>= 1).
    pub measure_windows: u16,
    /// Ends the sweep early once this many points have followed the best one and the latest
    /// conductance is at most half the best (the peak is behind: a resonance's conductance
    /// falls to a fifth one bandwidth away); 0 sweeps every point. The first such peak wins,
    /// not the largest in the band. Only a best point whose conductance is at least
    /// `min_peak` and that comes after the first `start_up` points ends it (a resonance, not
    /// noise or the envelope's start-up transient).
    pub stop_past_peak: u16,
    /// Points at the start of the sweep (one envelope time constant) whose best never ends
    /// the sweep early.
    pub start_up: u16,
    /// The least conductance a peak that ends the sweep early has (Q2.30 full scale).
    pub min_peak: Q2_30,
}

/// The conductance at one point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SweepPoint {
    /// The drive frequency there (achieved), mHz.
    pub millihertz: u32,
    /// The mean in-phase current, Q2.30 full scale (conductance times drive voltage).
    pub conductance: Q2_30,
}

/// What the sweep found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SweepResult {
    /// The interpolated peak of the conductance (parabola through the best point and its
    /// neighbours).
    pub peak: Frequency,
    /// The best point.
    pub best: SweepPoint,
    /// Its index, 0 to `points - 1`: at either end the peak is not bracketed.
    pub best_index: u16,
    /// Number of points swept (fewer than planned if the timer could not make the rest).
    pub points: u16,
}

/// What to do after a window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SweepProgress {
    /// Keep driving at this tuning (the same as before, or the next point's).
    Drive(Tuning),
    /// The last point is done.
    Done(SweepResult),
}

/// A sweep in progress.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sweep {
    plan: SweepPlan,
    clock: TimerClock,
    index: u16,
    /// The present point as planned (before the timer's rounding), mHz.
    planned_mhz: u32,
    tuning: Tuning,
    /// Windows since this point's frequency was set.
    windows: u16,
    /// Sum of in-phase components times window samples, and the samples summed.
    weighted_sum: i64,
    measured: u32,
    previous: SweepPoint,
    best: SweepPoint,
    best_index: u16,
    before_best: SweepPoint,
    after_best: Option<SweepPoint>,
    /// Sum of the squared in-phase components (Q2.30 bits squared) of every window of the
    /// start-up points, and their count: the noise floor a peak must stand out of.
    floor_sum_squares: u128,
    floor_windows: u32,
}

/// How many standard deviations of the start-up points' in-phase current a peak that ends
/// the sweep early stands above them: 4 (a Gaussian noise point passes it with probability
/// 3e-5). The current sense's noise is the sweep's own measurement, not a setting: at Q 300
/// the conductance off resonance is below one converter step, and a single noisy window
/// above [`SweepPlan::min_peak`] followed by one below half of it ended the sweep
/// before f0 (docs/resonance.md).
pub const PEAK_NOISE_RATIO: u32 = 4;

impl Sweep {
    /// A sweep at its first point. Error: the timer cannot make the first point's frequency
    /// (outside 20-60 kHz).
    pub fn new(plan: SweepPlan, clock: TimerClock) -> Result<Self, DriveError> {
        let tuning = Tuning::nearest(Frequency::from_millihertz(plan.start_mhz), clock)?;
        Ok(Self {
            plan,
            clock,
            index: 0,
            planned_mhz: plan.start_mhz,
            tuning,
            windows: 0,
            weighted_sum: 0,
            measured: 0,
            previous: SweepPoint::default(),
            best: SweepPoint::default(),
            best_index: 0,
            before_best: SweepPoint::default(),
            after_best: None,
            floor_sum_squares: 0,
            floor_windows: 0,
        })
    }

    /// The drive setting of the present point.
    pub const fn tuning(&self) -> Tuning {
        self.tuning
    }

    /// The present point's index.
    pub const fn index(&self) -> u16 {
        self.index
    }

    /// Takes a window measured at [`Self::tuning`]. Returns the point just finished with the
    /// next drive (or the result), so the caller can inspect every point (fault checks,
    /// telemetry). Integer only; one division per point.
    pub fn update(&mut self, window: &Demodulated) -> (Option<SweepPoint>, SweepProgress) {
        self.windows = self.windows.saturating_add(1);
        if self.index < self.plan.start_up {
            let in_phase = i128::from(window.phasor.in_phase.to_bits());
            // < 2^62 per window, < 2^32 windows: fits u128.
            self.floor_sum_squares += (in_phase * in_phase) as u128;
            self.floor_windows = self.floor_windows.saturating_add(1);
        }
        if self.windows > self.plan.settle_windows {
            // |in-phase| < 2^31 and samples < 2^21 per window: 2^16 windows fit i64.
            self.weighted_sum +=
                i64::from(window.phasor.in_phase.to_bits()) * i64::from(window.samples);
            self.measured += window.samples;
        }
        let wanted = self
            .plan
            .settle_windows
            .saturating_add(self.plan.measure_windows.max(1));
        if self.windows < wanted || self.measured == 0 {
            return (None, SweepProgress::Drive(self.tuning));
        }
        let point = SweepPoint {
            millihertz: self.tuning.frequency.millihertz(),
            conductance: Q2_30::from_bits((self.weighted_sum / i64::from(self.measured)) as i32),
        };
        self.record(point);
        self.index += 1;
        // f (1 + r): f < 2^32 mHz and r < 2^32, so the product fits u64.
        let next = u64::from(self.planned_mhz)
            + ((u64::from(self.planned_mhz) * u64::from(self.plan.relative_step_q32) + (1 << 31))
                >> 32);
        let next = Frequency::from_millihertz(u32::try_from(next).unwrap_or(u32::MAX));
        let past = self.index - 1 - self.best_index;
        let peak_behind = self.plan.stop_past_peak > 0
            && self.best_index > 0
            && self.best_index >= self.plan.start_up
            && self.best.conductance >= self.plan.min_peak
            && self.above_floor(self.best.conductance)
            && past >= self.plan.stop_past_peak
            && i64::from(point.conductance.to_bits()) * 2
                <= i64::from(self.best.conductance.to_bits());
        match Tuning::nearest(next, self.clock) {
            Ok(tuning) if self.index < self.plan.points && !peak_behind => {
                self.planned_mhz = next.millihertz();
                self.tuning = tuning;
                self.windows = 0;
                self.weighted_sum = 0;
                self.measured = 0;
                (Some(point), SweepProgress::Drive(self.tuning))
            }
            // The last point, or the next one is beyond what the timer can make.
            _ => (Some(point), SweepProgress::Done(self.result())),
        }
    }

    /// `conductance` stands [`PEAK_NOISE_RATIO`] standard deviations of a point's mean above
    /// the start-up windows' RMS in-phase current: `G^2 n m >= 16 sum x^2` over `n` start-up
    /// windows, a point averaging `m` windows. Integer; false before any start-up window.
    fn above_floor(&self, conductance: Q2_30) -> bool {
        if self.floor_windows == 0 {
            return false;
        }
        let g = i128::from(conductance.to_bits().max(0)) as u128;
        let ratio = u128::from(PEAK_NOISE_RATIO * PEAK_NOISE_RATIO);
        // g^2 < 2^62, windows < 2^32, measure < 2^16: < 2^110.
        g * g * u128::from(self.floor_windows) * u128::from(self.plan.measure_windows.max(1))
            >= ratio * self.floor_sum_squares
    }

    fn record(&mut self, point: SweepPoint) {
        if self.index == 0 || point.conductance > self.best.conductance {
            self.before_best = if self.index == 0 {
                point
            } else {
                self.previous
            };
            self.best = point;
            self.best_index = self.index;
            self.after_best = None;
        } else if self.after_best.is_none() {
            self.after_best = Some(point);
        }
        self.previous = point;
    }

    /// The vertex of the parabola through the *reciprocal* conductances of the best point and
    /// its neighbours: `1 / G = (1 + x^2) / G0` is exactly a parabola in the detuning, so a
    /// settled sweep's peak comes out unbiased however coarse the points (a parabola through
    /// `G` itself is off by up to a quarter step). The best point itself at either end of the
    /// sweep, or when a neighbour's conductance is not positive. Four divisions per sweep.
    fn result(&self) -> SweepResult {
        let reciprocal = |point: SweepPoint| {
            let g = i128::from(point.conductance.to_bits());
            // 2^60 / G: G >= 1 ulp gives at most 2^60.
            if g > 0 { Some((1i128 << 60) / g) } else { None }
        };
        let best = i128::from(self.best.millihertz);
        let mut peak = best;
        if let (Some(after), true) = (self.after_best, self.best_index > 0) {
            let points = (
                reciprocal(self.before_best),
                reciprocal(self.best),
                reciprocal(after),
            );
            if let (Some(r1), Some(r0), Some(r2)) = points {
                // Parabola through (d1, r1), (0, r0), (d2, r2), with the neighbours' distances
                // d1 < 0 < d2 (unequal: the spacing grows with f). With u = r - r0 the vertex
                // is at -(d2^2 u1 - d1^2 u2) / (2 (d1 u2 - d2 u1)); r0 is the smallest, so the
                // denominator is < 0 unless all three are equal, and the vertex lies between
                // the neighbours. |u| < 2^61, |d| < 2^26: the products fit i128.
                let d1 = i128::from(self.before_best.millihertz) - best;
                let d2 = i128::from(after.millihertz) - best;
                let (u1, u2) = (r1 - r0, r2 - r0);
                let denominator = 2 * (d1 * u2 - d2 * u1);
                if denominator < 0 {
                    peak = best - (d2 * d2 * u1 - d1 * d1 * u2) / denominator;
                }
            }
        }
        SweepResult {
            peak: Frequency::from_millihertz(peak.clamp(0, i128::from(u32::MAX)) as u32),
            best: self.best,
            best_index: self.best_index,
            points: self.index,
        }
    }
}

#[cfg(test)]
#[path = "sweep_tests.rs"]
mod tests;
