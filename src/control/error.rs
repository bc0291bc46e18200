//! Errors of the controller's commands, and their protocol codes.
//!
//! The protocol reserves execution errors 21-23 for exactly these refusals
//! (`protocol::ErrorCode`); a target outside its command range is the parser's
//! `out-of-range` (6), which the controller repeats if such a target reaches it anyway.

use heapless::String;

use super::reason::Reason;
use crate::protocol::{ErrorCode, ProtocolError, SupervisorState, Target, TargetRange, TokenText};

/// Why a command was refused. The controller's state is unchanged by a refused command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ControlError {
    /// The command is not allowed in the present state (21 `wrong-state`).
    WrongState {
        /// The command's protocol keyword (`start`, `clear`).
        command: &'static str,
        /// The present state.
        state: SupervisorState,
    },
    /// A fault is latched; `clear` it first (22 `fault-latched`).
    FaultLatched {
        /// The latched fault.
        fault: Reason,
    },
    /// `start` without a target (23 `no-target`).
    NoTarget,
    /// The target is outside its command range (6 `out-of-range`).
    InvalidTarget {
        /// The refused target.
        target: Target,
    },
}

impl ControlError {
    /// The protocol's error code.
    pub const fn code(&self) -> ErrorCode {
        match self {
            ControlError::WrongState { .. } => ErrorCode::WrongState,
            ControlError::FaultLatched { .. } => ErrorCode::FaultLatched,
            ControlError::NoTarget => ErrorCode::NoTarget,
            ControlError::InvalidTarget { .. } => ErrorCode::OutOfRange,
        }
    }

    /// The protocol error to reply with.
    pub fn to_protocol(&self) -> ProtocolError {
        match *self {
            ControlError::WrongState { command, state } => {
                ProtocolError::WrongState { command, state }
            }
            ControlError::FaultLatched { fault } => ProtocolError::FaultLatched {
                fault: fault.name(),
            },
            ControlError::NoTarget => ProtocolError::NoTarget,
            ControlError::InvalidTarget { target } => {
                let mut value: String<24> = String::new();
                // 24 bytes hold every u32 with its decimals; on failure the quote is empty.
                let _ = crate::protocol::write_target_value(&target, &mut value);
                ProtocolError::OutOfRange {
                    token: TokenText::new(value.as_str()),
                    quantity: target.quantity(),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_map_to_the_protocol_codes() {
        let wrong = ControlError::WrongState {
            command: "start",
            state: SupervisorState::Running,
        };
        assert_eq!(wrong.code().code(), 21);
        assert_eq!(wrong.to_protocol().code(), ErrorCode::WrongState);
        let latched = ControlError::FaultLatched {
            fault: Reason::Overcurrent,
        };
        assert_eq!(latched.code().code(), 22);
        assert_eq!(
            latched.to_protocol(),
            ProtocolError::FaultLatched {
                fault: "overcurrent"
            }
        );
        assert_eq!(ControlError::NoTarget.code().code(), 23);
        assert_eq!(
            ControlError::NoTarget.to_protocol(),
            ProtocolError::NoTarget
        );
        let bad = ControlError::InvalidTarget {
            target: Target::Coef {
                coef_ppm: 3_000_000,
            },
        };
        assert_eq!(bad.code(), ErrorCode::OutOfRange);
        match bad.to_protocol() {
            ProtocolError::OutOfRange { token, .. } => assert_eq!(token.as_str(), "3.000000"),
            other => panic!("{other:?}"),
        }
    }
}
