//! Nominal calibrations from the analog front end's data sheet values.
//!
//! Before a tare and a known load are available, a channel still needs a calibration that
//! gives roughly the right newtons or amperes (and the overcurrent comparator needs its
//! threshold before the drive ever runs). These compute it from the parts: shunt and
//! amplifier for the drive current, bridge and amplifier for a load cell. One-time
//! configuration; integer arithmetic (`u128`) so the results are exact and reproducible.

use super::calibration::Calibration;
use super::error::SenseError;
use crate::fx::{Q1_31, Q16_16};

/// A current shunt and a current-sense amplifier feeding an ADC input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShuntAmplifier {
    /// Shunt resistance, micro-ohms (25 mOhm = 25 000).
    pub shunt_micro_ohm: u32,
    /// Amplifier gain, milli-V/V (20 V/V = 20 000).
    pub gain_milli: u32,
    /// Amplifier output at zero current, millivolts (a bidirectional amplifier referenced to
    /// mid-supply: 1650 at 3.3 V).
    pub zero_millivolt: u32,
    /// The ADC's full scale (VREF+), millivolts.
    pub full_scale_millivolt: u32,
}

impl ShuntAmplifier {
    /// The calibration: zero at `zero / full scale`, `full scale / (R gain)` amperes per full
    /// scale. Errors: `InvalidFrontEnd` for a zero value or a zero above full scale, `Overflow`
    /// above 32 767 A per full scale.
    pub fn calibration(&self) -> Result<Calibration, SenseError> {
        if self.shunt_micro_ohm == 0
            || self.gain_milli == 0
            || self.full_scale_millivolt == 0
            || self.zero_millivolt >= self.full_scale_millivolt
        {
            return Err(SenseError::InvalidFrontEnd);
        }
        let offset = fraction(self.zero_millivolt, self.full_scale_millivolt);
        // A per FS = (FS_mV / 1e3) / ((R_uOhm / 1e6) (G_milli / 1e3)) = FS_mV 1e6 / (R G).
        let numerator = (u128::from(self.full_scale_millivolt) * 1_000_000) << 16;
        let denominator = u128::from(self.shunt_micro_ohm) * u128::from(self.gain_milli);
        Ok(Calibration::new(offset, q16_16(numerator, denominator)?))
    }
}

/// A strain-gauge load cell and the amplifier (instrumentation amplifier or the external ADC's
/// PGA) between it and the converter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BridgeAmplifier {
    /// Rated capacity of the cell, newtons.
    pub rated_load_n: u32,
    /// Rated output, microvolts per volt of excitation (2 mV/V = 2000).
    pub sensitivity_uv_per_v: u32,
    /// Bridge excitation, millivolts.
    pub excitation_millivolt: u32,
    /// Gain between bridge and converter, milli-V/V (128 = 128 000).
    pub gain_milli: u32,
    /// Input voltage of one converter full scale, microvolts: VREF+ for the G4 ADC
    /// (3 300 000), 1.2 V for the ADS131M02 (1 200 000; its codes span +-1 full scale).
    pub full_scale_microvolt: u32,
    /// The reading at zero load: 1/2 for an instrumentation amplifier whose reference pin sits
    /// at mid-supply, 0 for a differential bipolar converter.
    pub zero: Q1_31,
}

impl BridgeAmplifier {
    /// The calibration: `rated load * full scale / (sensitivity * excitation * gain)` newtons
    /// per full scale. Errors: `InvalidFrontEnd` for a zero value, `Overflow` above 32 767 N
    /// per full scale.
    pub fn calibration(&self) -> Result<Calibration, SenseError> {
        if self.rated_load_n == 0
            || self.sensitivity_uv_per_v == 0
            || self.excitation_millivolt == 0
            || self.gain_milli == 0
            || self.full_scale_microvolt == 0
        {
            return Err(SenseError::InvalidFrontEnd);
        }
        // Bridge output at rated load: uV/V * mV = nV; times gain_milli / 1000. Full scale in
        // nV: uV * 1000. So N per FS = rated * FS_uV * 1e6 / (sens * exc * gain_milli).
        let numerator =
            (u128::from(self.rated_load_n) * u128::from(self.full_scale_microvolt) * 1_000_000)
                << 16;
        let denominator = u128::from(self.sensitivity_uv_per_v)
            * u128::from(self.excitation_millivolt)
            * u128::from(self.gain_milli);
        Ok(Calibration::new(self.zero, q16_16(numerator, denominator)?))
    }
}

/// `part / whole` as Q1.31, for `part < whole`.
fn fraction(part: u32, whole: u32) -> Q1_31 {
    // part < whole: the quotient is below 2^31.
    let bits = ((u64::from(part) << 31) + u64::from(whole) / 2) / u64::from(whole);
    Q1_31::from_bits(i32::try_from(bits).unwrap_or(i32::MAX))
}

/// `numerator / denominator` (already scaled by 2^16), rounded, as Q16.16.
fn q16_16(numerator: u128, denominator: u128) -> Result<Q16_16, SenseError> {
    let bits = (numerator + denominator / 2) / denominator;
    i32::try_from(bits)
        .map(Q16_16::from_bits)
        .map_err(|_| SenseError::Overflow)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The drive-current chain of the board README: 25 mOhm, INA240A1 (20 V/V), mid-supply zero.
    const BOARD_SHUNT: ShuntAmplifier = ShuntAmplifier {
        shunt_micro_ohm: 25_000,
        gain_milli: 20_000,
        zero_millivolt: 1650,
        full_scale_millivolt: 3300,
    };

    #[test]
    fn the_board_current_sense_spans_6_6_a() {
        let calibration = BOARD_SHUNT.calibration().unwrap();
        assert_eq!(calibration.offset(), Q1_31::from_bits(1 << 30));
        assert_eq!(calibration.span(), Q16_16::from_ratio(66, 10).unwrap());
        // 0.5 V/A: 1.75 A (seed 003 I_max) reads 1.65 V + 0.875 V = 0.765 FS.
        let reading = calibration
            .reading_for(Q16_16::from_ratio(175, 100).unwrap())
            .unwrap();
        assert!((reading.to_f64() - 2.525 / 3.3).abs() < 1e-6);
    }

    #[test]
    fn a_50_lbf_cell_on_either_converter() {
        // 222 N, 2 mV/V, 5 V excitation. INA (gain 150) into the 3.3 V G4 ADC:
        let ina = BridgeAmplifier {
            rated_load_n: 222,
            sensitivity_uv_per_v: 2000,
            excitation_millivolt: 5000,
            gain_milli: 150_000,
            full_scale_microvolt: 3_300_000,
            zero: Q1_31::from_bits(1 << 30),
        };
        let span = ina.calibration().unwrap().span().to_f64();
        assert!((span - 488.4).abs() < 1e-3, "{span}");
        // ADS131M02 with PGA 64: 10 mV * 64 = 0.64 V of a 1.2 V full scale.
        let ads = BridgeAmplifier {
            gain_milli: 64_000,
            full_scale_microvolt: 1_200_000,
            zero: Q1_31::ZERO,
            ..ina
        };
        let calibration = ads.calibration().unwrap();
        assert!((calibration.span().to_f64() - 416.25).abs() < 1e-3);
        // Rated load reads 0.64 / 1.2 of full scale and converts back to 222 N.
        let rated = Q1_31::from_f64(0.64 / 1.2).unwrap();
        assert!((calibration.apply(rated).value.to_f64() - 222.0).abs() < 1e-3);
    }

    #[test]
    fn nonsense_front_ends_are_refused() {
        let zero_shunt = ShuntAmplifier {
            shunt_micro_ohm: 0,
            ..BOARD_SHUNT
        };
        assert_eq!(zero_shunt.calibration(), Err(SenseError::InvalidFrontEnd));
        let zero_above_scale = ShuntAmplifier {
            zero_millivolt: 3300,
            ..BOARD_SHUNT
        };
        assert_eq!(
            zero_above_scale.calibration(),
            Err(SenseError::InvalidFrontEnd)
        );
        // 1 uOhm with unity gain: 3.3 MA per full scale does not fit Q16.16.
        let tiny = ShuntAmplifier {
            shunt_micro_ohm: 1,
            gain_milli: 1000,
            ..BOARD_SHUNT
        };
        assert_eq!(tiny.calibration(), Err(SenseError::Overflow));
        let bridge = BridgeAmplifier {
            rated_load_n: u32::MAX,
            sensitivity_uv_per_v: 1,
            excitation_millivolt: 1,
            gain_milli: 1,
            full_scale_microvolt: u32::MAX,
            zero: Q1_31::ZERO,
        };
        assert_eq!(bridge.calibration(), Err(SenseError::Overflow));
        let no_gain = BridgeAmplifier {
            gain_milli: 0,
            ..bridge
        };
        assert_eq!(no_gain.calibration(), Err(SenseError::InvalidFrontEnd));
    }

    /// Each of the bridge chain's five values, zero on its own, is refused (a zero
    /// sensitivity, excitation or gain would otherwise divide by zero).
    #[test]
    fn each_zero_value_of_a_bridge_is_refused_alone() {
        let cell = BridgeAmplifier {
            rated_load_n: 222,
            sensitivity_uv_per_v: 2000,
            excitation_millivolt: 5000,
            gain_milli: 150_000,
            full_scale_microvolt: 3_300_000,
            zero: Q1_31::ZERO,
        };
        assert!(cell.calibration().is_ok());
        let zeroed = [
            BridgeAmplifier {
                rated_load_n: 0,
                ..cell
            },
            BridgeAmplifier {
                sensitivity_uv_per_v: 0,
                ..cell
            },
            BridgeAmplifier {
                excitation_millivolt: 0,
                ..cell
            },
            BridgeAmplifier {
                gain_milli: 0,
                ..cell
            },
            BridgeAmplifier {
                full_scale_microvolt: 0,
                ..cell
            },
        ];
        for bridge in zeroed {
            assert_eq!(
                bridge.calibration(),
                Err(SenseError::InvalidFrontEnd),
                "{bridge:?}"
            );
        }
    }
}
