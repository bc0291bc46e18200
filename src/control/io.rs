//! What a control step takes and what it gives back.

use super::estimate::FrictionEstimate;
use super::reason::{Reason, SensorFault};
use crate::drive::Amplitude;
use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
use crate::model::Reach;
use crate::protocol::SupervisorState;

/// The sensor readings of one control step. Any bit patterns are accepted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Inputs {
    /// Normal force, Q16.16 N (calibrated load cell).
    pub normal_force: Q16_16,
    /// Tangential (friction) force, Q16.16 N, either sign.
    pub tangential_force: Q16_16,
    /// Sliding velocity, Q8.24 m/s, either sign.
    pub sliding_velocity: Q8_24,
    /// A fault the sensing chain found in this sample (`crate::sense`), if any.
    pub sensor_fault: Option<SensorFault>,
}

/// Which limits acted in a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Saturation {
    /// The target ratio did not fit Q2.30 (far above natural friction) and was clamped.
    pub target: bool,
    /// The model could not reach the ratio command (its `Reach` was not `Reached`).
    pub model: bool,
    /// The actuator's voltage/current ceiling cut the model's amplitude.
    pub actuator: bool,
    /// The soft-start ceiling cut the command.
    pub soft_start: bool,
    /// The slew limit cut the command.
    pub slew: bool,
    /// The PI's integral was frozen (clamping anti-windup).
    pub integral_frozen: bool,
}

/// The result of one control step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Output {
    /// Drive amplitude command, fraction of full scale in [0, max amplitude]: the drive's own
    /// encoding ([`Amplitude`], unsigned Q1.31), applied as it is.
    pub amplitude: Amplitude,
    /// Supervisor state after this step.
    pub state: SupervisorState,
    /// Reason of the last transition.
    pub reason: Reason,
    /// The latched fault, if any.
    pub fault: Option<Reason>,
    /// Whether a run is armed (it restarts by itself when sliding comes back).
    pub armed: bool,
    /// Whether the contact slides (debounced).
    pub sliding: bool,
    /// The friction estimate (filtered forces, speed, coefficient `mu`).
    pub estimate: FrictionEstimate,
    /// The natural friction coefficient `mu0`, Q2.30.
    pub natural_coefficient: Q2_30,
    /// Measured friction ratio `mu / mu0`, Q2.30.
    pub measured_ratio: Q2_30,
    /// Target friction ratio, Q2.30 in [0, 2); `None` without a target.
    pub target_ratio: Option<Q2_30>,
    /// PI error (reference minus measured ratio), Q2.30; zero while the loop is open.
    pub error: Q2_30,
    /// PI correction added to the target before the inversion, Q2.30 ratio units.
    pub correction: Q2_30,
    /// The PI's integral (part of the correction), Q2.30 ratio units.
    pub integral: Q2_30,
    /// The model inversion's amplitude for the corrected ratio (the feedforward, before the
    /// actuator ceiling, the lead and the slew limit), Q1.31; zero while the loop is open.
    pub feedforward: Q1_31,
    /// Whether the target is reachable (`None` while the loop is open).
    pub reach: Option<Reach>,
    /// The limits that acted.
    pub saturation: Saturation,
}
