//! One sensor channel from raw code to physical value: format, fault checks, calibration.

use super::calibration::{Calibration, mean, rms_deviation};
use super::error::SenseError;
use super::fault::{FaultLimits, FaultMonitor, SensorFault};
use super::format::{AdcCode, AdcFormat};
use crate::fx::{Q1_31, Q16_16, Sat};

/// What can go wrong with one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SampleError {
    /// The code cannot come from this converter (a corrupted transfer or a wrong format).
    Code(SenseError),
    /// The sensor itself is faulty.
    Fault(SensorFault),
}

/// A load-cell or current channel: the converter's format, the fault checks and the
/// calibration, so the sampling code makes one call per sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorChannel {
    format: AdcFormat,
    calibration: Calibration,
    monitor: FaultMonitor,
    /// The RMS noise of the last tare's burst, Q1.31 fraction of full scale (its standard
    /// deviation about its mean); `None` before a tare.
    noise: Option<Q1_31>,
}

impl SensorChannel {
    /// A channel reading codes of `format`, checked against `limits`, converted with
    /// `calibration`.
    pub const fn new(format: AdcFormat, limits: FaultLimits, calibration: Calibration) -> Self {
        Self {
            format,
            calibration,
            monitor: FaultMonitor::new(format, limits),
            noise: None,
        }
    }

    /// Checks and converts one raw code. The value is Q16.16 newtons or amperes, clamped with
    /// the flag set if out of range. Integer only (one 64-bit multiply plus comparisons).
    pub fn process(&mut self, code: AdcCode) -> Result<Sat<Q16_16>, SampleError> {
        let reading = self.format.normalize(code).map_err(SampleError::Code)?;
        self.monitor.check(reading).map_err(SampleError::Fault)?;
        Ok(self.calibration.apply(reading))
    }

    /// Sets the zero to the mean of `codes` taken with no load (or with the drive off), and
    /// measures the cell's noise as the burst's RMS deviation from that mean (the load is
    /// steady, so what moves is the cell's and the converter's noise, quantisation included):
    /// [`Self::noise`]. Errors: `InvalidFormat` for no codes, `CodeOutOfRange` for a code the
    /// converter cannot produce.
    pub fn tare(&mut self, codes: &[AdcCode]) -> Result<(), SenseError> {
        let zero = self.mean_reading(codes)?;
        let readings = codes
            .iter()
            .filter_map(|&code| self.format.normalize(code).ok());
        self.noise = rms_deviation(readings, zero);
        self.calibration = self.calibration.with_tare(zero);
        Ok(())
    }

    /// The noise the last tare measured, RMS per sample, in the channel's unit (Q16.16
    /// newtons): the burst's RMS deviation times the span, rounded up by one lsb so that a
    /// noisy cell never reads as noise-free; saturating at the Q16.16 maximum. `None` before a
    /// tare. The controller's tuning takes it (`control::Settings::tangential_noise_n`).
    pub fn noise(&self) -> Option<Q16_16> {
        let noise = self.noise?;
        let span = i64::from(self.calibration.span().to_bits()).unsigned_abs();
        // noise < 2^31 and span <= 2^31: the product < 2^62; >> 31 gives Q16.16.
        let value = ((u64::from(noise.to_bits().unsigned_abs()) * span) >> 31) + 1;
        Some(i32::try_from(value).map_or(Q16_16::MAX, Q16_16::from_bits))
    }

    /// Sets the span so that the mean of `codes`, taken under `load` (Q16.16 newtons), reads
    /// `load`. Tare first. Errors: those of [`Self::tare`] and
    /// [`Calibration::with_known_load`].
    pub fn calibrate_gain(&mut self, codes: &[AdcCode], load: Q16_16) -> Result<(), SenseError> {
        let loaded = self.mean_reading(codes)?;
        self.calibration = self.calibration.with_known_load(loaded, load)?;
        Ok(())
    }

    fn mean_reading(&self, codes: &[AdcCode]) -> Result<Q1_31, SenseError> {
        for &code in codes {
            self.format.normalize(code)?;
        }
        let readings = codes
            .iter()
            .filter_map(|&code| self.format.normalize(code).ok());
        mean(readings).ok_or(SenseError::InvalidFormat)
    }

    /// Replaces the calibration (a stored one, see [`crate::settings`]); the fault history is
    /// kept.
    pub fn set_calibration(&mut self, calibration: Calibration) {
        self.calibration = calibration;
    }

    /// The calibration in use.
    pub const fn calibration(&self) -> Calibration {
        self.calibration
    }

    /// The converter format.
    pub const fn format(&self) -> AdcFormat {
        self.format
    }

    /// Forgets the fault history (after a pause in sampling).
    pub fn reset_faults(&mut self) {
        self.monitor.reset();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sense::format::Oversampling;

    fn channel() -> SensorChannel {
        let format = AdcFormat::oversampled(12, Oversampling::new(4, 0).unwrap()).unwrap();
        let limits = FaultLimits {
            rail_margin: Q1_31::from_bits(1 << 22),
            noise_band: Q1_31::ZERO,
            stuck_samples: 0,
            max_step: Q1_31::from_bits(1 << 28),
        };
        // Nominal: zero at mid-scale, 500 N per full scale.
        let nominal = Calibration::new(Q1_31::from_bits(1 << 30), Q16_16::from_int_const(500));
        SensorChannel::new(format, limits, nominal)
    }

    #[test]
    fn tare_and_gain_from_bursts_of_codes() {
        let mut cell = channel();
        cell.tare(&[33_000, 33_002, 32_998, 33_000].map(AdcCode::new))
            .unwrap();
        assert_eq!(
            cell.process(AdcCode::new(33_000)),
            Ok(Sat::exact(Q16_16::ZERO))
        );
        // 20 N makes the reading rise by 1311 LSB.
        cell.calibrate_gain(
            &[34_311, 34_311].map(AdcCode::new),
            Q16_16::from_int_const(20),
        )
        .unwrap();
        let value = cell.process(AdcCode::new(34_311)).unwrap();
        assert!((value.value.to_f64() - 20.0).abs() < 1e-3);
        let half = cell.process(AdcCode::new(33_656)).unwrap().value.to_f64();
        assert!((half - 10.0).abs() < 0.02, "{half}");
    }

    #[test]
    fn the_tare_measures_the_cells_noise() {
        let mut cell = channel();
        assert_eq!(cell.noise(), None);
        // +-8 codes of the 16-bit result about 33 000: 8 / 65 536 of full scale, 500 N per full
        // scale: 0.061 N RMS.
        let burst: [i32; 64] = core::array::from_fn(|k| if k % 2 == 0 { 32_992 } else { 33_008 });
        cell.tare(&burst.map(AdcCode::new)).unwrap();
        let noise = cell.noise().unwrap().to_f64();
        assert!((noise - 500.0 * 8.0 / 65_536.0).abs() < 1e-4, "{noise}");
        // A quiet burst reads one lsb, not zero; a burst four times as noisy, four times.
        cell.tare(&[33_000; 16].map(AdcCode::new)).unwrap();
        assert_eq!(cell.noise(), Some(Q16_16::from_bits(1)));
        let loud: [i32; 64] = core::array::from_fn(|k| if k % 2 == 0 { 32_968 } else { 33_032 });
        cell.tare(&loud.map(AdcCode::new)).unwrap();
        let ratio = cell.noise().unwrap().to_f64() / noise;
        assert!((ratio - 4.0).abs() < 1e-3, "{ratio}");
    }

    #[test]
    fn bad_codes_and_faults_are_told_apart() {
        let mut cell = channel();
        assert_eq!(
            cell.process(AdcCode::new(65_521)),
            Err(SampleError::Code(SenseError::CodeOutOfRange {
                code: 65_521
            }))
        );
        assert!(matches!(
            cell.process(AdcCode::new(65_520)),
            Err(SampleError::Fault(SensorFault::HighRail { .. }))
        ));
        cell.reset_faults();
        assert!(cell.process(AdcCode::new(30_000)).is_ok());
        assert_eq!(cell.tare(&[]), Err(SenseError::InvalidFormat));
        assert_eq!(
            cell.tare(&[1, -5].map(AdcCode::new)),
            Err(SenseError::CodeOutOfRange { code: -5 })
        );
        // A failed tare leaves the calibration alone.
        assert_eq!(cell.calibration(), channel().calibration());
        assert_eq!(cell.format(), channel().format());
    }
}
