//! Whether the running target is within the drive's reach and the drive near the resonance:
//! the `reach=`, `reachable=` and `resonance=` fields of `status` and of every telemetry record
//! (issue 26: a target out of reach showed only as `amp=1.000000 fault=none`).

use heapless::string::StringView;

use super::reply::OkReply;
use super::target::Target;
use super::text::FormatError;

/// Whether the loop holds its target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ReachState {
    /// `ok`: no sign that the target is out of reach (the drive is below its limit, or the
    /// error still falls).
    Ok,
    /// `target-unreachable`: the drive has been at its limit, with the error not falling, for
    /// as long as the drive takes to act (the envelope, the cell and the force filter).
    TargetUnreachable,
}

impl ReachState {
    /// Every state.
    pub const ALL: [ReachState; 2] = [ReachState::Ok, ReachState::TargetUnreachable];

    /// The word on the wire.
    pub const fn name(self) -> &'static str {
        match self {
            ReachState::Ok => "ok",
            ReachState::TargetUnreachable => "target-unreachable",
        }
    }

    /// The state of a wire word.
    pub fn from_name(word: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == word)
    }
}

/// Where the drive frequency is against the stack's resonance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResonanceDistance {
    /// `near`: within the half-power band, the motional conductance at least half of the
    /// resonance's (`G / G0 = 1 / (1 + x^2) >= 1/2`, `x = 2 Q (f - f0) / f0`).
    Near,
    /// `far`: outside it: the drive moves less than 71 % of the vibration full scale promises.
    Far,
}

impl ResonanceDistance {
    /// Every value.
    pub const ALL: [ResonanceDistance; 2] = [ResonanceDistance::Near, ResonanceDistance::Far];

    /// The word on the wire.
    pub const fn name(self) -> &'static str {
        match self {
            ResonanceDistance::Near => "near",
            ResonanceDistance::Far => "far",
        }
    }

    /// The value of a wire word.
    pub fn from_name(word: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == word)
    }

    /// The distance of a detuning `x = (f - f0) / (f0 / 2Q)` in half-bandwidths: the
    /// motional conductance over the resonance's is `1 / (1 + x^2)`, half at `|x| = 1`.
    pub fn of_detuning(half_bandwidths: f64) -> Self {
        if libm::fabs(half_bandwidths) <= 1.0 {
            ResonanceDistance::Near
        } else {
            ResonanceDistance::Far
        }
    }
}

/// The reach fields of `status` and telemetry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RunReach {
    /// Whether the target is held or out of reach.
    pub state: ReachState,
    /// With `target-unreachable`, the nearest value the model says the full drive reaches now,
    /// in the target's kind; `None` (`none`) otherwise.
    pub reachable: Option<Target>,
    /// The drive frequency against the resonance; `None` (`unknown`) without a scene.
    pub resonance: Option<ResonanceDistance>,
}

impl RunReach {
    /// Nothing known: `reach=ok reachable=none resonance=unknown`.
    pub const UNKNOWN: Self = Self {
        state: ReachState::Ok,
        reachable: None,
        resonance: None,
    };
}

/// The word of an unknown resonance distance.
pub const UNKNOWN_WORD: &str = "unknown";

/// The word of a target beyond reach in the `target` acknowledgement.
pub const BEYOND_REACH: &str = "beyond-reach";

/// Writes the acknowledgement of `target`: `ok target=kind:value`, and when the model says
/// the full drive does not reach it now, `warning=beyond-reach reachable=kind:value` (the
/// nearest value the drive gives). The target is accepted either way.
pub fn format_target_ack(
    target: &Target,
    reachable: Option<&Target>,
    out: &mut StringView,
) -> Result<(), FormatError> {
    let reply = OkReply::new(out).target("target", Some(target));
    match reachable {
        Some(reachable) => reply
            .word("warning", BEYOND_REACH)
            .target("reachable", Some(reachable)),
        None => reply,
    }
    .finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_target_beyond_reach_is_acknowledged_with_a_warning() {
        let mut out: heapless::String<128> = heapless::String::new();
        let target = Target::Reduction {
            reduction_mpct: 99_999,
        };
        format_target_ack(&target, None, &mut out).unwrap();
        assert_eq!(out, "ok target=reduction:99.999\n");
        let reachable = Target::Reduction {
            reduction_mpct: 79_400,
        };
        format_target_ack(&target, Some(&reachable), &mut out).unwrap();
        assert_eq!(
            out,
            "ok target=reduction:99.999 warning=beyond-reach reachable=reduction:79.400\n"
        );
        let Ok(super::super::Reply::Ok(payload)) = super::super::parse_reply(&out) else {
            panic!("{out}");
        };
        assert_eq!(payload.get("reachable"), Some("reduction:79.400"));
    }

    #[test]
    fn words_round_trip() {
        for state in ReachState::ALL {
            assert_eq!(ReachState::from_name(state.name()), Some(state));
        }
        for distance in ResonanceDistance::ALL {
            assert_eq!(
                ResonanceDistance::from_name(distance.name()),
                Some(distance)
            );
        }
        assert_eq!(ReachState::from_name("unknown"), None);
    }

    #[test]
    fn the_half_power_band_is_near() {
        assert_eq!(ResonanceDistance::of_detuning(0.0), ResonanceDistance::Near);
        assert_eq!(
            ResonanceDistance::of_detuning(-1.0),
            ResonanceDistance::Near
        );
        assert_eq!(ResonanceDistance::of_detuning(1.01), ResonanceDistance::Far);
        // `freq 20000` on the 40 kHz, Q = 100 stack: x = 2 * 100 * (-0.5) = -100.
        assert_eq!(
            ResonanceDistance::of_detuning(-100.0),
            ResonanceDistance::Far
        );
    }
}
