//! The supervisor states as the protocol names them.
//!
//! The supervisor owns the state machine; this list is its public face in `status` replies,
//! `wrong-state` errors and telemetry. Adding a state changes what a host can receive, so it
//! goes with a bump of [`PROTOCOL_VERSION`](super::PROTOCOL_VERSION).

/// State of the supervisor, printed by its [`name`](SupervisorState::name).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SupervisorState {
    /// `boot`: self-check running, drive off.
    Boot,
    /// `idle`: ready, drive off.
    Idle,
    /// `tuning`: resonance search (`freq auto`) running, loop open.
    Tuning,
    /// `calibrating`: `tare` or `cal` in progress, drive off.
    Calibrating,
    /// `ramp-up`: soft start, drive amplitude rising at a limited rate toward the loop's output.
    RampUp,
    /// `running`: drive on, friction loop closed.
    Running,
    /// `ramp-down`: drive amplitude falling at a limited rate to zero (stop, or no sliding).
    RampDown,
    /// `fault`: a fault is latched, drive in its safe state until `clear`.
    Fault,
}

impl SupervisorState {
    /// Every state, in the order of the table above.
    pub const ALL: [SupervisorState; 8] = [
        SupervisorState::Boot,
        SupervisorState::Idle,
        SupervisorState::Tuning,
        SupervisorState::Calibrating,
        SupervisorState::RampUp,
        SupervisorState::Running,
        SupervisorState::RampDown,
        SupervisorState::Fault,
    ];

    /// The state's name on the wire: lowercase ASCII, at most 11 bytes.
    pub const fn name(self) -> &'static str {
        match self {
            SupervisorState::Boot => "boot",
            SupervisorState::Idle => "idle",
            SupervisorState::Tuning => "tuning",
            SupervisorState::Calibrating => "calibrating",
            SupervisorState::RampUp => "ramp-up",
            SupervisorState::Running => "running",
            SupervisorState::RampDown => "ramp-down",
            SupervisorState::Fault => "fault",
        }
    }

    /// The state with this name, if any (the inverse of [`name`](Self::name)).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|state| state.name() == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::text::is_word;

    #[test]
    fn names_round_trip_and_are_words() {
        for state in SupervisorState::ALL {
            assert_eq!(SupervisorState::from_name(state.name()), Some(state));
            assert!(is_word(state.name()));
        }
        assert_eq!(SupervisorState::from_name("Running"), None);
        assert_eq!(SupervisorState::from_name(""), None);
    }
}
