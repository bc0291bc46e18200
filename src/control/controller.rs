//! The friction controller: estimate, supervisor, feedforward, PI correction and drive
//! shaping in one step (the design and its tuning are in the `control` module docs).

use super::SampleBlock;
use super::config::Config;
use super::error::ControlError;
use super::estimate::{FrictionEstimate, FrictionEstimator, MIN_NATURAL_COEF, NaturalFriction};
use super::filter::LowPass;
use super::io::{Inputs, Output, Saturation};
use super::pi::{Clamp, Pi, PiGains};
use super::reason::{ExternalFault, Reason, Sensor, SensorFault, SensorFaultKind};
use super::recip::Reciprocal;
use super::schedule::{Boost, GainSchedule};
use super::shaper::{DriveRequest, DriveShaper};
use super::sliding::SlidingDetector;
use super::stage::StepStage;
use super::supervisor::{Contact, Supervisor};
use super::target::PreparedTarget;
use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
use crate::model::{FrictionModel, ModelError, OperatingPoint, Reach};
use crate::protocol::{SupervisorState, Target};
use crate::stage::{Stage, StageMarks};

/// The load at which a model whose load enters only through `mu W` (the Dahl steady state,
/// [`FrictionModel::load_enters_as_coulomb_force`]) sees the measured Coulomb force: `W mu0 /
/// mu`, with `mu0` the learned natural friction and `mu` the model's (the scene's prior).
///
/// Why: the Dahl steady state depends on `kappa x_a = k_t x_a / (mu W)`, the amplitude over the
/// contact's elastic slip length `mu W / k_t`. That length is set by the real Coulomb force,
/// which the controller measures (mu0, learned sliding with the drive off), not by the
/// nominal `mu`. With the nominal value a plant whose mu is 20 % higher looks 20 % stiffer
/// than it is, the inverse asks for too little amplitude and the PI has to find the whole
/// difference. (k_t is not observable without vibration and stays nominal.)
///
/// `mu0 / mu` as a factor in Q33.30 (an `i64`; `mu0` and `mu` Q2.30, floored at
/// [`MIN_NATURAL_COEF`] as the learner floors them, so the factor is in (2^19, 2^42)). Rounded
/// to nearest. The controller keeps it while `mu0` and `mu` stay put: the division runs when
/// they change (learning happens with the drive off), not in every step.
pub(super) fn coulomb_factor(mu0: Q2_30, mu: Q2_30) -> i64 {
    let num = (mu0.max(MIN_NATURAL_COEF).to_bits() as i64) << 30;
    let den = mu.max(MIN_NATURAL_COEF).to_bits() as i64;
    // num < 2^61, den in [2^20, 2^31): no overflow.
    (num + den / 2) / den
}

/// `W mu0 / mu` for `load` Q16.16 N > 0 and `factor` = [`coulomb_factor`]`(mu0, mu)`, rounded
/// to nearest (within 1.5 Q16.16 steps of the exact value: half a step of rounding, plus the
/// factor's rounding, 2^-31, times W < 2^15 N). Error `OutOfDomain` if it does not
/// fit Q16.16 (>= 32768 N): never saturated.
pub(super) fn coulomb_load(load: Q16_16, factor: i64) -> Result<Q16_16, ModelError> {
    let too_large = ModelError::OutOfDomain {
        input: "W mu0 / mu",
        reason: "the load at the learned natural friction exceeds Q16.16",
    };
    let product = (load.to_bits() as i64)
        .checked_mul(factor)
        .and_then(|p| p.checked_add(1 << 29))
        .ok_or(too_large)?;
    i32::try_from(product >> 30)
        .map(Q16_16::from_bits)
        .map_err(|_| too_large)
}

/// Largest reduction of the friction, as the model predicts it at the envelope of a drive
/// the controller did not command (the resonance search), at which mu0 is still learned:
/// 2^-10 of natural (0.1 %), a tenth of the reference scene's RMS error limit. A learned
/// mu0 that much low is a steady error of the same size that no feedback sees.
const NATURAL_MAX_REDUCTION: Q2_30 = Q2_30::from_bits(1 << 20);

/// Whether the friction at `envelope` is natural by the model (within
/// [`NATURAL_MAX_REDUCTION`]) at the present estimate. A model error counts as not natural.
fn natural_at<M: FrictionModel + ?Sized>(
    model: &M,
    c: &Config,
    s: &mut ControllerState,
    envelope: Q1_31,
) -> bool {
    operating_point(model, c, s)
        .and_then(|point| model.ratio(&point, envelope))
        .is_ok_and(|ratio| ratio >= Q2_30::ONE.saturating_sub(NATURAL_MAX_REDUCTION).value)
}

/// The model's operating point at the present estimate: the filtered load (at least the
/// no-load guard; as the Coulomb force's load for a model whose load enters as `mu W`) and
/// the filtered speed's magnitude.
#[inline(always)]
fn operating_point<M: FrictionModel + ?Sized>(
    model: &M,
    c: &Config,
    s: &mut ControllerState,
) -> Result<OperatingPoint, ModelError> {
    let load = s.estimate.normal_force.max(c.estimator.min_normal_force);
    let normal_force = if model.load_enters_as_coulomb_force() {
        let (mu0, mu) = (s.natural.coefficient(), c.natural.prior);
        if (s.coulomb.0, s.coulomb.1) != (mu0, mu) {
            s.coulomb = (mu0, mu, coulomb_factor(mu0, mu));
        }
        coulomb_load(load, s.coulomb.2)?
    } else {
        load
    };
    Ok(OperatingPoint {
        normal_force,
        sliding_velocity: s.estimate.sliding_velocity.saturating_abs().value,
    })
}

/// A drive in the envelope estimate that the controller did not command (the search's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ExternalDrive {
    /// None (or it has died out).
    None,
    /// One, under which the model has said the friction stays natural so far: mu0 is learned.
    Natural,
    /// One under which the model said the friction is reduced: mu0 waits until it dies out
    /// (the filtered readings lag the envelope).
    Reduced,
}

/// The controller's state (separate from its [`Config`]; never re-allocated).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ControllerState {
    supervisor: Supervisor,
    estimator: FrictionEstimator,
    estimate: FrictionEstimate,
    sliding: SlidingDetector,
    contact: Contact,
    natural: NaturalFriction,
    shaper: DriveShaper,
    pi: Pi,
    boost: Boost,
    gains: PiGains,
    prediction: LowPass<30>,
    /// The prediction through the tangential cell's lag, before `prediction`'s filter.
    sensed_prediction: LowPass<30>,
    /// The prediction through the contact's relaxation lag, before the cell's lag.
    contact_prediction: LowPass<30>,
    prediction_valid: bool,
    /// The last model inversion's amplitude (Q1.31 fraction of full scale, [0, 1)): where
    /// the next inversion starts ([`FrictionModel::invert_from`]); zero from each ramp-up.
    feedforward: Q1_31,
    target: Option<(Target, PreparedTarget)>,
    /// The `mu0` and `mu` of the last [`coulomb_factor`], and the factor (Q33.30).
    coulomb: (Q2_30, Q2_30, i64),
    /// Whether the envelope estimate holds a drive this controller did not command
    /// ([`Controller::drive_replaced`]); back to `None` once it has decayed to
    /// `natural_max_drive`.
    external_drive: ExternalDrive,
    /// The staging of the present target step's feedforward (`control/stage.rs`).
    stage: StepStage,
}

/// The friction controller: configuration plus state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controller {
    config: Config,
    state: ControllerState,
}

/// The loop's values of one step, for the output.
#[derive(Default)]
struct LoopReport {
    target_ratio: Option<Q2_30>,
    error: Q2_30,
    feedforward: Q1_31,
    reach: Option<Reach>,
    saturation: Saturation,
}

impl Controller {
    /// A controller in idle, no target, natural friction at the configured prior.
    pub fn new(config: Config) -> Self {
        Self {
            state: ControllerState {
                supervisor: Supervisor::new(),
                estimator: FrictionEstimator::new(),
                estimate: FrictionEstimate {
                    normal_force: Q16_16::ZERO,
                    tangential_force: Q16_16::ZERO,
                    sliding_velocity: Q8_24::ZERO,
                    coefficient: Q2_30::ZERO,
                    load_ok: false,
                    normal_reciprocal: Reciprocal::ONE,
                },
                sliding: SlidingDetector::new(),
                contact: Contact::NotSliding,
                natural: NaturalFriction::new(&config.natural),
                shaper: DriveShaper::new(),
                pi: Pi::new(),
                boost: Boost::new(),
                gains: config.gains.slow(),
                prediction: LowPass::new(Q2_30::ONE),
                sensed_prediction: LowPass::new(Q2_30::ONE),
                contact_prediction: LowPass::new(Q2_30::ONE),
                prediction_valid: false,
                feedforward: Q1_31::ZERO,
                target: None,
                coulomb: (Q2_30::ZERO, Q2_30::ZERO, 1 << 30),
                external_drive: ExternalDrive::None,
                stage: StepStage::new(),
            },
            config,
        }
    }

    /// Runs one control step on `inputs` with `model`. Never panics, whatever the inputs.
    /// A sensor fault (reported or implausible) or a model error puts the drive at zero in
    /// this very step.
    pub fn step<M: FrictionModel + ?Sized>(&mut self, inputs: &Inputs, model: &M) -> Output {
        self.step_marked(inputs, model, &mut ())
    }

    /// [`Self::step`] with its stages marked in `marks` (the benchmark's breakdown of a
    /// step's cost, [`crate::stage`]); the same computation whatever the marks.
    pub fn step_marked<M: FrictionModel + ?Sized>(
        &mut self,
        inputs: &Inputs,
        model: &M,
        marks: &mut impl StageMarks,
    ) -> Output {
        marks.enter(Stage::Supervision);
        let before = self.state.supervisor.state();
        match inputs.sensor_fault.or_else(|| self.implausible(inputs)) {
            Some(fault) => self.state.supervisor.latch(fault.into()),
            None => self.estimate(inputs, model, marks),
        }
        self.on_transition(before);
        let mut report = LoopReport::default();
        match self.state.supervisor.state() {
            SupervisorState::RampUp | SupervisorState::Running => {
                if self.close_loop(model, &mut report, marks).is_err() {
                    marks.enter(Stage::Supervision);
                    self.state.supervisor.latch(Reason::ModelError);
                    self.state.shaper.apply(&self.config.shaper, Q1_31::ZERO);
                    report = LoopReport::default();
                }
            }
            SupervisorState::RampDown => {
                marks.enter(Stage::Shaper);
                let s = &mut self.state;
                let lowered = s
                    .shaper
                    .command()
                    .saturating_sub(self.config.ramp.down_step)
                    .value;
                // max/min rather than clamp: clamp has a panic path (min > max) in the binary.
                let lowered = lowered
                    .min(self.config.limit.max_amplitude)
                    .max(Q1_31::ZERO);
                s.shaper.apply(&self.config.shaper, lowered);
                // A ramp-down lasts at least one step, so that its reason is seen.
                if lowered == Q1_31::ZERO && before == SupervisorState::RampDown {
                    s.supervisor.finish_ramp_down();
                }
            }
            _ => {
                marks.enter(Stage::Shaper);
                self.state.shaper.apply(&self.config.shaper, Q1_31::ZERO)
            }
        }
        marks.enter(Stage::Supervision);
        self.output(report)
    }

    fn implausible(&self, inputs: &Inputs) -> Option<SensorFault> {
        let r = &self.config.ranges;
        let out = |sensor| {
            Some(SensorFault {
                sensor,
                kind: SensorFaultKind::OutOfRange,
            })
        };
        if inputs.normal_force.saturating_abs().value > r.normal {
            out(Sensor::NormalForce)
        } else if inputs.tangential_force.saturating_abs().value > r.tangential {
            out(Sensor::TangentialForce)
        } else if inputs.sliding_velocity.saturating_abs().value > r.velocity {
            out(Sensor::SlidingVelocity)
        } else {
            None
        }
    }

    fn estimate<M: FrictionModel + ?Sized>(
        &mut self,
        inputs: &Inputs,
        model: &M,
        marks: &mut impl StageMarks,
    ) {
        let (c, s) = (&self.config, &mut self.state);
        marks.enter(Stage::Estimator);
        s.estimate = s.estimator.update(
            &c.estimator,
            inputs.normal_force,
            inputs.tangential_force,
            inputs.sliding_velocity,
        );
        marks.enter(Stage::Supervision);
        s.contact = match (
            c.sliding.process(&mut s.sliding, inputs.sliding_velocity),
            s.estimate.load_ok,
        ) {
            (false, _) => Contact::NotSliding,
            (true, false) => Contact::NoLoad,
            (true, true) => Contact::Ok,
        };
        // mu0 is the friction without vibration: learn it only while sliding, drive off.
        let envelope = s.shaper.envelope();
        let mut drive_off = envelope <= c.natural_max_drive;
        if drive_off {
            s.external_drive = ExternalDrive::None;
        } else if s.external_drive == ExternalDrive::Natural && s.contact == Contact::Ok {
            // The resonance search's own low drive: it leaves the friction natural where the
            // model says so (the Littmann law's dead zone v_a <= v), and mu0 is learned on.
            // Once it did not, the filtered readings lag the envelope's decay: learning
            // waits for the envelope to die out, as after the controller's own drive.
            drive_off = natural_at(model, c, s, envelope);
            if !drive_off {
                s.external_drive = ExternalDrive::Reduced;
            }
        }
        if s.contact == Contact::Ok && drive_off && s.supervisor.state() != SupervisorState::Fault {
            s.natural.learn(&c.natural, s.estimate.coefficient);
        }
        if s.contact == Contact::Ok && s.natural.weight() < c.natural_ready {
            // A reduction is relative to mu0: no run starts on a mu0 worth a few samples.
            s.contact = Contact::Learning;
        }
        s.supervisor.follow_contact(s.contact, s.shaper.command());
    }

    /// Closing the loop starts from rest: no correction, prediction re-seeded, fast gains.
    fn on_transition(&mut self, before: SupervisorState) {
        let now = self.state.supervisor.state();
        if now == SupervisorState::RampUp && before != SupervisorState::RampUp {
            self.state.pi.reset();
            self.state.prediction_valid = false;
            self.state.feedforward = Q1_31::ZERO;
            self.state.boost.restart();
            self.state.stage.restart();
        }
    }

    fn close_loop<M: FrictionModel + ?Sized>(
        &mut self,
        model: &M,
        report: &mut LoopReport,
        marks: &mut impl StageMarks,
    ) -> Result<(), ModelError> {
        let (c, s) = (&self.config, &mut self.state);
        marks.enter(Stage::Feedback);
        let Some((_, target)) = s.target else {
            // start() refuses without a target and targets cannot be removed.
            s.supervisor.stop();
            return Ok(());
        };
        let estimate = s.estimate;
        let natural = s.natural.reciprocal();
        let target_ratio = target.ratio(natural, estimate.normal_reciprocal);
        let measured = natural.times::<30, 30>(estimate.coefficient).value;
        let ramping = s.supervisor.state() == SupervisorState::RampUp;
        let max = c.limit.max_amplitude;
        let ceiling = if ramping {
            s.supervisor.ramp_ceiling().min(max)
        } else {
            max
        };
        report.target_ratio = Some(target_ratio.value);
        report.saturation.target = target_ratio.saturated;
        let desired = if target_ratio.value >= Q2_30::ONE {
            // At or above natural friction the nearest reachable point is no vibration; the
            // PI holds (nothing to correct) and the prediction is re-seeded on the way back.
            s.prediction_valid = false;
            report.error = target_ratio.value.saturating_sub(measured).value;
            report.reach = Some(Reach::AboveNatural);
            report.saturation.integral_frozen = true;
            Q1_31::ZERO
        } else {
            marks.enter(Stage::Model);
            let point = operating_point(model, c, s)?;
            // The reference: what the model says the cells should read now, given the drive
            // actually applied (envelope estimate) and the same filter as the measurement.
            // Without vibration F'/F is 1 by definition: no model call while the drive is off.
            let envelope = s.shaper.envelope();
            let predicted_now = if envelope == Q1_31::ZERO {
                Q2_30::ONE
            } else {
                model.ratio(&point, envelope)?
            };
            marks.enter(Stage::Feedback);
            if !s.prediction_valid {
                let seed = measured.saturating_add(s.pi.correction()).value;
                s.prediction.reset(seed);
                s.sensed_prediction.reset(seed);
                s.contact_prediction.reset(seed);
                s.prediction_valid = true;
            }
            let predicted_now = match &c.contact_lag {
                Some(lag) => lag.process(&mut s.contact_prediction, predicted_now),
                None => predicted_now,
            };
            let sensed = match &c.sensor_lag {
                Some(lag) => lag.process(&mut s.sensed_prediction, predicted_now),
                None => predicted_now,
            };
            // The filtered prediction before this step: where a staged step begins.
            let before = s.prediction.output();
            let predicted = c.estimator.tangential.process(&mut s.prediction, sensed);
            let reference = predicted.saturating_sub(s.pi.correction()).value;
            let error = reference.saturating_sub(measured).value;
            // This step's gains on the schedule; the change from the last step is bumpless.
            let gains = c.gains.process(&mut s.boost, ());
            s.pi.retune(&s.gains, &gains);
            s.gains = gains;
            let candidate = s.pi.candidate(&gains, error);
            // The feedforward's target: the step staged by the declared mismatch.
            let feedforward = match &c.stage {
                Some(stage) => stage.staged(&mut s.stage, target_ratio.value, before, predicted),
                None => target_ratio.value,
            };
            let command = feedforward.saturating_add(candidate.correction()).value;
            marks.enter(Stage::Inverse);
            let inversion = model.invert_from(&point, command.max(Q2_30::ZERO), s.feedforward)?;
            marks.enter(Stage::Feedback);
            s.feedforward = inversion.amplitude;
            let actuator = inversion.amplitude > max;
            let desired = inversion.amplitude.min(max);
            let clamp = match inversion.reach {
                Reach::AboveNatural => Clamp::Upper,
                Reach::BelowMinimum => Clamp::Lower,
                Reach::Reached if actuator || desired >= ceiling => Clamp::Lower,
                Reach::Reached => Clamp::Free,
            };
            s.pi.commit(&gains, candidate, clamp);
            report.error = error;
            report.feedforward = inversion.amplitude;
            report.reach = Some(if actuator {
                Reach::BelowMinimum
            } else {
                inversion.reach
            });
            report.saturation.model = inversion.reach != Reach::Reached;
            report.saturation.actuator = actuator;
            report.saturation.integral_frozen = s.pi.frozen();
            desired
        };
        marks.enter(Stage::Shaper);
        let shaped = c
            .shaper
            .process(&mut s.shaper, DriveRequest { desired, ceiling });
        marks.enter(Stage::Supervision);
        report.saturation.slew = shaped.slew_limited;
        report.saturation.soft_start = ramping && shaped.ceiling_limited;
        s.supervisor
            .advance_ramp_up(&c.ramp, shaped.ceiling_limited, max);
        Ok(())
    }

    fn output(&self, report: LoopReport) -> Output {
        let s = &self.state;
        let natural = s.natural.reciprocal();
        let target_ratio = report.target_ratio.or_else(|| {
            s.target
                .map(|(_, t)| t.ratio(natural, s.estimate.normal_reciprocal).value)
        });
        Output {
            amplitude: crate::drive::Amplitude::from_command(s.shaper.command()),
            state: s.supervisor.state(),
            reason: s.supervisor.reason(),
            fault: s.supervisor.fault(),
            armed: s.supervisor.armed(),
            sliding: s.sliding.is_sliding(),
            estimate: s.estimate,
            natural_coefficient: s.natural.coefficient(),
            measured_ratio: natural.times::<30, 30>(s.estimate.coefficient).value,
            target_ratio,
            error: report.error,
            correction: s.pi.correction(),
            integral: s.pi.integral(),
            feedforward: report.feedforward,
            reach: report.reach,
            saturation: report.saturation,
        }
    }

    /// `start`: arms the run; the soft start begins now if the contact slides under load,
    /// otherwise as soon as it does. Errors: fault latched (22), no target (23), already
    /// ramping up or running (21).
    pub fn start(&mut self) -> Result<(), ControlError> {
        let before = self.state.supervisor.state();
        let s = &mut self.state;
        s.supervisor
            .start(s.target.is_some(), s.contact, s.shaper.command())?;
        self.on_transition(before);
        Ok(())
    }

    /// The drive applied over the last step was `amplitude`, not this controller's command:
    /// another owner drove the transducer (the resonance search of `freq auto`). The envelope
    /// estimate follows what was applied, so that the prediction, the lead and the test for
    /// learning mu0 with the drive off see the vibration the search left behind.
    pub fn drive_replaced(&mut self, amplitude: Q1_31) {
        self.state.shaper.replace(&self.config.shaper, amplitude);
        if self.state.external_drive == ExternalDrive::None {
            self.state.external_drive = ExternalDrive::Natural;
        }
    }

    /// `stop`: disarms and ramps the drive down. Always accepted.
    pub fn stop(&mut self) -> Result<(), ControlError> {
        self.state.supervisor.stop();
        Ok(())
    }

    /// `target`: holds `target` from the next step on. Bumpless: the PI's reference does not
    /// depend on the target, only the feedforward moves, at the slew limit; the PI's gains
    /// restart from the fast set (a new operating point's model error is to be found).
    /// Accepted in every state; error `InvalidTarget` (6) outside the command's range.
    pub fn set_target(&mut self, target: Target) -> Result<(), ControlError> {
        let prepared =
            PreparedTarget::new(&target).ok_or(ControlError::InvalidTarget { target })?;
        if self.state.target.map(|(t, _)| t) != Some(target) {
            self.state.boost.restart();
            self.state.stage.restart();
        }
        self.state.target = Some((target, prepared));
        Ok(())
    }

    /// `clear`: leaves a latched fault to idle. Error `WrongState` (21) without a fault. A
    /// fault whose cause persists latches again at the next step.
    pub fn clear_fault(&mut self) -> Result<(), ControlError> {
        self.state.supervisor.clear()
    }

    /// New PI gains, bumpless (the correction does not jump). Accepted in every state.
    pub fn set_gains(&mut self, gains: GainSchedule) -> Result<(), ControlError> {
        self.config.gains = gains;
        self.retune();
        Ok(())
    }

    /// Moves the PI to the schedule's present gains without a jump.
    fn retune(&mut self) {
        let s = &mut self.state;
        let gains = self.config.gains.gains(s.boost.weight());
        s.pi.retune(&s.gains, &gains);
        s.gains = gains;
    }

    /// Latches an external fault (overcurrent, overrun); the next step outputs zero.
    pub fn trip(&mut self, fault: ExternalFault) {
        self.state.supervisor.latch(fault.into());
    }

    /// Swaps the configuration between two steps, bumplessly: filter states, envelope
    /// estimate and supervisor state are kept, the PI is retuned without a jump, and the
    /// learned natural friction is kept unless the scene's prior changed (a new scene is
    /// learned afresh). A lower actuator ceiling applies at the next step.
    pub fn reconfigure(&mut self, config: Config) {
        if config.natural.prior != self.config.natural.prior {
            self.state.natural = NaturalFriction::new(&config.natural);
        }
        self.config = config;
        self.retune();
    }

    /// The configuration in use.
    pub const fn config(&self) -> &Config {
        &self.config
    }

    /// The supervisor state.
    pub const fn state(&self) -> SupervisorState {
        self.state.supervisor.state()
    }

    /// The reason of the last transition.
    pub const fn reason(&self) -> Reason {
        self.state.supervisor.reason()
    }

    /// The latched fault, if any.
    pub const fn fault(&self) -> Option<Reason> {
        self.state.supervisor.fault()
    }

    /// The target as set (protocol form), if any.
    pub fn target(&self) -> Option<Target> {
        self.state.target.map(|(t, _)| t)
    }

    /// The natural friction coefficient `mu0`, Q2.30.
    pub const fn natural_coefficient(&self) -> Q2_30 {
        self.state.natural.coefficient()
    }

    /// A friction `ratio` expressed as a target of the same kind as the present one (for
    /// telemetry: what the loop holds, in the user's terms).
    pub fn report_ratio(&self, ratio: Q2_30) -> Option<Target> {
        let s = &self.state;
        s.target
            .map(|(_, t)| t.report(ratio, s.natural.coefficient(), s.estimate.normal_force))
    }
}
