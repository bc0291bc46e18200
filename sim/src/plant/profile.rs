//! The scene's inputs over time: normal load, sliding velocity, target and injected faults.

use sonolube::protocol::Target;
use sonolube::scene::{Breakpoint, Channel, FaultEvent, FaultKind, Scene, TargetPoint};
use sonolube::scene::{interpolate, target_at};

/// The scenario inputs at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ScenarioInputs {
    /// Normal load, N, >= 0.
    pub normal_load_n: f32,
    /// Sliding velocity, m/s, signed.
    pub sliding_velocity_m_per_s: f32,
    /// The friction target, `None` before the first point.
    pub target: Option<Target>,
}

/// A scene's profiles and fault schedule, evaluated at any time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scenario<'a> {
    normal_load_n: &'a [Breakpoint],
    sliding_velocity_m_per_s: &'a [Breakpoint],
    target: &'a [TargetPoint],
    faults: &'a [FaultEvent],
    control_period_s: f64,
}

impl<'a> Scenario<'a> {
    /// The scenario of `scene`.
    pub fn new(scene: &Scene<'a>) -> Self {
        Self {
            normal_load_n: scene.normal_load_n,
            sliding_velocity_m_per_s: scene.sliding_velocity_m_per_s,
            target: scene.target,
            faults: scene.faults,
            control_period_s: scene.control_period_s(),
        }
    }

    /// Inputs at `t_s` (s from the scene start), interpolated in `f32`; a negative
    /// interpolated load (impossible for a validated scene) reads 0.
    pub fn at(&self, t_s: f32) -> ScenarioInputs {
        ScenarioInputs {
            normal_load_n: interpolate(self.normal_load_n, t_s).max(0.0),
            sliding_velocity_m_per_s: interpolate(self.sliding_velocity_m_per_s, t_s),
            target: target_at(self.target, t_s),
        }
    }

    /// The fault acting on `channel` at the sample of control step `step` (time
    /// `step / control rate`): the first of the scene's faults on that channel whose interval
    /// `[at_s, at_s + duration)` holds the sample. A fault without a duration lasts to the
    /// end, or one control period (exactly one sample) for a spike. Onsets and ends are
    /// placed on the control grid in units of periods, with a 1e-6-period tolerance, so a
    /// fault at a control instant starts at that sample whatever the rounding of its time.
    pub fn fault_at(&self, channel: Channel, step: u32) -> Option<FaultKind> {
        let grid = |t_s: f64| libm::ceil(t_s / self.control_period_s - 1e-6);
        let sample = f64::from(step);
        self.faults
            .iter()
            .filter(|fault| fault.channel == channel)
            .find(|fault| {
                let onset = grid(fault.at_s);
                let end = match (fault.duration_s, fault.kind) {
                    (Some(duration), _) => grid(fault.at_s + duration).max(onset + 1.0),
                    (None, FaultKind::Spike { .. }) => onset + 1.0,
                    (None, _) => f64::INFINITY,
                };
                sample >= onset && sample < end
            })
            .map(|fault| fault.kind)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::scene::{Rail, find};

    #[test]
    fn the_reference_scene_steps_its_target() {
        let scenario = Scenario::new(find("reference").expect("built in"));
        let before = scenario.at(0.004);
        assert_eq!(before.target, Some(Target::Reduction { reduction_mpct: 0 }));
        assert_eq!(before.normal_load_n, 4.155);
        assert_eq!(before.sliding_velocity_m_per_s, 0.038);
        let after = scenario.at(0.005);
        assert_eq!(
            after.target,
            Some(Target::Reduction {
                reduction_mpct: 50_000
            })
        );
    }

    const FAULTS: [FaultEvent; 3] = [
        FaultEvent {
            at_s: 0.01,
            channel: Channel::Tangential,
            kind: FaultKind::Spike { force_n: 1.0 },
            duration_s: None,
        },
        FaultEvent {
            at_s: 0.02,
            channel: Channel::Normal,
            kind: FaultKind::Stuck,
            duration_s: Some(0.005),
        },
        FaultEvent {
            at_s: 0.029_999_999_9,
            channel: Channel::Tangential,
            kind: FaultKind::Disconnected { rail: Rail::Low },
            duration_s: None,
        },
    ];

    #[test]
    fn faults_act_over_their_intervals() {
        let scenario = Scenario {
            normal_load_n: &[],
            sliding_velocity_m_per_s: &[],
            target: &[],
            faults: &FAULTS,
            control_period_s: 1e-4,
        };
        let tangential = |step| scenario.fault_at(Channel::Tangential, step);
        let normal = |step| scenario.fault_at(Channel::Normal, step);
        // A spike without a duration lasts one control period: exactly sample 100.
        assert_eq!(tangential(99), None);
        assert_eq!(tangential(100), Some(FaultKind::Spike { force_n: 1.0 }));
        assert_eq!(tangential(101), None);
        assert_eq!(normal(100), None);
        // A stuck reading for 5 ms: samples 200 to 249.
        assert_eq!(normal(199), None);
        assert_eq!(normal(200), Some(FaultKind::Stuck));
        assert_eq!(normal(249), Some(FaultKind::Stuck));
        assert_eq!(normal(250), None);
        // A disconnection without a duration lasts to the end.
        let rail = Some(FaultKind::Disconnected { rail: Rail::Low });
        assert_eq!(tangential(300), rail);
        assert_eq!(tangential(u32::MAX), rail);
    }
}
