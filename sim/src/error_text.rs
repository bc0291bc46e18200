//! Words for why a scene cannot run (`Display` of [`SimError`] and [`PlantError`]). The host's
//! `sonolube scene` adds which scene value led there (`cli/src/commands/scene/why.rs`).

use core::fmt;

use super::{MAX_CRITERIA, MAX_FAULTS, SimError};
use crate::plant::PlantError;

impl fmt::Display for PlantError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidScene { field } => write!(
                f,
                "the plant cannot use scene value {field}: outside the range scenes/README.md \
                 gives"
            ),
            Self::Model(error) => write!(f, "the plant's friction model: {error}"),
        }
    }
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Plant(error) => write!(f, "{error}"),
            Self::Model(error) => write!(f, "the controller's friction model: {error}"),
            Self::Config(error) => write!(f, "{error}"),
            Self::Control(error) => write!(f, "the controller refused the first target: {error}"),
            Self::Sense(error) => write!(f, "a load cell's converter: {error}"),
            Self::Calibration => f.write_str(
                "a load cell's full scale does not fit the calibration's Q16.16 span (above \
                 16 383 N)",
            ),
            Self::InvalidTarget => f.write_str(
                "a target point is outside the `target` command's range, or there is none",
            ),
            Self::TooLarge => write!(
                f,
                "more than {MAX_CRITERIA} criteria or {MAX_FAULTS} faults (the runner's capacity)"
            ),
            Self::Resonance(error) => {
                write!(f, "the scene's resonance loop refused its start: {error:?}")
            }
            Self::Commission(step, reason) => {
                write!(
                    f,
                    "commissioning refused at its {} step: {reason}",
                    step.name()
                )
            }
        }
    }
}
