//! The friction target: what the loop holds, in one of three ways.
//!
//! On the wire a target is written `kind:value` (`force:12.500`, `coef:0.350000`,
//! `reduction:40.000`) in replies and telemetry, and `none` when no target is set. The value
//! always has the full number of decimals of its quantity.

use heapless::string::StringView;

use super::number::{NumberError, decode_u32};
use super::quantity::{Quantity, TARGET_COEF, TARGET_FORCE, TARGET_REDUCTION};
use super::text::{FormatError, put, put_fixed};

/// A friction target. Ranges are those of the `target` command (see [`Quantity`]); the
/// telemetry decoder accepts any `u32` so that it never rejects what the firmware printed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Target {
    /// Hold the friction force (tangential force while sliding).
    Force {
        /// Friction force in mN, `1..=50_000_000` (0.001 N to 50 kN).
        force_mn: u32,
    },
    /// Hold the friction coefficient (friction force over normal force).
    Coef {
        /// Coefficient in ppm (1e-6), `1..=2_000_000` (0.000001 to 2).
        coef_ppm: u32,
    },
    /// Hold a reduction of the natural (undriven) friction.
    Reduction {
        /// Reduction in milli-percent, `0..=99_999` (0 % to 99.999 %).
        reduction_mpct: u32,
    },
}

/// Text of an absent target in replies and telemetry.
pub const NO_TARGET: &str = "none";

impl Target {
    /// The kind as written on the wire and in the `target` command: `force`, `coef` or
    /// `reduction`.
    pub const fn kind(&self) -> &'static str {
        match self {
            Target::Force { .. } => "force",
            Target::Coef { .. } => "coef",
            Target::Reduction { .. } => "reduction",
        }
    }

    /// The quantity (unit, resolution, command range) of this kind of target.
    pub const fn quantity(&self) -> &'static Quantity {
        match self {
            Target::Force { .. } => &TARGET_FORCE,
            Target::Coef { .. } => &TARGET_COEF,
            Target::Reduction { .. } => &TARGET_REDUCTION,
        }
    }

    /// The scaled value: mN, ppm or milli-percent depending on the kind.
    pub const fn scaled_value(&self) -> u32 {
        match *self {
            Target::Force { force_mn } => force_mn,
            Target::Coef { coef_ppm } => coef_ppm,
            Target::Reduction { reduction_mpct } => reduction_mpct,
        }
    }

    /// The target of kind `kind` (as returned by [`kind`](Self::kind)) with a scaled value.
    pub fn from_kind(kind: &str, scaled_value: u32) -> Option<Self> {
        match kind {
            "force" => Some(Target::Force {
                force_mn: scaled_value,
            }),
            "coef" => Some(Target::Coef {
                coef_ppm: scaled_value,
            }),
            "reduction" => Some(Target::Reduction {
                reduction_mpct: scaled_value,
            }),
            _ => None,
        }
    }

    /// Whether the value is inside the range the `target` command accepts.
    pub fn is_valid(&self) -> bool {
        self.quantity().contains(i64::from(self.scaled_value()))
    }

    /// Appends the value alone with all its decimals: `12.500`.
    pub(crate) fn write_value(&self, out: &mut StringView) -> Result<(), FormatError> {
        put_fixed(
            out,
            i64::from(self.scaled_value()),
            self.quantity().decimals,
        )
    }
}

/// Appends `kind:value`, or [`NO_TARGET`].
pub(crate) fn write_target(
    out: &mut StringView,
    target: Option<&Target>,
) -> Result<(), FormatError> {
    match target {
        None => put(out, NO_TARGET),
        Some(target) => {
            put(out, target.kind())?;
            put(out, ":")?;
            target.write_value(out)
        }
    }
}

/// Why a `kind:value` target could not be decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TargetDecodeError {
    /// Neither `none` nor `kind:value` with a known kind.
    UnknownKind,
    /// The value is not a number of the kind's resolution that fits a `u32`.
    BadValue(NumberError),
}

/// Decodes the `target=` value of a status reply or telemetry line: `None` for [`NO_TARGET`].
pub fn decode_target(text: &str) -> Result<Option<Target>, TargetDecodeError> {
    if text == NO_TARGET {
        return Ok(None);
    }
    let (kind, value) = text.split_once(':').ok_or(TargetDecodeError::UnknownKind)?;
    // Learn the kind first (with a dummy value) to know how many decimals to read.
    let decimals = Target::from_kind(kind, 0)
        .ok_or(TargetDecodeError::UnknownKind)?
        .quantity()
        .decimals;
    let scaled = decode_u32(value, decimals).map_err(TargetDecodeError::BadValue)?;
    Ok(Target::from_kind(kind, scaled))
}

#[cfg(test)]
mod tests {
    use super::*;
    use heapless::String;

    fn text(target: Option<&Target>) -> String<32> {
        let mut out = String::new();
        write_target(&mut out, target).unwrap();
        out
    }

    #[test]
    fn targets_print_with_full_resolution() {
        assert_eq!(
            text(Some(&Target::Force { force_mn: 12_500 })),
            "force:12.500"
        );
        assert_eq!(
            text(Some(&Target::Coef { coef_ppm: 350_000 })),
            "coef:0.350000"
        );
        assert_eq!(
            text(Some(&Target::Reduction {
                reduction_mpct: 99_999
            })),
            "reduction:99.999"
        );
        assert_eq!(text(None), "none");
    }

    #[test]
    fn targets_decode() {
        for target in [
            None,
            Some(Target::Force { force_mn: u32::MAX }),
            Some(Target::Coef { coef_ppm: 0 }),
            Some(Target::Reduction { reduction_mpct: 1 }),
        ] {
            assert_eq!(decode_target(&text(target.as_ref())), Ok(target));
        }
        assert_eq!(
            decode_target("speed:1"),
            Err(TargetDecodeError::UnknownKind)
        );
        assert_eq!(decode_target("force"), Err(TargetDecodeError::UnknownKind));
        assert_eq!(
            decode_target("coef:0.0000001"),
            Err(TargetDecodeError::BadValue(NumberError::TooManyDecimals))
        );
    }

    #[test]
    fn validity_follows_the_command_ranges() {
        assert!(Target::Force { force_mn: 1 }.is_valid());
        assert!(!Target::Force { force_mn: 0 }.is_valid());
        assert!(
            Target::Coef {
                coef_ppm: 2_000_000
            }
            .is_valid()
        );
        assert!(
            !Target::Coef {
                coef_ppm: 2_000_001
            }
            .is_valid()
        );
        assert!(Target::Reduction { reduction_mpct: 0 }.is_valid());
        assert!(
            !Target::Reduction {
                reduction_mpct: 100_000
            }
            .is_valid()
        );
    }
}
