//! Sensor faults a scene injects into the plant's load cells.

/// Which load cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Channel {
    /// The normal-load cell.
    Normal,
    /// The tangential (friction) cell.
    Tangential,
}

/// Which end of the converter range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Rail {
    /// Code 0.
    Low,
    /// Code 2^bits - 1.
    High,
}

/// What goes wrong with a cell.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FaultKind {
    /// The cell is disconnected: its amplifier drives the converter to a rail (an open bridge
    /// wire, an unplugged cell).
    Disconnected {
        /// Which rail the converter reads (default high).
        rail: Rail,
    },
    /// The reading freezes at the code it had at the onset (dead converter, frozen DMA).
    Stuck,
    /// A force is added to the measured value (a glitch, a knock, a loose connector).
    Spike {
        /// Added force, N, non-zero, |force| <= 2 x the cell's full scale.
        force_n: f64,
    },
}

/// A fault injected at a given time.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultEvent {
    /// Onset, s from the scene start, in [0, duration).
    pub at_s: f64,
    /// Which cell.
    pub channel: Channel,
    /// What happens.
    pub kind: FaultKind,
    /// How long it lasts, s, > 0, ending within the scene. `None`: to the end of the scene
    /// for a disconnection or a stuck reading, one control period for a spike.
    pub duration_s: Option<f64>,
}
