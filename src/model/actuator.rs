//! The PMN-PT stack actuator of seed 003 Table 1 (physics-notes §6) in fixed point: drive
//! voltage amplitude -> stack displacement amplitude, vibration velocity and drive current,
//! and the voltage and current ratings -> the largest admissible voltage at a frequency.
//!
//! - Free stroke d33 n V, reduced in series-spring fashion by the preload bolt:
//!   x_a = d33 n V K_stack / (K_stack + K_bolt) (Table 1, "Maximum displacement possible").
//! - v_a = 2 pi f x_a (seed 003 eq 2); I = 2 pi f C V (the stack is a capacitor, Table 1).
//! - V_limit = min(V_max, I_max / (2 pi f C)).
//!
//! Units in the hot path: volts Q16.16 (to 32767 V, 1.5e-5 V), kilohertz Q16.16 (1.5e-5 kHz =
//! 0.015 Hz), micrometres Q8.24 (to 128 um, 6e-8 um), m/s Q8.24, amperes Q8.24. The gains are
//! built once from SI values in f64 and carried as [`Scaled`] values. This is the quasi-static
//! stack of Table 1: it gives 0.121 um at 3 V where seed 003 measured 0.3 um (resonant gain the
//! table's model lacks; the paper-number table records the gap).

use crate::fx::{Q2_30, Q8_24, Q16_16};

use super::ModelError;
use super::fx_error;
use crate::fx::Scaled;
use crate::fx::wide;

/// SI parameters of the stack (seed 003 Table 1: n = 62, d33 = 730 pm/V, C = 300 nF,
/// K_stack = 3.14e8 N/m, K_bolt = 3.7e7 N/m, V_max = 15.466 V, I_max = 1.75 A).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorParams {
    /// Number of discs n (a whole number >= 1).
    pub discs: f64,
    /// Piezoelectric coefficient d33 in m/V (> 0).
    pub d33_m_per_v: f64,
    /// Stack capacitance C in farads (> 0).
    pub capacitance_f: f64,
    /// Stack stiffness in N/m (> 0).
    pub stack_stiffness: f64,
    /// Preload bolt stiffness in N/m (>= 0).
    pub bolt_stiffness: f64,
    /// Voltage rating V_max in volts (> 0, below 32768).
    pub max_voltage_v: f64,
    /// Current rating I_max in amperes (> 0, below 128).
    pub max_current_a: f64,
}

impl ActuatorParams {
    /// The PMN-PT stack of seed 003 (Bharadwaj & Dapino) Table 1, SI units: n = 62 discs,
    /// d33 = 730 pm/V, C = 300 nF, K_stack = 3.14e8 N/m, K_bolt = 3.7e7 N/m, and the ratings
    /// `V_max = dL / (d33 n) = 0.7 um / (730 pm/V * 62) = 15.466 V` and `I_max = 1.75 A`
    /// (2 pi f C V_max at 60 kHz). The one definition of these numbers in the firmware core:
    /// `crate::drive::StackRatings::SEED_003` and
    /// `crate::control::ActuatorRatings::SEED_003_40_KHZ` take their ratings from it. The f64
    /// reference in host-tests keeps its own copy (`reference::examples`, the `actuator`
    /// inputs) so that the two are written independently.
    pub const SEED_003_TABLE_1: Self = Self {
        discs: 62.0,
        d33_m_per_v: 730e-12,
        capacitance_f: 300e-9,
        stack_stiffness: 3.14e8,
        bolt_stiffness: 3.7e7,
        max_voltage_v: 0.7e-6 / (730e-12 * 62.0),
        max_current_a: 1.75,
    };
}

/// Scene constants of the actuator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ActuatorConstants {
    /// d33 n K_stack / (K_stack + K_bolt) in um/V.
    stroke_per_volt: Scaled,
    /// 2 pi 1e3 C in A / (V kHz).
    current_per_volt_khz: Scaled,
    /// I_max / (2 pi 1e3 C) in V kHz.
    current_corner: Scaled,
    max_voltage: Q16_16,
    max_current: Q8_24,
}

/// 2 pi 1e-3: m/s per (kHz um), Q2.30.
const VELOCITY_PER_KHZ_UM: Q2_30 = Q2_30::from_f64_const(core::f64::consts::TAU * 1e-3);

impl ActuatorConstants {
    /// Constants from SI values (f64, scene load). Errors: `NonFinite`; `OutOfDomain` for n
    /// not a whole number >= 1, d33, C, K_stack, V_max or I_max <= 0, K_bolt < 0, V_max >=
    /// 32768 V or I_max >= 128 A.
    pub fn new(params: &ActuatorParams) -> Result<Self, ModelError> {
        let n = params.discs;
        if !n.is_finite() {
            return Err(ModelError::NonFinite { input: "n" });
        }
        if n < 1.0 || libm::trunc(n) != n {
            return Err(ModelError::OutOfDomain {
                input: "n",
                reason: "must be a whole number of discs >= 1",
            });
        }
        let d33 = crate::model::scaled_from_f64(params.d33_m_per_v, "d33")?.to_f64();
        let c = crate::model::scaled_from_f64(params.capacitance_f, "C")?.to_f64();
        let k_stack = crate::model::scaled_from_f64(params.stack_stiffness, "K_stack")?.to_f64();
        let k_bolt = params.bolt_stiffness;
        if !k_bolt.is_finite() {
            return Err(ModelError::NonFinite { input: "K_bolt" });
        }
        if k_bolt < 0.0 {
            return Err(ModelError::OutOfDomain {
                input: "K_bolt",
                reason: "must be >= 0",
            });
        }
        let v_max = crate::model::scaled_from_f64(params.max_voltage_v, "V_max")?.to_f64();
        let i_max = crate::model::scaled_from_f64(params.max_current_a, "I_max")?.to_f64();
        let omega_per_khz = core::f64::consts::TAU * 1e3;
        Ok(Self {
            stroke_per_volt: crate::model::scaled_from_f64(
                d33 * n * (k_stack / (k_stack + k_bolt)) * 1e6,
                "d33",
            )?,
            current_per_volt_khz: crate::model::scaled_from_f64(omega_per_khz * c, "C")?,
            current_corner: crate::model::scaled_from_f64(i_max / (omega_per_khz * c), "I_max")?,
            max_voltage: Q16_16::from_f64(v_max).map_err(fx_error("V_max"))?,
            max_current: Q8_24::from_f64(i_max).map_err(fx_error("I_max"))?,
        })
    }

    /// Displacement amplitude x_a in um (Q8.24) at the voltage amplitude `voltage` (volts,
    /// Q16.16, >= 0). Errors: `OutOfDomain` for V < 0, `Overflow` beyond 128 um (saturation
    /// is reported, never returned). Cost: a CLZ and one product.
    pub fn stroke_um(&self, voltage: Q16_16) -> Result<Q8_24, ModelError> {
        non_negative("V", voltage)?;
        exact(wide::mul_q::<24, 16>(self.stroke_per_volt, voltage), "x_a")
    }

    /// Vibration velocity amplitude v_a = 2 pi f x_a in m/s (Q8.24) for a stroke in um (Q8.24,
    /// non-negative) at `frequency_khz` (kHz, Q16.16, positive). Errors: `OutOfDomain`,
    /// `Overflow` beyond 128 m/s.
    pub fn vibration_velocity(
        &self,
        stroke_um: Q8_24,
        frequency_khz: Q16_16,
    ) -> Result<Q8_24, ModelError> {
        non_negative("x_a", stroke_um)?;
        let f = positive_khz(frequency_khz)?;
        let Some(x) = wide::from_q(stroke_um) else {
            return Ok(Q8_24::ZERO);
        };
        let product = wide::mul(f, x);
        exact(wide::mul_q::<24, 30>(product, VELOCITY_PER_KHZ_UM), "v_a")
    }

    /// Current amplitude I = 2 pi f C V in amperes (Q8.24) at `voltage` (V, Q16.16, >= 0) and
    /// `frequency_khz` (kHz, Q16.16, > 0). Errors: `OutOfDomain`, `Overflow` beyond 128 A.
    pub fn current(&self, voltage: Q16_16, frequency_khz: Q16_16) -> Result<Q8_24, ModelError> {
        non_negative("V", voltage)?;
        let f = positive_khz(frequency_khz)?;
        exact(
            wide::mul_q::<24, 16>(wide::mul(self.current_per_volt_khz, f), voltage),
            "I",
        )
    }

    /// Largest admissible voltage amplitude min(V_max, I_max / (2 pi f C)) in volts (Q16.16)
    /// at `frequency_khz` (kHz, Q16.16, > 0). A current limit beyond the Q16.16 range is above
    /// V_max anyway: that saturation is harmless and not reported. Cost: one reciprocal, one
    /// product.
    pub fn voltage_limit(&self, frequency_khz: Q16_16) -> Result<Q16_16, ModelError> {
        let f = positive_khz(frequency_khz)?;
        let by_current = wide::to_q::<16>(wide::mul(self.current_corner, wide::recip(f))).value;
        Ok(by_current.min(self.max_voltage))
    }

    /// Whether V <= V_max and I(V, f) <= I_max (comparisons of the fixed-point values: within
    /// one ulp of a rating the answer may differ from an f64 evaluation).
    pub fn within_limits(
        &self,
        voltage: Q16_16,
        frequency_khz: Q16_16,
    ) -> Result<bool, ModelError> {
        if voltage > self.max_voltage {
            return Ok(false);
        }
        match self.current(voltage, frequency_khz) {
            Ok(current) => Ok(current <= self.max_current),
            Err(ModelError::Overflow { .. }) => Ok(false),
            Err(e) => Err(e),
        }
    }
}

fn non_negative<const F: u32>(input: &'static str, x: crate::fx::Q<F>) -> Result<(), ModelError> {
    if x.is_negative() {
        Err(ModelError::OutOfDomain {
            input,
            reason: "must be >= 0",
        })
    } else {
        Ok(())
    }
}

fn positive_khz(frequency_khz: Q16_16) -> Result<Scaled, ModelError> {
    wide::from_q(frequency_khz).ok_or(ModelError::OutOfDomain {
        input: "f",
        reason: "must be > 0",
    })
}

fn exact<T>(s: crate::fx::Sat<T>, quantity: &'static str) -> Result<T, ModelError> {
    s.exact_or_overflow().map_err(fx_error(quantity))
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::TAU;

    fn seed003() -> ActuatorConstants {
        ActuatorConstants::new(&ActuatorParams::SEED_003_TABLE_1).unwrap()
    }

    fn q16(x: f64) -> Q16_16 {
        Q16_16::from_f64(x).unwrap()
    }

    #[test]
    fn seed_003_table_1() {
        let a = seed003();
        let v_max = 0.7e-6 / (730e-12 * 62.0);
        // I_max = 2 pi f C V_max = 1.749 A at 60 kHz; Z = 1 / (C omega) = 8.84 ohm.
        let i = a.current(q16(v_max), q16(60.0)).unwrap().to_f64();
        let v_q = q16(v_max).to_f64();
        assert!((i / (TAU * 60e3 * 300e-9 * v_q) - 1.0).abs() < 1e-6, "{i}");
        assert!((v_q / i - 8.84).abs() < 0.005);
        // 32.2 um at the nominal 36 um free stroke; 0.7 um free at V_max (no bolt).
        let v36 = q16(36e-6 / (730e-12 * 62.0));
        let x = a.stroke_um(v36).unwrap().to_f64();
        let want = 730e-12 * 62.0 * v36.to_f64() * 3.14e8 / (3.14e8 + 3.7e7) * 1e6;
        assert!(
            (x / want - 1.0).abs() < 1e-6 && (x - 32.2).abs() < 0.05,
            "{x}"
        );
        let free = ActuatorConstants::new(&ActuatorParams {
            bolt_stiffness: 0.0,
            ..ActuatorParams::SEED_003_TABLE_1
        })
        .unwrap();
        assert!((free.stroke_um(q16(v_max)).unwrap().to_f64() - 0.7).abs() < 1e-5);
        // 3 V amplitude: 0.121 um, v_a = 2 pi 40 kHz x_a.
        let x3 = a.stroke_um(q16(3.0)).unwrap();
        let want = 730e-12 * 62.0 * 3.0 * 3.14e8 / (3.14e8 + 3.7e7) * 1e6; // 0.1215 um
        assert!((x3.to_f64() - want).abs() < 2e-7, "{x3:?}");
        let v_a = a.vibration_velocity(x3, q16(40.0)).unwrap().to_f64();
        assert!((v_a / (TAU * 40e3 * x3.to_f64() * 1e-6) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn limits() {
        let a = seed003();
        // At 60 kHz the current limit is just above V_max: V_max rules; at 80 kHz the current.
        let v_max = a.voltage_limit(q16(60.0)).unwrap().to_f64();
        assert!((v_max - 15.466).abs() < 1e-3);
        let at_80 = a.voltage_limit(q16(80.0)).unwrap().to_f64();
        assert!((at_80 - 1.75 / (TAU * 80e3 * 300e-9)).abs() < 1e-4);
        assert_eq!(a.within_limits(q16(15.0), q16(60.0)), Ok(true));
        assert_eq!(a.within_limits(q16(16.0), q16(20.0)), Ok(false));
        assert_eq!(a.within_limits(q16(14.0), q16(80.0)), Ok(false));
        assert_eq!(a.within_limits(q16(30_000.0), q16(30_000.0)), Ok(false));
        assert!(a.current(q16(-1.0), q16(40.0)).is_err());
        assert!(a.voltage_limit(Q16_16::ZERO).is_err());
        assert!(matches!(
            a.stroke_um(q16(30_000.0)),
            Err(ModelError::Overflow { .. })
        ));
        assert_eq!(
            a.vibration_velocity(Q8_24::ZERO, q16(40.0)),
            Ok(Q8_24::ZERO)
        );
        let bad = |p: ActuatorParams| ActuatorConstants::new(&p).is_err();
        let s = ActuatorParams::SEED_003_TABLE_1;
        assert!(
            bad(ActuatorParams { discs: 61.5, ..s }) && bad(ActuatorParams { discs: 0.0, ..s })
        );
        assert!(bad(ActuatorParams {
            bolt_stiffness: -1.0,
            ..s
        }));
        assert!(bad(ActuatorParams {
            capacitance_f: f64::NAN,
            ..s
        }));
        assert!(bad(ActuatorParams {
            max_current_a: 200.0,
            ..s
        }));
    }
}
