//! The one shape of the loop's per-sample blocks: configuration apart from state, one sample
//! in, one out.
//!
//! A block's configuration (coefficients, thresholds, limits) is the value the trait is
//! implemented on: `Copy`, computed once in `f64` at configuration and swapped whole between
//! two samples (a `freq` command, new gains), never changed by a sample. Its state (filter
//! memory, debounce count, last command) is a separate value the caller owns and passes in:
//! a sample can change the state, never the configuration. So one configuration can run
//! several states (the controller's three prediction filters share the tangential filter's
//! coefficient with the estimator's), and replacing the configuration never loses the state
//! (a retune is bumpless by construction).
//!
//! The shape follows the split-state processing trait of the `idsp` / `dsp-process` crates
//! (immutable configuration operating on explicit mutable state); ours is smaller: one
//! method, [`SampleBlock::process`], no block or in-place variants (the loop takes one sample
//! per period), and the state type is tied to the configuration.
//!
//! The blocks: [`super::LowPassCoef`] on [`super::LowPass`] (the filters),
//! [`super::SlidingConfig`] on [`super::SlidingDetector`], [`super::ShaperConfig`] on
//! [`super::DriveShaper`], [`super::GainSchedule`] on [`super::Boost`]; in the resonance
//! loop, [`crate::resonance::Demodulator`] on [`crate::resonance::LockInSums`] (the lock-in,
//! one current sample in, a window's phasor out at its end) and
//! [`crate::resonance::TrackingLoop`] on [`crate::resonance::TrackerState`] (the PI tracker,
//! one window in, one drive setting out). The search's sweep and the ring-down fit work once
//! per window or per group, on the lock-in's output, not per sample: they stay step machines.

/// A per-sample block of the control loop: `self` is its configuration, `state` what one
/// sample changes.
pub trait SampleBlock<Input> {
    /// The part of the block one sample changes.
    type State;
    /// What the block gives for one sample.
    type Output;

    /// Takes one `input` sample into `state` and returns the block's output for it. Never
    /// panics, never overflows (each block states its formats and ranges).
    fn process(&self, state: &mut Self::State, input: Input) -> Self::Output;
}
