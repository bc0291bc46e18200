//! The simulation beside the Sonolube firmware: the simulated plant ([`plant`]), the closed
//! loop of a scene, its judge and metrics ([`metrics`]). The firmware core (`sonolube`) never
//! depends on it; the QEMU board and the host tools do.
//!
//! [`ClosedLoop`] builds everything from a [`sonolube::scene::Scene`]: the plant
//! ([`crate::plant::Plant::from_scene`], the scene's plant model), the firmware's station
//! ([`sonolube::station::Station`]: the controller's model, the variant
//! [`sonolube::variant::select`] chooses for the scene; the controller with the core's tuning,
//! [`sonolube::control::controller_settings`]), the two load-cell channels of the scene's
//! cells with their fault checks ([`sensor_channel`]) and a bench calibration ([`commission`]:
//! `tare` and `cal` on the simulated cells, or the datasheet calibration alone), and a
//! [`Judge`] that keeps per-segment metrics ([`crate::metrics`]), the criteria's windows and the
//! fault reactions online. Each period runs in three phases ([`ClosedLoop::plant_phase`],
//! [`ClosedLoop::control_phase`], [`ClosedLoop::finish_step`]) so that a firmware can time the
//! control part alone, and returns a [`StepRecord`]; [`ClosedLoop::summary`] gives the
//! [`RunSummary`] with a [`Verdict`] per criterion.
//!
//! # Determinism
//!
//! The plant is `f32` with `libm`, the controller and the sensing are integer, the judge is
//! `f32`/`f64` IEEE arithmetic in a fixed order: a run is bit-identical on the host and on the
//! Cortex-M4F, and from one run to the next. Nothing allocates.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod metrics;
pub mod plant;

mod closed_loop;
mod commission;
mod error_text;
mod judge;
mod quantity;
mod rig_commission;
mod setup;
mod summary;

#[cfg(test)]
mod station_tests;
#[cfg(test)]
mod tests;

pub use closed_loop::{ClosedLoop, Mode, StepRecord};
pub use commission::{COMMISSIONED, COMMISSIONING_SAMPLES, CellCalibration, commission};
pub use judge::{
    DEFAULT_BAND, DEFAULT_STEADY_AFTER_S, Judge, MAX_CRITERIA, MAX_FAULTS, MAX_SEGMENTS,
};
pub use quantity::{Judged, Quantity, target_friction_n, target_value};
pub use rig_commission::{commission_rig, rig_commission_outcome, rig_scene, start_rig_commission};
pub use setup::{
    MAX_STEP_OF_SPAN, STUCK_MIN_NOISE_STEPS, STUCK_SAMPLES, cell_format, fault_limits,
    nominal_calibration, scene_station, sensor_channel,
};
pub use summary::{
    FaultReaction, Measured, Observation, Origin, RampTracking, RunSummary, StepSegment, Verdict,
};

use crate::plant::PlantError;
use sonolube::control::{ConfigError, ControlError};
use sonolube::model::ModelError;
use sonolube::sense::SenseError;
use sonolube::station::StationError;

/// Why a scene cannot be run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SimError {
    /// The plant could not be built.
    Plant(PlantError),
    /// The controller's model could not be built from the scene's controller spec.
    Model(ModelError),
    /// The controller settings made from the scene were refused.
    Config(ConfigError),
    /// The controller refused the first target or the start.
    Control(ControlError),
    /// A load cell's converter format is unusable.
    Sense(SenseError),
    /// A load cell's full scale does not fit the calibration's Q16.16 span (above 16 383 N).
    Calibration,
    /// A target point is outside the `target` command's range, or there is none.
    InvalidTarget,
    /// More criteria or faults than the runner holds ([`MAX_CRITERIA`], [`MAX_FAULTS`]).
    TooLarge,
    /// The scene asks for `freq auto` and the station refused it or the start after it.
    Resonance(sonolube::protocol::ProtocolError),
    /// The scene asks for `commission = true` and the firmware's commissioning refused its
    /// result: the step and the reason ([`sonolube::commission::Refusal`]).
    Commission(sonolube::commission::Step, &'static str),
}

impl From<StationError> for SimError {
    fn from(error: StationError) -> Self {
        match error {
            StationError::Model(error) => SimError::Model(error),
            StationError::Config(error) => SimError::Config(error),
        }
    }
}
