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
use crate::fx::{Q1_31, Q8_24, Q16_16, Turns};
use crate::model::ModelError;
use crate::model::horn::HornShape;
use crate::model::motor::{MotorPoint, MotorScene, classify, scene_motor};
use crate::protocol::{SupervisorState, Target};
use crate::scene::Scene;

/// The block's place on the horn and the hold of a net-force target.
#[derive(Debug, Clone)]
pub(super) struct MotorHold {
    model: MotorScene,
    /// The block's place as the horn's position phase x / (2 L) in turns (`fx::Turns` bits,
    /// U0.32 read as signed: |x| <= L/2 is |phase| <= 2^30), the phase `HornShape::from_phase`
    /// takes: 2L / 2^32 per count (59 pm on the 127 mm horn), so the 0.8 um a period of a
    /// 5 mm/s block moves is about 14,000 counts, integrated without drift or float.
    phase: i32,
    /// Counts per m/s of sliding velocity over one period, T 2^32 / (2 L) (scene load).
    counts_per_m_per_s: f32,
    /// Table 1's boundaries (`MeasuredRegions`) as phases (scene load): transition [low, high],
    /// motor outer ends.
    transition: (i32, i32),
    motor_outer: (i32, i32),
    /// The horn's length L, m (the position read back in metres).
    horn_length_m: f64,
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
        let horn_length_m = model.horn_length();
        HornShape::new(position_m, horn_length_m)?;
        let per_m = COUNTS_PER_TURN / (2.0 * horn_length_m);
        // A boundary beyond the face (|x| > L/2) is where the block never is: the face's end.
        // max/min, not `clamp`: clamp's assertion would link f64 formatting into the board.
        let phase_of = |x: f64| {
            libm::round(x.max(-0.5 * horn_length_m).min(0.5 * horn_length_m) * per_m) as i32
        };
        Ok(Some(Self {
            transition: (
                phase_of(regions.transition.0),
                phase_of(regions.transition.1),
            ),
            motor_outer: (
                phase_of(regions.motor_outer.0),
                phase_of(regions.motor_outer.1),
            ),
            model,
            phase: phase_of(position_m),
            counts_per_m_per_s: (settings.period_s * per_m) as f32,
            horn_length_m,
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
        f64::from(self.phase) * 2.0 * self.horn_length_m / COUNTS_PER_TURN
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
        // The period's move in counts (f32: the velocity's own type; a non-finite or huge one
        // saturates and is then refused by the face's bound below).
        let step = (velocity_m_per_s * self.counts_per_m_per_s) as i64;
        let next = i64::from(self.phase) + step;
        // Off the face (|x| > L/2, |phase| > 2^30) the rig has lost the block: the position
        // stays where it was.
        if next.abs() <= HALF_FACE_COUNTS {
            self.phase = next as i32;
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
        let region = classify(self.phase, self.transition, self.motor_outer);
        let shape = HornShape::from_phase(Turns::from_bits(self.phase as u32));
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

/// 2^32 counts per turn of the horn's position phase.
const COUNTS_PER_TURN: f64 = 4_294_967_296.0;
/// |x| = L/2, a quarter turn: the face's ends.
const HALF_FACE_COUNTS: i64 = 1 << 30;

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
