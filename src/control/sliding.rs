//! Sliding detection: is there sliding, hence friction to reduce?
//!
//! Without sliding there is no kinetic friction to lower (physics-notes §1: the Littmann law
//! needs `v_s != 0`), and the friction ratio means nothing. The detector compares the speed
//! `|v|` with two thresholds (hysteresis: on above `on`, off below `off < on`) and accepts a
//! change only after it has held for `debounce_steps` consecutive control steps, so that
//! velocity noise near a threshold or a glitch of one sample does not toggle the loop. It uses
//! the unfiltered velocity: the debounce is the filter, and its delay is exactly stated.

use super::SampleBlock;
use crate::fx::Q8_24;

/// Configuration of the sliding detector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SlidingConfig {
    /// Speed above which sliding starts, Q8.24 m/s, > `off`.
    pub on: Q8_24,
    /// Speed below which sliding stops, Q8.24 m/s, >= 0.
    pub off: Q8_24,
    /// Consecutive steps a change must hold before it is accepted (0 or 1: immediate).
    pub debounce_steps: u32,
}

/// State of the sliding detector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SlidingDetector {
    sliding: bool,
    pending: u32,
}

impl SlidingDetector {
    /// A detector that starts in "not sliding".
    pub const fn new() -> Self {
        Self {
            sliding: false,
            pending: 0,
        }
    }

    /// Whether the contact slides (as of the last update).
    pub const fn is_sliding(&self) -> bool {
        self.sliding
    }
}

/// The detector: one velocity sample (any bits, signed) into the state; whether the contact
/// slides out.
impl SampleBlock<Q8_24> for SlidingConfig {
    type State = SlidingDetector;
    type Output = bool;

    fn process(&self, detector: &mut SlidingDetector, velocity: Q8_24) -> bool {
        let speed = velocity.saturating_abs().value;
        let wants_change = if detector.sliding {
            speed < self.off
        } else {
            speed > self.on
        };
        if wants_change {
            detector.pending = detector.pending.saturating_add(1);
            if detector.pending >= self.debounce_steps {
                detector.sliding = !detector.sliding;
                detector.pending = 0;
            }
        } else {
            detector.pending = 0;
        }
        detector.sliding
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> SlidingConfig {
        SlidingConfig {
            on: Q8_24::from_f64(1e-3).unwrap(),
            off: Q8_24::from_f64(0.5e-3).unwrap(),
            debounce_steps: 20,
        }
    }

    fn v(x: f64) -> Q8_24 {
        Q8_24::from_f64(x).unwrap()
    }

    #[test]
    fn debounce_and_hysteresis() {
        let cfg = config();
        let mut det = SlidingDetector::new();
        // 19 fast samples then a glitch: not yet sliding.
        for _ in 0..19 {
            assert!(!cfg.process(&mut det, v(0.038)));
        }
        assert!(!cfg.process(&mut det, v(0.0)));
        for _ in 0..19 {
            assert!(!cfg.process(&mut det, v(-0.038)));
        }
        assert!(cfg.process(&mut det, v(-0.038)), "20th sample in a row");
        // Between the thresholds: stays sliding for ever.
        for _ in 0..1_000 {
            assert!(cfg.process(&mut det, v(0.7e-3)));
        }
        for _ in 0..19 {
            assert!(cfg.process(&mut det, v(0.1e-3)));
        }
        assert!(!cfg.process(&mut det, v(0.1e-3)));
        // Between the thresholds again: stays stopped.
        for _ in 0..1_000 {
            assert!(!cfg.process(&mut det, v(0.7e-3)));
        }
        assert!(!det.is_sliding());
    }

    #[test]
    fn extreme_velocity_bits() {
        let cfg = SlidingConfig {
            debounce_steps: 0,
            ..config()
        };
        let mut det = SlidingDetector::new();
        assert!(cfg.process(&mut det, Q8_24::MIN)); // |MIN| saturates to MAX: fast
        assert!(cfg.process(&mut det, Q8_24::MAX));
        assert!(!cfg.process(&mut det, Q8_24::ZERO));
    }
}
