//! The resonance loop's state as the protocol writes it (`lock=` in `status` and telemetry).

/// The resonance loop's state on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Lock {
    /// `freq HZ`: the frequency is pinned.
    Pinned,
    /// `freq auto`: searching.
    Searching,
    /// `freq auto`: tracking, not locked.
    Tracking,
    /// `freq auto`: tracking and locked.
    Locked,
    /// `freq auto`: the resonance was lost (`resonance-lost` is latched).
    Lost,
}

impl Lock {
    /// Every state, in the order above.
    pub const ALL: [Lock; 5] = [
        Lock::Pinned,
        Lock::Searching,
        Lock::Tracking,
        Lock::Locked,
        Lock::Lost,
    ];

    /// The word on the wire.
    pub const fn name(self) -> &'static str {
        match self {
            Lock::Pinned => "pinned",
            Lock::Searching => "searching",
            Lock::Tracking => "tracking",
            Lock::Locked => "locked",
            Lock::Lost => "lost",
        }
    }

    /// The state named `word`, if any.
    pub fn from_name(word: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|lock| lock.name() == word)
    }
}

impl From<crate::resonance::LockState> for Lock {
    fn from(state: crate::resonance::LockState) -> Self {
        use crate::resonance::LockState;
        match state {
            LockState::Pinned => Lock::Pinned,
            LockState::Searching => Lock::Searching,
            LockState::Tracking => Lock::Tracking,
            LockState::Locked => Lock::Locked,
            LockState::Lost(_) => Lock::Lost,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_match_the_loop() {
        for lock in Lock::ALL {
            assert_eq!(Lock::from_name(lock.name()), Some(lock));
            assert!(crate::protocol::is_word(lock.name()));
        }
        assert_eq!(Lock::from_name("none"), None);
        let lost = crate::resonance::LockState::Lost(crate::resonance::ResonanceFault::NoCurrent);
        assert_eq!(Lock::from(lost).name(), lost.name());
    }
}
