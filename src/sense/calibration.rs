//! The one calibration type every channel uses: fraction of full scale to newtons or amperes.
//!
//! `value = (reading - offset) * span`, with the reading and the offset (tare) as Q1.31
//! fractions of the converter's full scale ([`crate::sense::AdcFormat`]) and the span as the
//! physical value of one full scale, Q16.16 (newtons for a load cell, amperes for the current
//! sense). The offset comes from a tare (no load, or no drive for the current), the span from
//! a known load or from the front end's data ([`crate::sense::ShuntAmplifier`],
//! [`crate::sense::BridgeAmplifier`]). Integer only: one 64-bit product per sample.

use super::error::SenseError;
use crate::fx::{Q1_31, Q16_16, Sat, div_round_i64};

/// Offset and span of one channel. `Copy`, so a loop can swap in a new calibration at once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Calibration {
    offset: Q1_31,
    span: Q16_16,
}

impl Calibration {
    /// A known load must move the reading by at least this much (1/4096 of full scale: 16 LSB
    /// of the 16-bit oversampled ADC, 4096 LSB of the 24-bit ADS131M02) for a usable gain.
    pub const MIN_CALIBRATION_SPAN: Q1_31 = Q1_31::from_bits(1 << 19);

    /// Reading `offset` means zero; one full scale more means `span_per_full_scale`
    /// (Q16.16 newtons or amperes; negative for a sensor mounted the other way round).
    pub const fn new(offset: Q1_31, span_per_full_scale: Q16_16) -> Self {
        Self {
            offset,
            span: span_per_full_scale,
        }
    }

    /// The reading that means zero, as a fraction of full scale.
    pub const fn offset(&self) -> Q1_31 {
        self.offset
    }

    /// The physical value of one full scale, Q16.16.
    pub const fn span(&self) -> Q16_16 {
        self.span
    }

    /// The same span with `zero_reading` (taken unloaded, or with the drive off) as the zero.
    pub const fn with_tare(self, zero_reading: Q1_31) -> Self {
        Self {
            offset: zero_reading,
            span: self.span,
        }
    }

    /// The same zero with the span set so that `loaded_reading` means `load` (a known weight
    /// on the cell, in Q16.16 newtons). Tare first.
    ///
    /// Errors: `SpanTooSmall` if the load moved the reading by less than
    /// [`Self::MIN_CALIBRATION_SPAN`]; `Overflow` if the span does not fit Q16.16 (more than
    /// 32 767 N per full scale).
    pub const fn with_known_load(
        self,
        loaded_reading: Q1_31,
        load: Q16_16,
    ) -> Result<Self, SenseError> {
        let delta = loaded_reading.to_bits() as i64 - self.offset.to_bits() as i64;
        if delta.unsigned_abs() < Self::MIN_CALIBRATION_SPAN.to_bits() as u64 {
            return Err(SenseError::SpanTooSmall);
        }
        // span = load / delta * 2^31: |load << 31| <= 2^62, delta != 0.
        let numerator = (load.to_bits() as i64) << 31;
        let span = div_round_i64(numerator, delta);
        if span > i32::MAX as i64 || span < i32::MIN as i64 {
            return Err(SenseError::Overflow);
        }
        Ok(Self {
            offset: self.offset,
            span: Q16_16::from_bits(span as i32),
        })
    }

    /// The physical value (Q16.16) of `reading`, rounded to nearest; clamped to the Q16.16 range
    /// with the flag set if it does not fit. One multiply, no panic, no overflow.
    pub const fn apply(&self, reading: Q1_31) -> Sat<Q16_16> {
        // |delta| < 2^32 and |span| <= 2^31: |product| < 2^63.
        let delta = reading.to_bits() as i64 - self.offset.to_bits() as i64;
        let product = delta * self.span.to_bits() as i64;
        // Rounding add: |product| <= 2^63 - 2^31, so adding 2^30 cannot overflow.
        let value = (product + (1 << 30)) >> 31;
        if value > i32::MAX as i64 {
            Sat::clamped(Q16_16::MAX)
        } else if value < i32::MIN as i64 {
            Sat::clamped(Q16_16::MIN)
        } else {
            Sat::exact(Q16_16::from_bits(value as i32))
        }
    }

    /// The reading (fraction of full scale) at which the channel shows `value`: the inverse of
    /// [`Self::apply`], for thresholds set in hardware (the overcurrent comparator). Errors:
    /// `Overflow` when the reading falls outside [-1, 1) of full scale or the span is zero.
    pub const fn reading_for(&self, value: Q16_16) -> Result<Q1_31, SenseError> {
        let span = self.span.to_bits() as i64;
        if span == 0 {
            return Err(SenseError::Overflow);
        }
        let delta = div_round_i64((value.to_bits() as i64) << 31, span);
        let reading = self.offset.to_bits() as i64 + delta;
        if reading > i32::MAX as i64 || reading < i32::MIN as i64 {
            return Err(SenseError::Overflow);
        }
        Ok(Q1_31::from_bits(reading as i32))
    }
}

/// The mean of `readings`, rounded to nearest: the tare from a burst of unloaded samples.
/// `None` for no readings. Sums in `i64`, exact for up to 2^32 readings.
pub fn mean(readings: impl IntoIterator<Item = Q1_31>) -> Option<Q1_31> {
    let mut sum: i64 = 0;
    let mut count: i64 = 0;
    for reading in readings {
        sum = sum.saturating_add(i64::from(reading.to_bits()));
        count = count.saturating_add(1);
    }
    if count == 0 {
        return None;
    }
    // The mean of i32 values is an i32.
    i32::try_from(div_round_i64(sum, count))
        .ok()
        .map(Q1_31::from_bits)
}

/// The RMS deviation of `readings` from `mean` (their standard deviation, population form),
/// rounded down: the noise of a burst taken with the load steady (the tare). Q1.31 fraction of
/// full scale in [0, 2^31); `None` for no readings. Sums the squared deviations in `u128`
/// (each < 2^64: exact for any burst that fits memory); the square root is the integer one,
/// exact to the lsb. Configuration-time arithmetic (one square root per tare).
pub fn rms_deviation(readings: impl IntoIterator<Item = Q1_31>, mean: Q1_31) -> Option<Q1_31> {
    let mut sum: u128 = 0;
    let mut count: u128 = 0;
    for reading in readings {
        let deviation = i64::from(reading.to_bits()) - i64::from(mean.to_bits());
        sum = sum.saturating_add(u128::from(deviation.unsigned_abs().pow(2)));
        count += 1;
    }
    if count == 0 {
        return None;
    }
    let variance = sum / count;
    // Deviations are below 2^32, so the variance is below 2^64 and its root below 2^32.
    let root = u64::try_from(variance).map_or(u64::MAX, |v| v.isqrt());
    i32::try_from(root)
        .ok()
        .map(Q1_31::from_bits)
        .or(Some(Q1_31::MAX))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rms_deviation_of_a_burst() {
        let q = |bits: i32| Q1_31::from_bits(bits);
        // Deviations -3, +3, -3, +3 lsb about 10: RMS 3.
        let burst = [q(7), q(13), q(7), q(13)];
        assert_eq!(rms_deviation(burst, q(10)), Some(q(3)));
        assert_eq!(rms_deviation([q(5); 8], q(5)), Some(Q1_31::ZERO));
        assert_eq!(rms_deviation([], q(0)), None);
        // The extremes: half the readings at each end of the range, about the middle.
        let wide = [Q1_31::MIN, Q1_31::MAX, Q1_31::MIN, Q1_31::MAX];
        let rms = rms_deviation(wide, Q1_31::ZERO).unwrap().to_f64();
        assert!((rms - 1.0).abs() < 1e-9, "{rms}");
    }

    fn q31(x: f64) -> Q1_31 {
        Q1_31::from_f64(x).unwrap()
    }

    fn q16(x: f64) -> Q16_16 {
        Q16_16::from_f64(x).unwrap()
    }

    #[test]
    fn tare_then_known_load_gives_the_load_back() {
        // A cell whose zero sits at 0.5 FS and which reads 0.7 FS under a 10 kg weight.
        let load = q16(98.0665);
        let calibration = Calibration::new(Q1_31::ZERO, Q16_16::ONE)
            .with_tare(q31(0.5))
            .with_known_load(q31(0.7), load)
            .unwrap();
        assert_eq!(calibration.apply(q31(0.5)), Sat::exact(Q16_16::ZERO));
        let back = calibration.apply(q31(0.7));
        assert!(!back.saturated);
        assert!((back.value.to_f64() - 98.0665).abs() < 2e-5);
        // Linear in between and beyond, and signed below the zero.
        let quarter = calibration.apply(q31(0.55)).value.to_f64();
        assert!((quarter - 98.0665 / 4.0).abs() < 2e-5);
        let negative = calibration.apply(q31(0.3)).value.to_f64();
        assert!((negative + 98.0665).abs() < 2e-5);
    }

    #[test]
    fn a_load_that_barely_moves_the_reading_is_refused() {
        let tared = Calibration::new(q31(0.25), Q16_16::ONE);
        let almost = Q1_31::from_bits(q31(0.25).to_bits() + (1 << 19) - 1);
        assert_eq!(
            tared.with_known_load(almost, q16(10.0)),
            Err(SenseError::SpanTooSmall)
        );
        // A huge load for a small movement overflows Q16.16 (over 32 767 N per full scale).
        let enough = Q1_31::from_bits(q31(0.25).to_bits() + (1 << 19));
        assert_eq!(
            tared.with_known_load(enough, q16(10.0)),
            Err(SenseError::Overflow)
        );
        // A negative movement gives a negative span: the sensor is mounted the other way.
        let flipped = tared.with_known_load(q31(0.15), q16(10.0)).unwrap();
        assert!(flipped.span().is_negative());
        assert!((flipped.apply(q31(0.15)).value.to_f64() - 10.0).abs() < 1e-4);
    }

    #[test]
    fn extreme_inputs_saturate_instead_of_overflowing() {
        let wide = Calibration::new(Q1_31::MIN, Q16_16::MAX);
        let top = wide.apply(Q1_31::MAX);
        assert_eq!(top, Sat::clamped(Q16_16::MAX));
        let inverted = Calibration::new(Q1_31::MAX, Q16_16::MIN);
        assert_eq!(inverted.apply(Q1_31::MIN), Sat::clamped(Q16_16::MAX));
        assert_eq!(inverted.apply(Q1_31::MAX), Sat::exact(Q16_16::ZERO));
        let other = Calibration::new(Q1_31::MIN, Q16_16::MIN);
        assert_eq!(other.apply(Q1_31::MAX), Sat::clamped(Q16_16::MIN));
    }

    /// A value that lands exactly on the largest Q16.16 (32 768 N less one ulp) fits: it is
    /// exact, not flagged as clamped; one ulp more is clamped. Offset -1 + 2^-31 and 16 384 N
    /// per full scale: the reading 1 - 2^-31 is 2 - 2^-30 full scales above the zero, i.e.
    /// 32 768 - 2^-16 N.
    #[test]
    fn a_value_on_the_top_of_q16_16_is_exact() {
        let top = Calibration::new(Q1_31::from_bits(i32::MIN + 1), q16(16_384.0));
        assert_eq!(top.apply(Q1_31::MAX), Sat::exact(Q16_16::MAX));
        let above = Calibration::new(Q1_31::MIN, q16(16_384.0));
        assert_eq!(above.apply(Q1_31::MAX), Sat::clamped(Q16_16::MAX));
        let bottom = Calibration::new(Q1_31::ZERO, q16(16_384.0));
        assert_eq!(
            bottom.apply(Q1_31::MIN),
            Sat::exact(Q16_16::from_int(-16_384).unwrap())
        );
    }

    #[test]
    fn the_inverse_finds_the_reading_of_a_value() {
        // A current sense: zero at 0.5 FS, 6.6 A per full scale.
        let current = Calibration::new(q31(0.5), q16(6.6));
        let reading = current.reading_for(q16(2.5)).unwrap();
        assert!((reading.to_f64() - (0.5 + 2.5 / 6.6)).abs() < 1e-6);
        let back = current.apply(reading).value.to_f64();
        assert!((back - 2.5).abs() < 2e-5);
        assert_eq!(current.reading_for(q16(4.0)), Err(SenseError::Overflow));
        assert_eq!(
            Calibration::new(Q1_31::ZERO, Q16_16::ZERO).reading_for(Q16_16::ONE),
            Err(SenseError::Overflow)
        );
    }

    #[test]
    fn the_mean_rounds_and_handles_empty_input() {
        assert_eq!(mean([]), None);
        let readings = [Q1_31::from_bits(1), Q1_31::from_bits(2)];
        assert_eq!(mean(readings), Some(Q1_31::from_bits(2))); // 1.5 rounds away from zero
        assert_eq!(mean([Q1_31::MAX; 1000]), Some(Q1_31::MAX));
        assert_eq!(mean([Q1_31::MIN; 1000]), Some(Q1_31::MIN));
        let negative = [Q1_31::from_bits(-1), Q1_31::from_bits(-2)];
        assert_eq!(mean(negative), Some(Q1_31::from_bits(-2)));
    }
}
