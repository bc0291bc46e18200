//! PMN-PT stack actuator of seed 003 Table 1 (physics-notes §6): free stroke d33 n V, reduced
//! by the bolt in series-spring fashion, K_stack / (K_stack + K_bolt) (the Table 1 rule
//! "Maximum displacement possible"), and the drive current 2 pi f C V of a capacitive load.

use std::f64::consts::PI;

use super::RefError;
use super::error::{non_negative, positive};

/// Inputs of [`actuator`] (seed 003 Table 1: n = 62, d33 = 730 pm/V, C = 300 nF,
/// K_stack = 3.14e8 N/m, K_bolt = 3.7e7 N/m, V_max = 15.466 V, I_max = 1.75 A).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorInput {
    /// Drive voltage amplitude V in volts (>= 0; "6 V peak-to-peak" is V = 3).
    pub voltage: f64,
    /// Drive frequency f in Hz (> 0).
    pub frequency: f64,
    /// Number of discs n (a whole number >= 1).
    pub discs: f64,
    /// Piezoelectric coefficient d33 in m/V (> 0).
    pub d33: f64,
    /// Stack capacitance C in F (> 0).
    pub capacitance: f64,
    /// Stack stiffness in N/m (> 0).
    pub stack_stiffness: f64,
    /// Preload bolt stiffness in N/m (>= 0).
    pub bolt_stiffness: f64,
    /// Voltage limit in volts (> 0).
    pub max_voltage: f64,
    /// Current limit in amperes (> 0).
    pub max_current: f64,
}

/// Outputs of [`actuator`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorOutput {
    /// Displacement amplitude x_a = d33 n V K_stack / (K_stack + K_bolt) in m.
    pub displacement_amplitude: f64,
    /// Vibration velocity amplitude v_a = 2 pi f x_a in m/s.
    pub vibration_velocity: f64,
    /// Current amplitude I = 2 pi f C V in A.
    pub current: f64,
    /// Whether V <= V_max and I <= I_max (exact comparisons).
    pub within_limits: bool,
    /// Largest admissible amplitude min(V_max, I_max / (2 pi f C)) in volts.
    pub voltage_limit: f64,
}

/// Stack actuator kinematics and electrical limits (seed 003 Table 1).
pub fn actuator(input: &ActuatorInput) -> Result<ActuatorOutput, RefError> {
    let voltage = non_negative("V", input.voltage)?;
    let frequency = positive("f", input.frequency)?;
    let discs = positive("n", input.discs)?;
    if discs < 1.0 || discs.fract() != 0.0 {
        return Err(RefError::OutOfDomain {
            key: "n",
            value: discs,
            rule: "must be a whole number of discs >= 1",
        });
    }
    let d33 = positive("d33", input.d33)?;
    let capacitance = positive("C", input.capacitance)?;
    let k_stack = positive("K_stack", input.stack_stiffness)?;
    let k_bolt = non_negative("K_bolt", input.bolt_stiffness)?;
    let v_max = positive("V_max", input.max_voltage)?;
    let i_max = positive("I_max", input.max_current)?;
    let omega = 2.0 * PI * frequency;
    let displacement = d33 * discs * voltage * (k_stack / (k_stack + k_bolt));
    let current = omega * capacitance * voltage;
    Ok(ActuatorOutput {
        displacement_amplitude: displacement,
        vibration_velocity: omega * displacement,
        current,
        within_limits: voltage <= v_max && current <= i_max,
        voltage_limit: v_max.min(i_max / (omega * capacitance)),
    })
}
