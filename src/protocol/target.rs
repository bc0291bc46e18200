//! The friction target: what the loop holds, in one of three ways.
//!
//! On the wire a target is written `kind:value` (`force:12.500`, `coef:0.350000`,
//! `reduction:40.000`, `net-force:-5.000`) in replies and telemetry, and `none` when no target
//! is set. The value always has the full number of decimals of its quantity; only the net
//! force carries a sign.

use heapless::string::StringView;

use super::number::{NumberError, decode_i32, decode_u32};
use super::quantity::{Quantity, TARGET_COEF, TARGET_FORCE, TARGET_NET_FORCE, TARGET_REDUCTION};
use super::text::{FormatError, put, put_fixed};

/// The friction target (defined with the scene types, `sonolube-scene-types`, which the scene
/// files share; its wire ranges are the protocol's: [`TargetRange`]).
pub use sonolube_scene_types::Target;

/// Text of an absent target in replies and telemetry.
pub const NO_TARGET: &str = "none";

/// What the protocol adds to a [`Target`]: its quantity (unit, resolution, the `target`
/// command's range) and its written value.
pub trait TargetRange {
    /// The quantity (unit, resolution, command range) of this kind of target.
    fn quantity(&self) -> &'static Quantity;

    /// Whether the value is inside the range the `target` command accepts.
    fn is_valid(&self) -> bool;
}

impl TargetRange for Target {
    fn quantity(&self) -> &'static Quantity {
        match self {
            Target::Force { .. } => &TARGET_FORCE,
            Target::Coef { .. } => &TARGET_COEF,
            Target::Reduction { .. } => &TARGET_REDUCTION,
            Target::NetForce { .. } => &TARGET_NET_FORCE,
        }
    }

    fn is_valid(&self) -> bool {
        self.quantity().contains(self.scaled_value())
    }
}

/// Appends the value alone with all its decimals: `12.500`.
pub(crate) fn write_value(target: &Target, out: &mut StringView) -> Result<(), FormatError> {
    put_fixed(out, target.scaled_value(), target.quantity().decimals)
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
            write_value(target, out)
        }
    }
}

/// Why a `kind:value` target could not be decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TargetDecodeError {
    /// Neither `none` nor `kind:value` with a known kind.
    UnknownKind,
    /// The value is not a number of the kind's resolution that fits the kind's field (`u32`,
    /// or `i32` for the net force).
    BadValue(NumberError),
}

/// Decodes the `target=` value of a status reply or telemetry line: `None` for [`NO_TARGET`].
pub fn decode_target(text: &str) -> Result<Option<Target>, TargetDecodeError> {
    if text == NO_TARGET {
        return Ok(None);
    }
    let (kind, value) = text.split_once(':').ok_or(TargetDecodeError::UnknownKind)?;
    // Learn the kind first (with a dummy value) to know how many decimals and which sign.
    let probe = Target::from_kind(kind, 0).ok_or(TargetDecodeError::UnknownKind)?;
    let decimals = probe.quantity().decimals;
    let scaled = if probe.is_signed() {
        decode_i32(value, decimals).map(i64::from)
    } else {
        decode_u32(value, decimals).map(i64::from)
    }
    .map_err(TargetDecodeError::BadValue)?;
    // The decoders bound the value to the kind's field: this cannot be `None`.
    Target::from_kind(kind, scaled)
        .map(Some)
        .ok_or(TargetDecodeError::BadValue(NumberError::OutOfRange))
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
        assert_eq!(
            text(Some(&Target::NetForce { force_mn: -5_000 })),
            "net-force:-5.000"
        );
        assert_eq!(
            text(Some(&Target::NetForce { force_mn: 1 })),
            "net-force:0.001"
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
            Some(Target::NetForce { force_mn: i32::MIN }),
            Some(Target::NetForce { force_mn: i32::MAX }),
            Some(Target::NetForce { force_mn: 0 }),
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
        // A negative value is refused for the magnitude kinds, and beyond i32 for the net
        // force: never wrapped.
        assert_eq!(
            decode_target("force:-1.000"),
            Err(TargetDecodeError::BadValue(NumberError::OutOfRange))
        );
        assert_eq!(
            decode_target("net-force:-2147483.649"),
            Err(TargetDecodeError::BadValue(NumberError::OutOfRange))
        );
        assert_eq!(
            decode_target("net-force:x"),
            Err(TargetDecodeError::BadValue(NumberError::NotANumber))
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
        assert!(
            Target::NetForce {
                force_mn: -50_000_000
            }
            .is_valid()
        );
        assert!(Target::NetForce { force_mn: 0 }.is_valid());
        assert!(
            !Target::NetForce {
                force_mn: 50_000_001
            }
            .is_valid()
        );
    }
}
