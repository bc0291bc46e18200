//! What can go wrong: settings refused at configuration, and faults found while running.

use core::fmt;

use crate::drive::DriveError;

/// A resonance setting that cannot work. Returned at configuration (and by a retune that would
/// leave the lock-in without a usable reference), never by the per-sample path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResonanceError {
    /// Fewer than 3 samples per turn of the (possibly aliased) drive phase, or a drive that is
    /// an exact multiple of the sample rate (the reference would not rotate): in-phase and
    /// quadrature cannot both be observed.
    SamplingTooSlow,
    /// A demodulation window longer than [`crate::resonance::MAX_WINDOW_SAMPLES`] (the
    /// accumulators' stated headroom), or of zero periods.
    WindowLength,
    /// The drive refused the frequency (outside 20-60 kHz) or the timer cannot produce it.
    Drive(DriveError),
    /// A search band, step or limit that is empty, inverted or outside 20-60 kHz.
    Band,
    /// A physical setting (capacitance, voltage, current scale, Q, gain, rate) that is not
    /// finite and positive, or whose fixed-point form would overflow.
    Setting,
}

impl From<DriveError> for ResonanceError {
    fn from(error: DriveError) -> Self {
        Self::Drive(error)
    }
}

impl fmt::Display for ResonanceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::SamplingTooSlow => {
                f.write_str("fewer than 3 current samples per turn of the drive phase")
            }
            Self::WindowLength => f.write_str("demodulation window empty or too long"),
            Self::Drive(error) => write!(f, "drive: {error}"),
            Self::Band => f.write_str("frequency band, step or limit out of range"),
            Self::Setting => f.write_str("resonance setting not finite, positive and in range"),
        }
    }
}

impl core::error::Error for ResonanceError {}

/// A fault found while searching or tracking: the drive must not be trusted to sit at the
/// resonance, and no frequency is reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResonanceFault {
    /// The drive current stayed below the no-current threshold: stack or current sense
    /// disconnected, or the bridge not switching.
    NoCurrent,
    /// Current flows but the conductance has no peak inside the search band (the peak sits at
    /// a band edge or does not stand out of the capacitive background).
    NoResonance,
    /// The phase loop did not settle on the resonance within its time budget.
    PullInTimeout,
    /// The tracked frequency sat at a frequency limit for the configured time while the
    /// motional phase still asked to go further: the resonance left the allowed range.
    AtFrequencyLimit,
}

impl fmt::Display for ResonanceFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NoCurrent => "no drive current (stack or current sense disconnected)",
            Self::NoResonance => "no conductance peak inside the search band",
            Self::PullInTimeout => "phase loop did not settle on the resonance in time",
            Self::AtFrequencyLimit => "resonance outside the allowed frequency range",
        })
    }
}

impl core::error::Error for ResonanceFault {}
