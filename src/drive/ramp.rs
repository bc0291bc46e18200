//! Rate-limited amplitude: soft start and ramp-down.
//!
//! A step in drive amplitude is a step in stack voltage; into a capacitive load behind an
//! inductor it rings, and a step of friction reduction jolts the slider. The ramp moves the
//! applied amplitude towards the requested one by at most a fixed increment per control step.
//! The ceiling from [`crate::drive::DriveLimits`] is different: it is a hard bound, applied at
//! once, because exceeding a rating for even a few steps is not acceptable.

use super::amplitude::Amplitude;
use super::error::DriveError;

/// Full scale in Q2.30 bits.
const FULL_BITS: u32 = Amplitude::FULL.bits();

/// An amplitude that follows its target at a limited rate. State plus two constants; `Copy`
/// so a control loop can swap configurations atomically.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AmplitudeRamp {
    now: Amplitude,
    rise_per_step: u32,
    fall_per_step: u32,
}

impl AmplitudeRamp {
    /// A ramp, starting at zero, that takes at most `rise_steps` control steps from zero to full
    /// scale and at most `fall_steps` back. Error `InvalidRamp` if either is zero.
    pub const fn new(rise_steps: u32, fall_steps: u32) -> Result<Self, DriveError> {
        if rise_steps == 0 || fall_steps == 0 {
            return Err(DriveError::InvalidRamp);
        }
        Ok(Self {
            now: Amplitude::ZERO,
            rise_per_step: FULL_BITS.div_ceil(rise_steps),
            fall_per_step: FULL_BITS.div_ceil(fall_steps),
        })
    }

    /// A ramp taking `rise_ms` from zero to full scale and `fall_ms` back, for a control loop
    /// stepping at `step_hz`. Durations are rounded up to whole steps, at least one. Error
    /// `InvalidRamp` if `step_hz` is zero.
    pub const fn from_durations(
        rise_ms: u32,
        fall_ms: u32,
        step_hz: u32,
    ) -> Result<Self, DriveError> {
        if step_hz == 0 {
            return Err(DriveError::InvalidRamp);
        }
        Self::new(steps_for(rise_ms, step_hz), steps_for(fall_ms, step_hz))
    }

    /// Advances one control step towards `target`, never above `ceiling`, and returns the
    /// amplitude to apply. If the ceiling has dropped below the present amplitude, the
    /// amplitude drops to it in this step (a rating is never exceeded to make a ramp smooth).
    pub fn step(&mut self, target: Amplitude, ceiling: Amplitude) -> Amplitude {
        let goal = target.min(ceiling).bits();
        let mut now = self.now.min(ceiling).bits();
        if now < goal {
            now = now.saturating_add(self.rise_per_step).min(goal);
        } else {
            now = now.saturating_sub(self.fall_per_step).max(goal);
        }
        // `now` lies between two valid amplitudes, so it is one too.
        self.now = match Amplitude::from_bits(now) {
            Ok(amplitude) => amplitude,
            Err(_) => Amplitude::ZERO,
        };
        self.now
    }

    /// Drops the amplitude to zero at once (a fault: no ramp-down).
    pub fn stop(&mut self) {
        self.now = Amplitude::ZERO;
    }

    /// The amplitude applied after the last step.
    pub const fn now(&self) -> Amplitude {
        self.now
    }
}

/// `ms` milliseconds in control steps at `step_hz`, rounded up, clamped to 1..=`u32::MAX`.
const fn steps_for(ms: u32, step_hz: u32) -> u32 {
    let steps = (ms as u64 * step_hz as u64).div_ceil(1000);
    if steps == 0 {
        1
    } else if steps > u32::MAX as u64 {
        u32::MAX
    } else {
        steps as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ratio(n: u32, d: u32) -> Amplitude {
        Amplitude::from_ratio(n, d).unwrap()
    }

    #[test]
    fn soft_start_reaches_the_target_in_the_set_number_of_steps_without_overshoot() {
        let mut ramp = AmplitudeRamp::new(100, 50).unwrap();
        let target = ratio(1, 2);
        let mut previous = ramp.now();
        let mut steps = 0;
        while ramp.now() != target {
            let now = ramp.step(target, Amplitude::FULL);
            assert!(now > previous && now <= target);
            previous = now;
            steps += 1;
        }
        assert_eq!(steps, 50); // half of full scale at 1/100 per step
        assert_eq!(ramp.step(target, Amplitude::FULL), target); // and it stays
    }

    #[test]
    fn ramp_down_is_rate_limited_and_stop_is_not() {
        let mut ramp = AmplitudeRamp::new(1, 50).unwrap();
        assert_eq!(ramp.step(Amplitude::FULL, Amplitude::FULL), Amplitude::FULL);
        let mut steps = 0;
        while ramp.now() != Amplitude::ZERO {
            let before = ramp.now();
            let now = ramp.step(Amplitude::ZERO, Amplitude::FULL);
            assert!(before.bits() - now.bits() <= (1 << 31) / 50 + 1);
            steps += 1;
        }
        assert_eq!(steps, 50);
        ramp.step(Amplitude::FULL, Amplitude::FULL);
        ramp.stop();
        assert_eq!(ramp.now(), Amplitude::ZERO);
    }

    #[test]
    fn a_falling_ceiling_applies_at_once_and_a_target_above_it_is_clipped() {
        let mut ramp = AmplitudeRamp::new(1, 1000).unwrap();
        assert_eq!(ramp.step(Amplitude::FULL, Amplitude::FULL), Amplitude::FULL);
        let ceiling = ratio(3, 10);
        assert_eq!(ramp.step(Amplitude::FULL, ceiling), ceiling);
        assert_eq!(ramp.step(Amplitude::FULL, ceiling), ceiling);
    }

    #[test]
    fn durations_convert_to_steps() {
        // 100 ms at 1 kHz: 100 steps.
        let ramp = AmplitudeRamp::from_durations(100, 20, 1000).unwrap();
        assert_eq!(ramp, AmplitudeRamp::new(100, 20).unwrap());
        // Zero duration is one step; huge durations saturate instead of overflowing.
        assert_eq!(
            AmplitudeRamp::from_durations(0, u32::MAX, u32::MAX).unwrap(),
            AmplitudeRamp::new(1, u32::MAX).unwrap()
        );
        assert_eq!(
            AmplitudeRamp::from_durations(1, 1, 0),
            Err(DriveError::InvalidRamp)
        );
        assert_eq!(AmplitudeRamp::new(0, 1), Err(DriveError::InvalidRamp));
        assert_eq!(AmplitudeRamp::new(1, 0), Err(DriveError::InvalidRamp));
    }

    #[test]
    fn the_slowest_ramp_still_moves() {
        let mut ramp = AmplitudeRamp::new(u32::MAX, u32::MAX).unwrap();
        assert_eq!(ramp.step(Amplitude::FULL, Amplitude::FULL).bits(), 1);
    }
}
