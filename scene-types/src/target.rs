//! The friction target of a scene's target table and of the `target` command.

/// A friction target. Ranges are those of the `target` command (`sonolube::protocol::Quantity`); the
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
}
