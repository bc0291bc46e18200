//! The supervisor: idle, ramp-up (soft start), running, ramp-down and a latched fault.
//!
//! ```text
//!            start (contact)             ramp-done
//!   idle ─────────────────────> ramp-up ───────────> running
//!    ^  ^   sliding-resumed        │  ^                  │
//!    │  │  (armed, contact back)   │  │ start,           │ stop, not-sliding, no-load
//!    │  │                          v  │ sliding-resumed  v
//!    │  └──────────────────────── ramp-down <────────────┘
//!    │          ramp-done
//!    └── clear ── fault <── any state: sensor fault, overcurrent, overrun, model error
//! ```
//!
//! - `start` arms the run. With sliding contact, loaded, whose natural friction has been
//!   learned, the soft start begins at once; otherwise the supervisor stays idle, armed, and
//!   starts by itself when the contact comes back and the natural friction is learned
//!   (`sliding-resumed`). Losing sliding or load while running ramps down and keeps the run
//!   armed (`not-sliding`, `no-load`): no sliding, no friction reduction to control, so the
//!   drive goes to its safe idle level, zero, and the state and reason say why.
//! - `stop` disarms and ramps down; it is accepted in every state (stopping is always safe).
//! - A fault latches in any state, disarms, and puts the drive at zero in the same control
//!   step (no ramp: the controller bypasses the shaping). Only `clear` leaves the fault state,
//!   to idle. The first fault is the one kept; later ones do not overwrite it.
//! - The soft start is a ceiling on the drive rising at `ramp_up_step` per step from the
//!   amplitude at entry; ramp-up ends (`ramp-done`) when the ceiling no longer cuts the loop's
//!   command or reaches the actuator limit. The ramp-down lowers the command by
//!   `ramp_down_step` per step to zero.

use super::error::ControlError;
use super::reason::Reason;
use crate::fx::Q1_31;
use crate::protocol::SupervisorState;

/// Rates of the soft start and the ramp-down (configuration).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RampConfig {
    /// Rise of the soft-start ceiling per step, Q1.31 fraction of full scale, > 0.
    pub up_step: Q1_31,
    /// Fall of the command per step during ramp-down, Q1.31 fraction of full scale, > 0.
    pub down_step: Q1_31,
}

/// Whether the contact can be controlled this step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Contact {
    /// Sliding, with load.
    Ok,
    /// Not sliding.
    NotSliding,
    /// Sliding but the normal force is below its minimum.
    NoLoad,
    /// Sliding with load, but the natural friction has not been learned long enough for a
    /// run to start (the drive stays off and the learning goes on); a run already going on
    /// is not affected.
    Learning,
}

/// The supervisor's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Supervisor {
    state: SupervisorState,
    reason: Reason,
    armed: bool,
    fault: Option<Reason>,
    ramp_ceiling: Q1_31,
}

impl Supervisor {
    /// Idle, not armed, reason `power-on`.
    pub const fn new() -> Self {
        Self {
            state: SupervisorState::Idle,
            reason: Reason::PowerOn,
            armed: false,
            fault: None,
            ramp_ceiling: Q1_31::ZERO,
        }
    }

    fn enter(&mut self, state: SupervisorState, reason: Reason) {
        self.state = state;
        self.reason = reason;
    }

    fn enter_ramp_up(&mut self, reason: Reason, amplitude_now: Q1_31) {
        self.ramp_ceiling = amplitude_now;
        self.enter(SupervisorState::RampUp, reason);
    }

    /// `start` with or without a target set, given the present contact and drive amplitude.
    pub fn start(
        &mut self,
        has_target: bool,
        contact: Contact,
        amplitude_now: Q1_31,
    ) -> Result<(), ControlError> {
        if let Some(fault) = self.fault {
            return Err(ControlError::FaultLatched { fault });
        }
        if !has_target {
            return Err(ControlError::NoTarget);
        }
        match self.state {
            SupervisorState::Idle | SupervisorState::RampDown => {
                self.armed = true;
                if contact == Contact::Ok {
                    self.enter_ramp_up(Reason::StartCommand, amplitude_now);
                }
                Ok(())
            }
            state => Err(ControlError::WrongState {
                command: "start",
                state,
            }),
        }
    }

    /// `stop`: disarms; ramp-up and running ramp down. Always accepted.
    pub fn stop(&mut self) {
        self.armed = false;
        if matches!(
            self.state,
            SupervisorState::RampUp | SupervisorState::Running
        ) {
            self.enter(SupervisorState::RampDown, Reason::StopCommand);
        }
    }

    /// `clear`: leaves the fault state to idle. Refused (`wrong-state`) when no fault is
    /// latched.
    pub fn clear(&mut self) -> Result<(), ControlError> {
        if self.state != SupervisorState::Fault {
            return Err(ControlError::WrongState {
                command: "clear",
                state: self.state,
            });
        }
        self.fault = None;
        self.enter(SupervisorState::Idle, Reason::ClearCommand);
        Ok(())
    }

    /// Latches `fault` (a reason with [`Reason::is_fault`]): state fault, run disarmed. The
    /// first fault stays latched until cleared.
    pub fn latch(&mut self, fault: Reason) {
        self.armed = false;
        if self.fault.is_none() {
            self.fault = Some(fault);
            self.enter(SupervisorState::Fault, fault);
        }
    }

    /// Follows the contact: ramps down when it is lost, ramps up again when it comes back to
    /// an armed run.
    pub fn follow_contact(&mut self, contact: Contact, amplitude_now: Q1_31) {
        match (self.state, contact) {
            (SupervisorState::RampUp | SupervisorState::Running, Contact::NotSliding) => {
                self.enter(SupervisorState::RampDown, Reason::NotSliding);
            }
            (SupervisorState::RampUp | SupervisorState::Running, Contact::NoLoad) => {
                self.enter(SupervisorState::RampDown, Reason::NoLoad);
            }
            (SupervisorState::Idle | SupervisorState::RampDown, Contact::Ok) if self.armed => {
                self.enter_ramp_up(Reason::SlidingResumed, amplitude_now);
            }
            _ => {}
        }
    }

    /// One step of the soft start: `limited` says whether the ceiling cut the loop's command
    /// this step. Ends the ramp-up when it did not, or when the ceiling reached `max`.
    pub fn advance_ramp_up(&mut self, config: &RampConfig, limited: bool, max: Q1_31) {
        if self.state != SupervisorState::RampUp {
            return;
        }
        if !limited || self.ramp_ceiling >= max {
            self.enter(SupervisorState::Running, Reason::RampDone);
        } else {
            self.ramp_ceiling = self
                .ramp_ceiling
                .saturating_add(config.up_step)
                .value
                .min(max);
        }
    }

    /// The ramp-down reached zero: idle.
    pub fn finish_ramp_down(&mut self) {
        if self.state == SupervisorState::RampDown {
            self.enter(SupervisorState::Idle, Reason::RampDone);
        }
    }

    /// The present state.
    pub const fn state(&self) -> SupervisorState {
        self.state
    }

    /// The reason of the last transition.
    pub const fn reason(&self) -> Reason {
        self.reason
    }

    /// Whether a run is armed (started and not stopped or faulted).
    pub const fn armed(&self) -> bool {
        self.armed
    }

    /// The latched fault, if any.
    pub const fn fault(&self) -> Option<Reason> {
        self.fault
    }

    /// The soft-start ceiling (meaningful in ramp-up), Q1.31 fraction of full scale.
    pub const fn ramp_ceiling(&self) -> Q1_31 {
        self.ramp_ceiling
    }
}

impl Default for Supervisor {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::reason::ExternalFault;

    const RAMP: RampConfig = RampConfig {
        up_step: Q1_31::from_f64_const(0.25),
        down_step: Q1_31::from_f64_const(0.25),
    };

    #[test]
    fn start_run_stop_cycle_with_reasons() {
        let mut s = Supervisor::new();
        assert_eq!(
            (s.state(), s.reason()),
            (SupervisorState::Idle, Reason::PowerOn)
        );
        assert_eq!(
            s.start(false, Contact::Ok, Q1_31::ZERO),
            Err(ControlError::NoTarget)
        );
        s.start(true, Contact::Ok, Q1_31::ZERO).unwrap();
        assert_eq!(
            (s.state(), s.reason()),
            (SupervisorState::RampUp, Reason::StartCommand)
        );
        assert_eq!(
            s.start(true, Contact::Ok, Q1_31::ZERO),
            Err(ControlError::WrongState {
                command: "start",
                state: SupervisorState::RampUp
            })
        );
        s.advance_ramp_up(&RAMP, true, Q1_31::MAX);
        s.advance_ramp_up(&RAMP, true, Q1_31::MAX);
        assert_eq!(s.ramp_ceiling(), Q1_31::from_f64_const(0.5));
        s.advance_ramp_up(&RAMP, false, Q1_31::MAX);
        assert_eq!(
            (s.state(), s.reason()),
            (SupervisorState::Running, Reason::RampDone)
        );
        s.stop();
        assert_eq!(
            (s.state(), s.reason()),
            (SupervisorState::RampDown, Reason::StopCommand)
        );
        assert!(!s.armed());
        s.follow_contact(Contact::Ok, Q1_31::ZERO); // disarmed: no restart
        s.finish_ramp_down();
        assert_eq!(
            (s.state(), s.reason()),
            (SupervisorState::Idle, Reason::RampDone)
        );
    }

    #[test]
    fn contact_loss_keeps_the_run_armed() {
        let mut s = Supervisor::new();
        s.start(true, Contact::NotSliding, Q1_31::ZERO).unwrap();
        assert_eq!((s.state(), s.armed()), (SupervisorState::Idle, true));
        s.follow_contact(Contact::Ok, Q1_31::ZERO);
        assert_eq!(
            (s.state(), s.reason()),
            (SupervisorState::RampUp, Reason::SlidingResumed)
        );
        s.follow_contact(Contact::NoLoad, Q1_31::ZERO);
        assert_eq!(
            (s.state(), s.reason()),
            (SupervisorState::RampDown, Reason::NoLoad)
        );
        s.follow_contact(Contact::NotSliding, Q1_31::ZERO);
        assert_eq!(s.reason(), Reason::NoLoad, "no transition, no new reason");
        s.follow_contact(Contact::Ok, Q1_31::from_f64_const(0.3));
        assert_eq!(s.state(), SupervisorState::RampUp);
        assert_eq!(
            s.ramp_ceiling(),
            Q1_31::from_f64_const(0.3),
            "bumpless soft start"
        );
    }

    /// A `stop` while the run waits, armed, for the contact (in idle, or in the ramp-down
    /// after a contact loss) disarms it: when the contact comes back the drive stays off
    /// instead of restarting by itself.
    #[test]
    fn a_stop_while_armed_in_idle_or_ramp_down_disarms() {
        let mut idle = Supervisor::new();
        idle.start(true, Contact::NotSliding, Q1_31::ZERO).unwrap();
        assert_eq!((idle.state(), idle.armed()), (SupervisorState::Idle, true));
        idle.stop();
        assert!(!idle.armed());
        idle.follow_contact(Contact::Ok, Q1_31::ZERO);
        assert_eq!(idle.state(), SupervisorState::Idle, "no restart from idle");

        let mut ramp_down = Supervisor::new();
        ramp_down.start(true, Contact::Ok, Q1_31::ZERO).unwrap();
        ramp_down.follow_contact(Contact::NotSliding, Q1_31::ZERO);
        assert_eq!(
            (ramp_down.state(), ramp_down.armed()),
            (SupervisorState::RampDown, true)
        );
        ramp_down.stop();
        assert!(!ramp_down.armed());
        ramp_down.follow_contact(Contact::Ok, Q1_31::from_f64_const(0.2));
        assert_eq!(
            ramp_down.state(),
            SupervisorState::RampDown,
            "no restart from the ramp-down"
        );
        ramp_down.finish_ramp_down();
        ramp_down.follow_contact(Contact::Ok, Q1_31::ZERO);
        assert_eq!(ramp_down.state(), SupervisorState::Idle);
    }

    #[test]
    fn faults_latch_until_cleared() {
        let mut s = Supervisor::new();
        assert!(matches!(
            s.clear(),
            Err(ControlError::WrongState {
                command: "clear",
                ..
            })
        ));
        s.start(true, Contact::Ok, Q1_31::ZERO).unwrap();
        s.latch(ExternalFault::Overcurrent.into());
        s.latch(ExternalFault::Overrun.into());
        assert_eq!(
            (s.state(), s.reason()),
            (SupervisorState::Fault, Reason::Overcurrent)
        );
        assert_eq!(s.fault(), Some(Reason::Overcurrent));
        assert!(!s.armed());
        assert_eq!(
            s.start(true, Contact::Ok, Q1_31::ZERO),
            Err(ControlError::FaultLatched {
                fault: Reason::Overcurrent
            })
        );
        s.follow_contact(Contact::Ok, Q1_31::ZERO);
        s.stop();
        s.finish_ramp_down();
        assert_eq!(s.state(), SupervisorState::Fault);
        s.clear().unwrap();
        assert_eq!(
            (s.state(), s.reason(), s.fault()),
            (SupervisorState::Idle, Reason::ClearCommand, None)
        );
    }
}
