//! The friction target of a scene's target table and of the `target` command.

/// A friction target. Ranges are those of the `target` command (`sonolube::protocol::Quantity`); the
/// telemetry decoder accepts any value of the field's type (`u32`, or `i32` for the signed net
/// force) so that it never rejects what the firmware printed.
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
    /// Hold the net tangential force the horn exerts on the block, along +x (seed 001 §3.2:
    /// in a motor region the vibration drives the block towards the centreline, so the force
    /// has either sign). Holding a block still against an external load F_ext is the target
    /// -F_ext (issue 27).
    NetForce {
        /// Force in mN along +x, signed, `-50_000_000..=50_000_000` (+-50 kN, the force
        /// targets' range).
        force_mn: i32,
    },
}

impl Target {
    /// The kind as written on the wire and in the `target` command: `force`, `coef`,
    /// `reduction` or `net-force`.
    pub const fn kind(&self) -> &'static str {
        match self {
            Target::Force { .. } => "force",
            Target::Coef { .. } => "coef",
            Target::Reduction { .. } => "reduction",
            Target::NetForce { .. } => "net-force",
        }
    }

    /// The scaled value: mN, ppm or milli-percent depending on the kind; signed (only
    /// [`Target::NetForce`] can be negative), so `i64` holds every kind's field.
    pub const fn scaled_value(&self) -> i64 {
        match *self {
            Target::Force { force_mn } => force_mn as i64,
            Target::Coef { coef_ppm } => coef_ppm as i64,
            Target::Reduction { reduction_mpct } => reduction_mpct as i64,
            Target::NetForce { force_mn } => force_mn as i64,
        }
    }

    /// Whether the kind's value is signed (the net force) rather than a magnitude.
    pub const fn is_signed(&self) -> bool {
        matches!(self, Target::NetForce { .. })
    }

    /// The target of kind `kind` (as returned by [`kind`](Self::kind)) with a scaled value;
    /// `None` for an unknown kind or a value that does not fit the kind's field (`u32`, or
    /// `i32` for the net force): never wrapped.
    pub fn from_kind(kind: &str, scaled_value: i64) -> Option<Self> {
        let unsigned = u32::try_from(scaled_value).ok();
        match kind {
            "force" => Some(Target::Force {
                force_mn: unsigned?,
            }),
            "coef" => Some(Target::Coef {
                coef_ppm: unsigned?,
            }),
            "reduction" => Some(Target::Reduction {
                reduction_mpct: unsigned?,
            }),
            "net-force" => Some(Target::NetForce {
                force_mn: i32::try_from(scaled_value).ok()?,
            }),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_round_trip_and_values_never_wrap() {
        for target in [
            Target::Force { force_mn: u32::MAX },
            Target::Coef { coef_ppm: 0 },
            Target::Reduction { reduction_mpct: 7 },
            Target::NetForce { force_mn: i32::MIN },
            Target::NetForce { force_mn: -5_000 },
        ] {
            assert_eq!(
                Target::from_kind(target.kind(), target.scaled_value()),
                Some(target)
            );
        }
        assert_eq!(Target::from_kind("force", -1), None);
        assert_eq!(Target::from_kind("coef", i64::from(u32::MAX) + 1), None);
        assert_eq!(
            Target::from_kind("net-force", i64::from(i32::MAX) + 1),
            None
        );
        assert_eq!(
            Target::from_kind("net-force", i64::from(i32::MIN) - 1),
            None
        );
        assert_eq!(Target::from_kind("speed", 1), None);
        assert!(Target::NetForce { force_mn: 1 }.is_signed());
        assert!(!Target::Force { force_mn: 1 }.is_signed());
    }
}
