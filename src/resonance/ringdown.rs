//! The envelope time constant from a ring-down of the drive current.
//!
//! With the drive off, the stack's motional branch (Butterworth-Van Dyke R1-L1-C1) rings at
//! its resonance and its current decays as `exp(-t / tau)`, `tau = 2Q / w0 = Q / (pi f0)`: the
//! same time constant as the vibration envelope the friction loop drives through
//! (`sim/src/plant/transducer.rs`, physics-notes). The clamped capacitance carries no current
//! once the voltage is zero, so the current the sense reads is the motional current alone.
//!
//! # Amplitude per group of four samples
//!
//! The current is sampled once per PWM period with the trigger a quarter turn later each
//! period ([`super::SYNCHRONOUS_PHASE_STEP`]), so four consecutive samples `x0..x3` sit a
//! quarter turn apart on the carrier: `x0 - x2 = 2A cos(theta)`, `x1 - x3 = -2A sin(theta)`
//! (the converter's mid-scale offset cancels). [`group_amplitude_squared`] returns
//! `(x0 - x2)^2 + (x1 - x3)^2 = 4 A^2` in integer LSB^2, exactly, with no floating point in the
//! control step. While the envelope decays over a group, the two differences see slightly
//! different amplitudes; the ratio is the same for every group of the same starting phase, so
//! it is a constant factor on each amplitude and leaves the slope of `ln A` untouched.
//!
//! # Fit
//!
//! [`fit_ring_down`] fits `ln A_k = c - t_k / tau` by weighted least squares with weights
//! `A_k^2`: the converter noise `sigma` is the same on every sample, so `ln A_k` has the
//! variance `(sigma / A_k)^2` and the weight is its inverse. The standard error of the slope
//! comes from the residuals (`s^2 = sum w r^2 / (n - 2)`, `se^2 = s^2 / sum w (t - t_w)^2`), so
//! it grows with the noise and is zero for an exact exponential. Points are used from the
//! first group after the drive went off while the amplitude stays above both `e^-3` of the
//! first (three time constants: the noise has not yet taken over) and
//! [`RING_DOWN_FLOOR_LSB`]. Set-up arithmetic in `f64`, once per commissioning.

/// Least amplitude of the first ring-down group, current-sense LSB (12-bit converter): eight
/// times [`RING_DOWN_FLOOR_LSB`], so that at least two time constants (`ln 8 = 2.1`) of the
/// decay lie above the floor.
pub const MIN_RING_DOWN_START_LSB: f64 = 64.0;

/// Amplitude below which a ring-down point is not used, LSB: four times the sense's 2 LSB RMS
/// noise (the amplitude of noise alone, `sqrt(2) sigma`, stays below it).
pub const RING_DOWN_FLOOR_LSB: f64 = 8.0;

/// Decay, in time constants, over which points are used (`e^-3`, 5 % of the start).
pub const RING_DOWN_SPAN_TIME_CONSTANTS: f64 = 3.0;

/// Fewest points a fit needs: two for the line, four more for a standard error worth the
/// name.
pub const MIN_RING_DOWN_POINTS: usize = 6;

/// `(x0 - x2)^2 + (x1 - x3)^2` of four consecutive current-sense codes a quarter turn apart:
/// four times the squared amplitude of the current's fundamental, LSB^2 (at most
/// `2 x 4095^2`, so a `u64` holds it and any sum of 2^32 of them).
pub const fn group_amplitude_squared(codes: [u16; 4]) -> u64 {
    let in_phase = codes[0] as i64 - codes[2] as i64;
    let quadrature = codes[1] as i64 - codes[3] as i64;
    (in_phase * in_phase + quadrature * quadrature) as u64
}

/// The amplitude (LSB) of a [`group_amplitude_squared`] value.
pub fn group_amplitude_lsb(amplitude_squared_x4: u64) -> f64 {
    0.5 * libm::sqrt(amplitude_squared_x4 as f64)
}

/// A ring-down fit.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RingDownFit {
    /// The envelope time constant, s (> 0).
    pub time_constant_s: f64,
    /// Its standard error from the fit's residuals, s (>= 0).
    pub time_constant_se_s: f64,
    /// Points used.
    pub points: u32,
    /// Amplitude of the first point, LSB.
    pub start_amplitude_lsb: f64,
}

/// Why a ring-down gives no time constant.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RingDownError {
    /// The group spacing is not a positive finite time.
    Spacing,
    /// The first amplitude is below [`MIN_RING_DOWN_START_LSB`] (the value, LSB).
    TooSmall(f64),
    /// Fewer than [`MIN_RING_DOWN_POINTS`] points above the floor (the count).
    TooShort(u32),
    /// The fitted amplitude does not decay (slope >= 0).
    NoDecay,
}

impl RingDownError {
    /// The reason in words, for the refusal.
    pub const fn reason(&self) -> &'static str {
        match self {
            RingDownError::Spacing => "ring-down spacing invalid",
            RingDownError::TooSmall(_) => "ring-down amplitude too small",
            RingDownError::TooShort(_) => "ring-down too short",
            RingDownError::NoDecay => "current did not decay",
        }
    }
}

/// The running sums of a ring-down fit, one point at a time (one per control period in the
/// station, so that no period carries the whole fit): the points are the group amplitudes from
/// the first after the drive went off, kept while they stay above the floor (the module
/// documentation). Time is counted in groups; `y = ln(A / A_first)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RingDownSums {
    count: u32,
    start_lsb: f64,
    log_start: f64,
    floor_lsb: f64,
    closed: bool,
    sum_w: f64,
    sum_wt: f64,
    sum_wy: f64,
    sum_wtt: f64,
    sum_wty: f64,
    sum_wyy: f64,
}

impl Default for RingDownSums {
    fn default() -> Self {
        Self::new()
    }
}

impl RingDownSums {
    /// No points yet.
    pub const fn new() -> Self {
        Self {
            count: 0,
            start_lsb: 0.0,
            log_start: 0.0,
            floor_lsb: 0.0,
            closed: false,
            sum_w: 0.0,
            sum_wt: 0.0,
            sum_wy: 0.0,
            sum_wtt: 0.0,
            sum_wty: 0.0,
            sum_wyy: 0.0,
        }
    }

    /// Adds the next group's amplitude, LSB; false once the ring-down is closed (a point
    /// below the floor, or a first point too small to fit).
    pub fn push(&mut self, amplitude_lsb: f64) -> bool {
        if self.closed {
            return false;
        }
        if self.count == 0 {
            self.start_lsb = amplitude_lsb;
            // NaN is refused too.
            if amplitude_lsb.is_nan() || amplitude_lsb < MIN_RING_DOWN_START_LSB {
                self.closed = true;
                return false;
            }
            self.log_start = libm::log(amplitude_lsb);
            self.floor_lsb = libm::fmax(
                amplitude_lsb * libm::exp(-RING_DOWN_SPAN_TIME_CONSTANTS),
                RING_DOWN_FLOOR_LSB,
            );
        }
        if amplitude_lsb.is_nan() || amplitude_lsb < self.floor_lsb {
            self.closed = true;
            return false;
        }
        let t = f64::from(self.count);
        let y = libm::log(amplitude_lsb) - self.log_start;
        let w = amplitude_lsb * amplitude_lsb;
        self.sum_w += w;
        self.sum_wt += w * t;
        self.sum_wy += w * y;
        self.sum_wtt += w * t * t;
        self.sum_wty += w * t * y;
        self.sum_wyy += w * y * y;
        self.count += 1;
        true
    }

    /// Whether a point fell below the floor (or the first was too small): the ring-down is over.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The fit of the points so far, groups `group_spacing_s` apart.
    pub fn fit(&self, group_spacing_s: f64) -> Result<RingDownFit, RingDownError> {
        if !(group_spacing_s.is_finite() && group_spacing_s > 0.0) {
            return Err(RingDownError::Spacing);
        }
        if self.start_lsb.is_nan() || self.start_lsb < MIN_RING_DOWN_START_LSB {
            return Err(RingDownError::TooSmall(self.start_lsb));
        }
        let n = self.count;
        if (n as usize) < MIN_RING_DOWN_POINTS {
            return Err(RingDownError::TooShort(n));
        }
        // Centred sums: t spans at most a few hundred groups and y three units, so the
        // cancellation costs a few digits of f64's sixteen.
        let stt = self.sum_wtt - self.sum_wt * self.sum_wt / self.sum_w;
        let sty = self.sum_wty - self.sum_wt * self.sum_wy / self.sum_w;
        let syy = self.sum_wyy - self.sum_wy * self.sum_wy / self.sum_w;
        let slope = sty / stt;
        if slope.is_nan() || slope >= 0.0 {
            return Err(RingDownError::NoDecay);
        }
        let residual = libm::fmax(syy - slope * sty, 0.0);
        let slope_se = libm::sqrt(residual / f64::from(n - 2) / stt);
        Ok(RingDownFit {
            time_constant_s: -group_spacing_s / slope,
            time_constant_se_s: group_spacing_s * slope_se / (slope * slope),
            points: n,
            start_amplitude_lsb: self.start_lsb,
        })
    }
}

/// Fits the ring-down of `amplitudes_lsb` (one per group, the first after the drive went off,
/// `group_spacing_s` apart) as described in the module documentation ([`RingDownSums`]).
pub fn fit_ring_down(
    amplitudes_lsb: impl Iterator<Item = f64>,
    group_spacing_s: f64,
) -> Result<RingDownFit, RingDownError> {
    let mut sums = RingDownSums::new();
    for amplitude in amplitudes_lsb {
        if !sums.push(amplitude) {
            break;
        }
    }
    sums.fit(group_spacing_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference stack: Q = 100 at 40 kHz, tau = 0.796 ms; one group per 4 drive periods.
    const TAU_S: f64 = 100.0 / (core::f64::consts::PI * 40_000.0);
    const SPACING_S: f64 = 4.0 / 40_000.0;

    fn exponential(start: f64, count: usize) -> impl Iterator<Item = f64> {
        (0..count).map(move |k| start * libm::exp(-(k as f64) * SPACING_S / TAU_S))
    }

    #[test]
    fn an_exact_exponential_gives_its_time_constant_with_no_error() {
        let fit = fit_ring_down(exponential(500.0, 200), SPACING_S).expect("fits");
        assert!((fit.time_constant_s / TAU_S - 1.0).abs() < 1e-12, "{fit:?}");
        // Only rounding is left in the one-pass residual: about sqrt(1e-16) of the slope.
        assert!(fit.time_constant_se_s < 1e-6 * TAU_S, "{fit:?}");
        // Three time constants of 0.1 ms groups: 24 points (the 25th is just below e^-3).
        assert_eq!(fit.points, 24);
    }

    #[test]
    fn noise_widens_the_standard_error_and_the_truth_stays_within_it() {
        // A deterministic pseudo-noise (a linear congruential sequence), amplitude `level` LSB.
        let noisy = |level: f64| {
            let mut state = 12_345u32;
            let values: [f64; 40] = core::array::from_fn(|k| {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                let uniform = f64::from(state >> 8) / f64::from(1u32 << 24) - 0.5;
                500.0 * libm::exp(-(k as f64) * SPACING_S / TAU_S) + level * uniform
            });
            fit_ring_down(values.into_iter(), SPACING_S).expect("fits")
        };
        let quiet = noisy(1.0);
        let loud = noisy(8.0);
        assert!(loud.time_constant_se_s > 4.0 * quiet.time_constant_se_s);
        assert!(quiet.time_constant_se_s > 0.0);
        for fit in [quiet, loud] {
            let error = (fit.time_constant_s - TAU_S).abs();
            assert!(error < 3.0 * fit.time_constant_se_s, "{fit:?}");
        }
    }

    #[test]
    fn a_small_or_short_or_rising_ring_down_is_refused() {
        assert_eq!(
            fit_ring_down(exponential(40.0, 100), SPACING_S),
            Err(RingDownError::TooSmall(40.0))
        );
        // Q = 5 at 60 kHz: tau = 26.5 us, a third of one group: three time constants in one.
        let fast = (0..100).map(|k| 500.0 * libm::exp(-(k as f64) * 3.8));
        assert_eq!(
            fit_ring_down(fast, SPACING_S),
            Err(RingDownError::TooShort(1))
        );
        assert_eq!(
            fit_ring_down(exponential(500.0, 4), SPACING_S),
            Err(RingDownError::TooShort(4))
        );
        let rising = (0..20).map(|k| 100.0 + k as f64);
        assert_eq!(
            fit_ring_down(rising, SPACING_S),
            Err(RingDownError::NoDecay)
        );
        assert_eq!(
            fit_ring_down(exponential(500.0, 50), 0.0),
            Err(RingDownError::Spacing)
        );
        assert_eq!(
            fit_ring_down(core::iter::empty(), SPACING_S),
            Err(RingDownError::TooSmall(0.0))
        );
    }

    #[test]
    fn four_samples_a_quarter_turn_apart_give_the_amplitude_whatever_the_offset_and_phase() {
        for phase in [0.0f64, 0.3, 1.7, 4.0] {
            let codes: [u16; 4] = core::array::from_fn(|k| {
                let theta = phase + k as f64 * core::f64::consts::FRAC_PI_2;
                libm::round(2100.0 + 300.0 * libm::cos(theta)) as u16
            });
            let amplitude = group_amplitude_lsb(group_amplitude_squared(codes));
            // Rounding each code moves it by at most half an LSB.
            assert!((amplitude - 300.0).abs() < 0.75, "{phase}: {amplitude}");
        }
        assert_eq!(group_amplitude_squared([4095, 4095, 0, 0]), 2 * 4095 * 4095);
    }
}
