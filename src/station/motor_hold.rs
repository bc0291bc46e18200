//! The net-force target in the station (issue 27): where the block is on the horn, which model
//! describes it there, and the hold that drives it in a motor region.
//!
//! Seed 001 Table 1 measured two regimes along the horn's bottom face: friction reduction in the
//! transition region around the node (the cube model, the controller's friction path) and a
//! net drive towards the centreline in the motor regions (`crate::model::motor`). The station
//! knows where the block is by integrating the sliding velocity it is given every period (the
//! carriage's encoder, or the rig's set speed) from the scene's contact position, and chooses
//! by Table 1's measured boundaries (`MeasuredRegions::region`):
//! - transition region: the controller's own step stands (its friction path holds the target's
//!   magnitude as a friction force, `crate::control::PreparedTarget`);
//! - motor region (and beyond the measured one): [`NetForceHold`] drives, with the PI gains
//!   of the friction loop (the same tuning, in units of mu F_n), and the station hands its
//!   command to the controller as a replaced drive (as the resonance search does), so that the
//!   supervisor, the faults and the drive's ceiling stay the controller's.
//!
//! Only a [`Target::NetForce`] target engages the hold; every other target leaves the
//! controller's step untouched (the position is tracked all the same).
//!
//! Sign: the hold's force is the horn's force on the block along +x. The tangential cell reads
//! the force the block drags the horn (and the carriage) with, signed like the sliding
//! velocity for friction: the hold measures minus the cell's reading.

use crate::control::{HoldStep, NetForceHold, NetForceTarget, Output, PiGains, Settings};
use crate::fx::{Q1_31, Q8_24, Q16_16};
use crate::model::ModelError;
use crate::model::horn::HornShape;
use crate::model::motor::{HornRegion, MeasuredRegions, MotorPoint, MotorScene, scene_motor};
use crate::protocol::{SupervisorState, Target};
use crate::scene::Scene;

/// The block's place on the horn and the hold of a net-force target.
#[derive(Debug, Clone)]
pub(super) struct MotorHold {
    model: MotorScene,
    regions: MeasuredRegions,
    /// x from the horn centre, m (f64: 0.5 um steps on centimetres, the plant's reasoning in
    /// `sim/src/plant/motor_contact.rs`).
    position_m: f64,
    period_s: f64,
    gains: PiGains,
    hold: Option<NetForceHold>,
    /// The last command the hold gave (kept while the model cannot be inverted).
    last_amplitude: Q1_31,
}

/// What [`MotorHold::step`] did in one period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum HoldOutcome {
    /// No net-force target, or the loop is not running: the controller's step stands.
    Idle,
    /// Transition region: the controller's friction path drives.
    Transition,
    /// Motor region: the hold's drive command.
    Motor(Q1_31),
}

impl MotorHold {
    /// The hold of `scene` (controller's contact parameters, `settings`' PI gains), the block
    /// at the horn's contact position; `None` for a scene the motor model does not describe
    /// ([`scene_motor`]). Errors: the model's, and unusable gains (as `OutOfDomain`).
    pub(super) fn for_scene(
        scene: &Scene<'_>,
        settings: &Settings,
    ) -> Result<Option<Self>, ModelError> {
        let Some((model, regions)) = scene_motor(scene, &scene.controller)? else {
            return Ok(None);
        };
        let position_m = scene.horn.map_or(0.0, |horn| horn.contact_position_m);
        HornShape::new(position_m, model.horn_length())?;
        Ok(Some(Self {
            model,
            regions,
            position_m,
            period_s: settings.period_s,
            gains: gains(settings)?,
            hold: None,
            last_amplitude: Q1_31::ZERO,
        }))
    }

    /// The friction loop's steady gains, recomputed after a tuning change. Errors as
    /// [`Self::for_scene`]; the old gains are kept then.
    pub(super) fn retune(&mut self, settings: &Settings) -> Result<(), ModelError> {
        self.gains = gains(settings)?;
        Ok(())
    }

    /// The block's position, m from the horn centre.
    pub(super) fn position_m(&self) -> f64 {
        self.position_m
    }

    /// One period: the block moves at `velocity_m_per_s` over the period; with a net-force
    /// `target` and the loop running (`output`), the hold steps on the cells' forces (N,
    /// Q16.16: normal load, tangential reading).
    pub(super) fn step(
        &mut self,
        velocity_m_per_s: f32,
        target: Option<Target>,
        output: &Output,
        normal_force: Q16_16,
        tangential_force: Q16_16,
    ) -> HoldOutcome {
        let next = self.position_m + f64::from(velocity_m_per_s) * self.period_s;
        // Off the face (|x| > L/2) the rig has lost the block: the position stays at the end.
        if HornShape::new(next, self.model.horn_length()).is_ok() {
            self.position_m = next;
        }
        let Some(Target::NetForce { force_mn }) = target else {
            self.hold = None;
            return HoldOutcome::Idle;
        };
        let running = output.state == SupervisorState::Running && output.fault.is_none();
        let Some(target) = NetForceTarget::from_millinewtons(force_mn).filter(|_| running) else {
            self.hold = None;
            return HoldOutcome::Idle;
        };
        let hold = match self.hold.as_mut() {
            Some(hold) if hold.target() == target => hold,
            _ => self.hold.insert(NetForceHold::new(target)),
        };
        // Finite by construction (checked at every move).
        let region = self
            .regions
            .region(self.position_m)
            .unwrap_or(HornRegion::BeyondMeasured);
        let Ok(shape) = HornShape::new(self.position_m, self.model.horn_length()) else {
            return HoldOutcome::Transition;
        };
        let point = MotorPoint {
            shape,
            normal_force,
            block_velocity: Q8_24::from_f32_saturating(velocity_m_per_s).value,
        };
        // The horn's force on the block is minus the cell's reading.
        let measured = Q16_16::from_bits(tangential_force.to_bits().saturating_neg());
        match hold.step(&self.gains, &self.model, region, &point, measured) {
            Ok(HoldStep::Transition) => HoldOutcome::Transition,
            Ok(HoldStep::Motor { amplitude, .. }) => {
                self.last_amplitude = amplitude;
                HoldOutcome::Motor(amplitude)
            }
            // No load, or a force the model cannot invert here: the drive is held where the
            // hold left it (the supervisor still watches the load and the faults).
            Err(_) => HoldOutcome::Motor(self.last_amplitude),
        }
    }
}

fn gains(settings: &Settings) -> Result<PiGains, ModelError> {
    PiGains::new(
        settings.kp,
        settings.ki_per_s,
        settings.period_s,
        settings.integral_limit,
    )
    .map_err(|_| ModelError::OutOfDomain {
        input: "gains",
        reason: "the friction loop's gains are unusable for the net-force hold",
    })
}
