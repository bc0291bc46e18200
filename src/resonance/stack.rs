//! The stack's nominal electrical data, in the fixed-point form the search and the tracker use.

use super::error::ResonanceError;
use super::motional::ClampedCapacitance;
use crate::drive::{Amplitude, Frequency};
use crate::fx::Q2_30;

/// What the firmware believes about the stack and its current sense (set-up, f64). The
/// defaults of the NUCLEO board and the reference stack are in
/// [`StackSettings::REFERENCE`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StackSettings {
    /// Nominal motional resonance f0, Hz, in 20-60 kHz.
    pub resonance_hz: f64,
    /// Nominal quality factor Q, 1 to 1e4: sets the half-bandwidth `f / 2Q` (Hz per unit of
    /// detuning near `f`) and the envelope time constant `2Q / (2 pi f0)`.
    pub quality_factor: f64,
    /// Clamped capacitance C0, F, >= 0 (0: no compensation, V-I phase).
    pub clamped_capacitance_f: f64,
    /// Fundamental voltage on the stack at full drive amplitude, V, > 0.
    pub full_scale_voltage_v: f64,
    /// Amperes per unit fraction of the current sensor's full scale, > 0.
    pub amperes_per_full_scale: f64,
    /// Admittance magnitude below which the stack counts as disconnected, S, > 0. A quarter of
    /// C0's susceptance at 20 kHz keeps a connected stack far above it anywhere in the band.
    pub min_admittance_s: f64,
}

impl StackSettings {
    /// The seed 003 stack of `scenes/reference.toml` (40 kHz, Q 100, C0 300 nF, 5.25 V full
    /// scale) on the NUCLEO current sense (25 mOhm, 20 V/V, 3.3 V: 6.6 A per full scale).
    pub const REFERENCE: Self = Self {
        resonance_hz: 40_000.0,
        quality_factor: 100.0,
        clamped_capacitance_f: 300e-9,
        full_scale_voltage_v: 5.25,
        amperes_per_full_scale: 6.6,
        min_admittance_s: 0.01,
    };
}

/// [`StackSettings`] in fixed point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StackModel {
    capacitance: ClampedCapacitance,
    /// `1 / 2Q` in Q0.32 (at most 2^31 for Q >= 1).
    inverse_2q_q32: u32,
    time_constant_ns: u32,
    /// No-current threshold at full amplitude, Q2.30 full scale.
    min_current: Q2_30,
}

impl StackModel {
    /// The fixed-point model. Error `Setting` for a value outside its stated range or a
    /// threshold that does not fit Q2.30.
    pub fn new(settings: &StackSettings) -> Result<Self, ResonanceError> {
        let s = settings;
        let f0_ok = (20_000.0..=60_000.0).contains(&s.resonance_hz);
        let q_ok = (1.0..=1e4).contains(&s.quality_factor);
        let admittance_ok = s.min_admittance_s.is_finite() && s.min_admittance_s > 0.0;
        if !(f0_ok && q_ok && admittance_ok) {
            return Err(ResonanceError::Setting);
        }
        let capacitance = ClampedCapacitance::new(
            s.clamped_capacitance_f,
            s.full_scale_voltage_v,
            s.amperes_per_full_scale,
        )?;
        let min_current = s.min_admittance_s * s.full_scale_voltage_v / s.amperes_per_full_scale;
        let min_current = Q2_30::from_f64(min_current).map_err(|_| ResonanceError::Setting)?;
        let time_constant_s = s.quality_factor / (core::f64::consts::PI * s.resonance_hz);
        Ok(Self {
            capacitance,
            // 1 / 2Q <= 1/2 and tau <= 1e4 / (pi 2e4) = 0.16 s: both fit u32.
            inverse_2q_q32: libm::round(4_294_967_296.0 / (2.0 * s.quality_factor)) as u32,
            time_constant_ns: libm::round(time_constant_s * 1e9) as u32,
            min_current,
        })
    }

    /// C0's current model.
    pub const fn capacitance(&self) -> ClampedCapacitance {
        self.capacitance
    }

    /// The half-bandwidth `f / 2Q` near `frequency`, mHz: the frequency error per unit of
    /// detuning there (`x = Q (f/f0 - f0/f)`, so `f - f0 = x f / 2Q` to first order). Taken at
    /// the drive frequency rather than at the nominal f0, so the loop gain stays right over a
    /// wide band (the bandwidth at 20 kHz is half that at 40 kHz). One multiplication.
    pub const fn half_bandwidth_mhz(&self, frequency: Frequency) -> u32 {
        // mHz < 2^32, factor <= 2^31: the product fits u64 and the result u32.
        ((frequency.millihertz() as u64 * self.inverse_2q_q32 as u64 + (1 << 31)) >> 32) as u32
    }

    /// Nominal envelope time constant `2Q / (2 pi f0)`, ns (795 775 for the reference stack).
    pub const fn time_constant_ns(&self) -> u32 {
        self.time_constant_ns
    }

    /// The no-current threshold at drive `amplitude`, Q2.30 full scale (one multiplication).
    pub const fn min_current(&self, amplitude: Amplitude) -> Q2_30 {
        let bits = (self.min_current.to_bits() as i64 * amplitude.fraction().to_bits() as i64
            + (1 << 29))
            >> 30;
        Q2_30::from_bits(bits as i32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_stack_numbers() {
        let model = StackModel::new(&StackSettings::REFERENCE).unwrap();
        assert_eq!(
            model.half_bandwidth_mhz(Frequency::from_hz(40_000)),
            200_000
        );
        assert_eq!(
            model.half_bandwidth_mhz(Frequency::from_hz(20_000)),
            100_000
        );
        assert_eq!(model.time_constant_ns(), 795_775);
        // 0.01 S x 5.25 V / 6.6 A = 0.00795 full scale at full amplitude.
        let full = model.min_current(Amplitude::FULL).to_f64();
        assert!((full - 0.01 * 5.25 / 6.6).abs() < 1e-9);
        let tenth = Amplitude::from_ratio(1, 10).unwrap();
        assert!((model.min_current(tenth).to_f64() - full / 10.0).abs() < 1e-9);
    }

    #[test]
    fn settings_out_of_range_are_refused() {
        let base = StackSettings::REFERENCE;
        for bad in [
            StackSettings {
                resonance_hz: 19_999.0,
                ..base
            },
            StackSettings {
                quality_factor: 0.5,
                ..base
            },
            StackSettings {
                min_admittance_s: 0.0,
                ..base
            },
            StackSettings {
                min_admittance_s: 1e3,
                ..base
            },
            StackSettings {
                full_scale_voltage_v: -1.0,
                ..base
            },
        ] {
            assert_eq!(
                StackModel::new(&bad),
                Err(ResonanceError::Setting),
                "{bad:?}"
            );
        }
    }
}
