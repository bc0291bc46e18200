//! The drive frequency and the band the stack may be driven in.

/// A frequency in millihertz (`u32`: 0 to 4.29 MHz, resolution 1 mHz).
///
/// Millihertz rather than hertz because a resonance tracker moves the drive in steps far below
/// 1 Hz; the timer resolves about 1.3 Hz at 60 kHz (see [`crate::drive::PwmPeriod`]), so the
/// type never limits the resolution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frequency {
    millihertz: u32,
}

impl Frequency {
    /// Lowest drive frequency of the stack, 20 kHz (seed 003 Table 1 and §2: 20-60 kHz).
    pub const BAND_MIN: Self = Self::from_hz(20_000);
    /// Highest drive frequency of the stack, 60 kHz (seed 003 Table 1).
    pub const BAND_MAX: Self = Self::from_hz(60_000);

    /// A frequency of `millihertz` mHz.
    pub const fn from_millihertz(millihertz: u32) -> Self {
        Self { millihertz }
    }

    /// A frequency of `hz` Hz. Saturates at `u32::MAX` mHz (4.29 MHz, far outside the band,
    /// so a saturated value is still refused by every band check).
    pub const fn from_hz(hz: u32) -> Self {
        Self {
            millihertz: hz.saturating_mul(1000),
        }
    }

    /// The frequency in millihertz.
    pub const fn millihertz(self) -> u32 {
        self.millihertz
    }

    /// The frequency in whole hertz, rounded to nearest.
    pub const fn hz_rounded(self) -> u32 {
        // u64: millihertz + 500 may exceed u32 near u32::MAX.
        ((self.millihertz as u64 + 500) / 1000) as u32
    }

    /// Whether the frequency lies in the stack's band, [`Self::BAND_MIN`] to [`Self::BAND_MAX`]
    /// inclusive.
    pub const fn in_band(self) -> bool {
        self.millihertz >= Self::BAND_MIN.millihertz && self.millihertz <= Self::BAND_MAX.millihertz
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_edges_are_inside_and_their_neighbours_outside() {
        assert!(Frequency::BAND_MIN.in_band());
        assert!(Frequency::BAND_MAX.in_band());
        assert!(!Frequency::from_millihertz(19_999_999).in_band());
        assert!(!Frequency::from_millihertz(60_000_001).in_band());
        assert_eq!(Frequency::BAND_MIN.millihertz(), 20_000_000);
    }

    #[test]
    fn hertz_saturate_and_round() {
        assert_eq!(Frequency::from_hz(u32::MAX).millihertz(), u32::MAX);
        assert!(!Frequency::from_hz(u32::MAX).in_band());
        assert_eq!(Frequency::from_millihertz(40_000_499).hz_rounded(), 40_000);
        assert_eq!(Frequency::from_millihertz(40_000_500).hz_rounded(), 40_001);
        assert_eq!(Frequency::from_millihertz(u32::MAX).hz_rounded(), 4_294_967);
    }
}
