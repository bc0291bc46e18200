//! Words for the controller's configuration and command errors (`Display`), so that a tool
//! reports "the slew time is not a positive number", not `Shaper(OutOfRange)`. A tool that
//! knows where a setting came from (a scene file) adds that; these say what the rule is.

use core::fmt;

use super::{ConfigError, ControlError, FilterError, GainsError, LimitsError, ShaperError};

impl fmt::Display for FilterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotPositive => "a frequency or time constant is not a finite positive number",
            Self::AboveNyquist => "the bandwidth is not below half the control rate (Nyquist)",
            Self::TooSlow => {
                "the filter is too slow for the control rate (coefficient below 2^-20: \
                 minutes to settle, and its precision is lost)"
            }
        })
    }
}

impl fmt::Display for ShaperError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Filter(error) => write!(f, "drive shaping: {error}"),
            Self::OutOfRange => f.write_str(
                "drive shaping: the slew time is not a positive number, or the lead gain (the \
                 response filter's coefficient over the envelope's) is 128 or more: the \
                 envelope is too slow for the response asked of it",
            ),
        }
    }
}

impl fmt::Display for GainsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotFinite => {
                "a PI gain, the period or the integral limit is negative or not finite"
            }
            Self::OutOfRange => {
                "PI gains: kp is 128 or more, the integral gain times the period (ki T) is above \
                 1 (the correction loop would oscillate), or the integral limit is 2 or more"
            }
        })
    }
}

impl fmt::Display for LimitsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotPositive => "an actuator rating is not a finite positive number",
            Self::NoHeadroom => {
                "the actuator ratings leave the drive less than 2^-20 of full scale: it could \
                 do nothing"
            }
        })
    }
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Filter { setting, error } => write!(f, "controller setting {setting}: {error}"),
            Self::Shaper(error) => write!(f, "controller {error}"),
            Self::Limits(error) => write!(f, "controller amplitude ceiling: {error}"),
            Self::Gains(error) => write!(f, "controller {error}"),
            Self::OutOfRange { setting } => write!(
                f,
                "controller setting {setting} is not a number, not positive where it must be, \
                 or does not fit its fixed-point format"
            ),
        }
    }
}

impl fmt::Display for ControlError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::WrongState { command, state } => {
                write!(f, "`{command}` is not allowed in state {}", state.name())
            }
            Self::FaultLatched { fault } => {
                write!(f, "fault {} is latched; `clear` it first", fault.name())
            }
            Self::NoTarget => f.write_str("`start` without a target"),
            Self::InvalidTarget { .. } => f.write_str("the target is outside its command range"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::format;

    #[test]
    fn errors_read_as_words_not_variant_names() {
        let texts = [
            format!("{}", ConfigError::Shaper(ShaperError::OutOfRange)),
            format!("{}", ConfigError::Gains(GainsError::OutOfRange)),
            format!(
                "{}",
                ConfigError::Filter {
                    setting: "normal_bandwidth_hz",
                    error: FilterError::AboveNyquist
                }
            ),
            format!("{}", ConfigError::Limits(LimitsError::NoHeadroom)),
            format!(
                "{}",
                ConfigError::OutOfRange {
                    setting: "natural_prior"
                }
            ),
            format!("{}", ControlError::NoTarget),
        ];
        for text in &texts {
            for name in [
                "OutOfRange",
                "Shaper(",
                "Gains(",
                "Filter",
                "NoHeadroom",
                "NoTarget",
            ] {
                assert!(!text.contains(name), "{text}");
            }
            assert!(text.split(' ').count() >= 4, "{text}");
        }
        assert!(texts[0].contains("lead gain"));
        assert!(texts[1].contains("ki T"));
        assert!(texts[2].contains("normal_bandwidth_hz") && texts[2].contains("Nyquist"));
    }
}
