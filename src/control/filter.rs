//! First-order fixed-point IIR low-pass filter with its bandwidth stated in hertz.
//!
//! `y[n] = y[n-1] + alpha (x[n] - y[n-1])`. The coefficient is computed once, in `f64`, at
//! configuration ([`LowPassCoef::from_bandwidth`]) so that the gain is exactly -3 dB at the
//! stated bandwidth `f_c` for the sampled filter (not only for its continuous prototype):
//! with `w = 2 pi f_c / f_s`, `c = cos w`, the pole is `b = (2 - c) - sqrt((2 - c)^2 - 1)`
//! and `alpha = 1 - b` (solve `|H(e^jw)|^2 = 1/2`). [`LowPassCoef::from_time_constant`]
//! instead matches the step response of a continuous first-order lag exactly (zero-order
//! hold): `alpha = 1 - exp(-T / tau)`; the controller models the transducer envelope this way.
//!
//! Numerics: `alpha` is Q1.31 (`0 < alpha < 1`). The state carries 31 bits below the input's
//! least significant bit in an `i64`, so the filter has no dead band: a constant input `x`
//! settles to an output of exactly `x` (DC gain 1, tested for every format edge) and a
//! small change of the input is never swallowed by rounding; a first-order section with a
//! constant input cannot limit-cycle. The update splits the 63-bit difference into a high and
//! a low word (two 32x32 multiplies, round-to-nearest), so the state always stays between the
//! old state and the input: no overflow at full-scale inputs of either sign. About 20
//! instructions per sample on the Cortex-M4.

use super::SampleBlock;
use crate::fx::{Q, Q1_31};

/// Why a filter coefficient could not be made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FilterError {
    /// A frequency or time was not a finite positive number.
    NotPositive,
    /// The bandwidth was not below the Nyquist frequency `f_s / 2`.
    AboveNyquist,
    /// The coefficient is below 2^-20: a filter that slow would take minutes to settle and
    /// loses coefficient precision.
    TooSlow,
}

/// The smallest coefficient accepted, 2^-20 in Q1.31 bits (bandwidth about 1.5e-7 f_s).
const MIN_ALPHA_BITS: i32 = 1 << 11;

/// Coefficient of a first-order low-pass (configuration: `Copy`, swapped atomically).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LowPassCoef {
    alpha: Q1_31,
}

impl LowPassCoef {
    /// The coefficient whose gain is exactly -3 dB at `bandwidth_hz` when sampled at
    /// `sample_rate_hz`. Errors: `NotPositive`, `AboveNyquist` (`bandwidth_hz >= fs / 2`),
    /// `TooSlow`. Configuration only (`f64`).
    pub fn from_bandwidth(bandwidth_hz: f64, sample_rate_hz: f64) -> Result<Self, FilterError> {
        if !(bandwidth_hz > 0.0 && sample_rate_hz > 0.0 && sample_rate_hz.is_finite()) {
            return Err(FilterError::NotPositive);
        }
        if bandwidth_hz >= sample_rate_hz / 2.0 {
            return Err(FilterError::AboveNyquist);
        }
        let c = libm::cos(core::f64::consts::TAU * bandwidth_hz / sample_rate_hz);
        let p = 2.0 - c;
        let pole = p - libm::sqrt(p * p - 1.0);
        Self::from_alpha(1.0 - pole)
    }

    /// The coefficient of a continuous first-order lag of time constant `time_constant_s`
    /// sampled every `period_s` with a zero-order hold: `1 - exp(-T / tau)`. Errors:
    /// `NotPositive`, `TooSlow`. Configuration only (`f64`).
    pub fn from_time_constant(time_constant_s: f64, period_s: f64) -> Result<Self, FilterError> {
        if !(time_constant_s > 0.0 && period_s > 0.0 && period_s.is_finite()) {
            return Err(FilterError::NotPositive);
        }
        Self::from_alpha(-libm::expm1(-period_s / time_constant_s))
    }

    fn from_alpha(alpha: f64) -> Result<Self, FilterError> {
        // alpha < 1 always here; the clamp keeps alpha * 2^31 inside Q1.31.
        let bits = libm::round(alpha * 2_147_483_648.0).min(i32::MAX as f64) as i32;
        if bits < MIN_ALPHA_BITS {
            return Err(FilterError::TooSlow);
        }
        Ok(Self {
            alpha: Q1_31::from_bits(bits),
        })
    }

    /// The coefficient `alpha`, Q1.31 in [2^-20, 1).
    pub const fn alpha(&self) -> Q1_31 {
        self.alpha
    }

    /// The exact -3 dB frequency of this coefficient at `sample_rate_hz` (for reports; `f64`).
    pub fn bandwidth_hz(&self, sample_rate_hz: f64) -> f64 {
        // |H|^2 = a^2 / (1 - 2 b cos w + b^2) = 1/2  =>  cos w = (1 + b^2 - 2 a^2) / (2 b)
        let a = self.alpha.to_f64();
        let b = 1.0 - a;
        let cos_w = ((1.0 + b * b - 2.0 * a * a) / (2.0 * b)).clamp(-1.0, 1.0);
        libm::acos(cos_w) * sample_rate_hz / core::f64::consts::TAU
    }
}

/// State of a first-order low-pass on values of format `Q<F>`, 31 bits finer than `Q<F>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LowPass<const F: u32> {
    /// The output times 2^31, in units of the input's least significant bit: |state| <= 2^62.
    state: i64,
}

impl<const F: u32> LowPass<F> {
    /// A filter at rest at `initial` (its output until the first update).
    pub const fn new(initial: Q<F>) -> Self {
        Self {
            state: (initial.to_bits() as i64) << 31,
        }
    }

    /// Sets the filter at rest at `value` (no transient from the old state).
    pub fn reset(&mut self, value: Q<F>) {
        *self = Self::new(value);
    }

    /// The present output, rounded to nearest from the wide state.
    pub const fn output(&self) -> Q<F> {
        // state <= (2^31 - 1) 2^31, so the rounded value fits i32.
        Q::<F>::from_bits(((self.state + (1 << 30)) >> 31) as i32)
    }
}

/// The filter: one input sample of format `Q<F>` into the state, the new output out. Never
/// overflows, never panics.
impl<const F: u32> SampleBlock<Q<F>> for LowPassCoef {
    type State = LowPass<F>;
    type Output = Q<F>;

    fn process(&self, filter: &mut LowPass<F>, input: Q<F>) -> Q<F> {
        let alpha = self.alpha.to_bits() as i64; // (0, 2^31)
        // |input << 31| <= 2^62 and the state lies between past inputs: |diff| < 2^63.
        let diff = ((input.to_bits() as i64) << 31) - filter.state;
        let high = diff >> 31; // [-2^32, 2^32)
        let low = diff & 0x7FFF_FFFF; // [0, 2^31)
        // alpha (high 2^31 + low) / 2^31, the low part rounded to nearest; |alpha high| < 2^63.
        let step = alpha * high + ((alpha * low + (1 << 30)) >> 31);
        filter.state += step;
        filter.output()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q2_30, Q16_16};
    use proptest::prelude::*;

    const FS: f64 = 10_000.0;

    /// Gain of the fixed-point filter at `freq_hz`, measured by correlating the steady-state
    /// output with a sine and a cosine over whole periods.
    fn measured_gain(coef: &LowPassCoef, freq_hz: f64) -> f64 {
        let amplitude = 10_000.0; // N, a third of the Q16.16 range
        let mut filter = LowPass::<16>::new(Q16_16::ZERO);
        let periods = 40.0;
        let settle = (6.0 / coef.alpha().to_f64()) as usize; // >> time constant
        let total = settle + (periods * FS / freq_hz).round() as usize;
        let (mut i_sum, mut q_sum, mut count) = (0.0, 0.0, 0.0);
        for n in 0..total {
            let phase = core::f64::consts::TAU * freq_hz * n as f64 / FS;
            let x = Q16_16::from_f64(amplitude * phase.sin()).unwrap();
            let y = coef.process(&mut filter, x).to_f64();
            if n >= settle {
                i_sum += y * phase.sin();
                q_sum += y * phase.cos();
                count += 1.0;
            }
        }
        2.0 * (i_sum * i_sum + q_sum * q_sum).sqrt() / count / amplitude
    }

    #[test]
    fn minus_3_db_at_the_stated_bandwidth() {
        for bandwidth in [20.0, 200.0, 600.0, 2_000.0] {
            let coef = LowPassCoef::from_bandwidth(bandwidth, FS).unwrap();
            let gain = measured_gain(&coef, bandwidth);
            assert!(
                (gain - core::f64::consts::FRAC_1_SQRT_2).abs() < 2e-3,
                "{bandwidth} Hz: gain {gain}"
            );
            assert!((coef.bandwidth_hz(FS) - bandwidth).abs() < 1e-3 * bandwidth);
            // One decade below: close to 1; one decade above: well attenuated.
            assert!(measured_gain(&coef, bandwidth / 10.0) > 0.99);
            if bandwidth * 10.0 < FS / 2.0 {
                assert!(measured_gain(&coef, bandwidth * 10.0) < 0.15);
            }
        }
    }

    #[test]
    fn dc_gain_is_exactly_one_at_steady_state() {
        let slow = LowPassCoef::from_bandwidth(1.0, FS).unwrap();
        let fast = LowPassCoef::from_bandwidth(3_000.0, FS).unwrap();
        for coef in [slow, fast] {
            for (start, level) in [
                (0, 1),
                (0, -1),
                (i32::MIN, i32::MAX),
                (i32::MAX, i32::MIN),
                (12_345, 12_346),
                (-7, 123_456_789),
            ] {
                let mut filter = LowPass::<30>::new(Q2_30::from_bits(start));
                let input = Q2_30::from_bits(level);
                // 1 Hz at 10 kHz: time constant 1592 samples; 60k samples is 37 of them.
                for _ in 0..60_000 {
                    coef.process(&mut filter, input);
                }
                assert_eq!(filter.output(), input, "from {start} to {level}");
            }
        }
    }

    #[test]
    fn step_response_matches_the_continuous_lag() {
        let tau = 0.8e-3;
        let coef = LowPassCoef::from_time_constant(tau, 1.0 / FS).unwrap();
        let mut filter = LowPass::<31>::new(Q1_31::ZERO);
        let step = Q1_31::from_f64(0.5).unwrap();
        for n in 1..=40 {
            let y = coef.process(&mut filter, step).to_f64();
            let exact = 0.5 * (1.0 - (-(n as f64) / (FS * tau)).exp());
            assert!((y - exact).abs() < 1e-8, "sample {n}: {y} vs {exact}");
        }
    }

    #[test]
    fn bad_settings_are_rejected() {
        assert_eq!(
            LowPassCoef::from_bandwidth(0.0, FS),
            Err(FilterError::NotPositive)
        );
        assert_eq!(
            LowPassCoef::from_bandwidth(f64::NAN, FS),
            Err(FilterError::NotPositive)
        );
        assert_eq!(
            LowPassCoef::from_bandwidth(5_000.0, FS),
            Err(FilterError::AboveNyquist)
        );
        assert_eq!(
            LowPassCoef::from_bandwidth(1e-5, FS),
            Err(FilterError::TooSlow)
        );
        assert_eq!(
            LowPassCoef::from_time_constant(-1.0, 1e-4),
            Err(FilterError::NotPositive)
        );
        assert!(LowPassCoef::from_time_constant(f64::INFINITY, 1e-4).is_err());
        // Near Nyquist the coefficient is still below 1.
        let c = LowPassCoef::from_bandwidth(4_999.0, FS).unwrap();
        assert!(c.alpha().to_bits() > 0);
    }

    proptest! {
        /// Any sequence of full-range inputs with any coefficient: no overflow (tests run with
        /// overflow checks) and the output never leaves the range of the inputs seen.
        #[test]
        fn no_overflow_and_output_stays_in_the_input_hull(
            alpha_bits in MIN_ALPHA_BITS..=i32::MAX,
            start in any::<i32>(),
            inputs in proptest::collection::vec(any::<i32>(), 1..64),
        ) {
            let coef = LowPassCoef { alpha: Q1_31::from_bits(alpha_bits) };
            let mut filter = LowPass::<16>::new(Q16_16::from_bits(start));
            let (mut low, mut high) = (start, start);
            for x in inputs {
                low = low.min(x);
                high = high.max(x);
                let y = coef.process(&mut filter, Q16_16::from_bits(x)).to_bits();
                prop_assert!(low <= y && y <= high, "{y} outside [{low}, {high}]");
            }
        }
    }
}
