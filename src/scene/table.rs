//! Time tables of a scene and their evaluation, in `f32`.
//!
//! Profiles (normal load, sliding velocity) are piecewise linear between breakpoints and hold
//! their end values outside them. The target table is a list of protocol [`Target`]s, each
//! reached by a step at its time or by a linear ramp from the previous point.
//!
//! Evaluation is in `f32` (the plant's format; one division per call): values are exact at the
//! breakpoints and within a few ulp between them. Times are `f32` seconds, so a 60 s scene is
//! resolved to 4 us; the plant passes `step / rate`, exact at every control step up to 2^24
//! steps.

use super::{Breakpoint, TargetPoint};
use crate::protocol::Target;

/// Value of a piecewise-linear profile at `t_s` (s), `f32`: linear between breakpoints, the
/// first value before the first breakpoint, the last after the last, 0 for an empty table.
pub fn interpolate(points: &[Breakpoint], t_s: f32) -> f32 {
    // First breakpoint strictly after t: the segment is [after - 1, after].
    let after = points.partition_point(|p| p.t_s as f32 <= t_s);
    match (
        after.checked_sub(1).and_then(|i| points.get(i)),
        points.get(after),
    ) {
        (None, None) => 0.0,
        (None, Some(first)) => first.value as f32,
        (Some(last), None) => last.value as f32,
        (Some(a), Some(b)) => {
            let (t_a, t_b) = (a.t_s as f32, b.t_s as f32);
            let (v_a, v_b) = (a.value as f32, b.value as f32);
            v_a + (v_b - v_a) * ((t_s - t_a) / (t_b - t_a))
        }
    }
}

/// The target at `t_s` (s): the last point at or before `t_s`, or on a ramp toward the next
/// point the linear interpolation between the two, rounded to the protocol's resolution (in
/// `f32`: exact for coefficients and reductions, and for forces up to 16.7 kN). `None` before
/// the first point or for an empty table.
pub fn target_at(points: &[TargetPoint], t_s: f32) -> Option<Target> {
    let after = points.partition_point(|p| p.at_s as f32 <= t_s);
    let current = points.get(after.checked_sub(1)?)?;
    let Some(next) = points.get(after).filter(|next| next.ramp) else {
        return Some(current.target);
    };
    let (t_a, t_b) = (current.at_s as f32, next.at_s as f32);
    let from = current.target.scaled_value() as f32;
    let to = next.target.scaled_value() as f32;
    let value = libm::roundf(from + (to - from) * ((t_s - t_a) / (t_b - t_a)));
    // Between two valid values of the kind's field, so the conversion neither wraps nor
    // saturates.
    Target::from_kind(next.target.kind(), value as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOAD: [Breakpoint; 3] = [
        Breakpoint {
            t_s: 0.0,
            value: 40.0,
        },
        Breakpoint {
            t_s: 0.05,
            value: 40.0,
        },
        Breakpoint {
            t_s: 1.05,
            value: 240.0,
        },
    ];

    #[test]
    fn profiles_are_exact_at_breakpoints_and_linear_between() {
        assert_eq!(interpolate(&LOAD, 0.0), 40.0);
        assert_eq!(interpolate(&LOAD, 0.05), 40.0);
        assert_eq!(interpolate(&LOAD, 1.05), 240.0);
        assert_eq!(interpolate(&LOAD, 0.025), 40.0);
        let mid = interpolate(&LOAD, 0.55);
        assert!((mid - 140.0).abs() < 1e-4, "{mid}");
        let quarter = interpolate(&LOAD, 0.3);
        assert!((quarter - 90.0).abs() < 1e-4, "{quarter}");
        // Held outside the table.
        assert_eq!(interpolate(&LOAD, -1.0), 40.0);
        assert_eq!(interpolate(&LOAD, 2.0), 240.0);
        assert_eq!(interpolate(&[], 0.5), 0.0);
    }

    #[test]
    fn a_single_point_is_a_constant() {
        let one = [Breakpoint {
            t_s: 0.0,
            value: -0.038,
        }];
        for t in [0.0, 0.1, 10.0] {
            assert_eq!(interpolate(&one, t), -0.038);
        }
    }

    const TARGET: [TargetPoint; 4] = [
        TargetPoint {
            at_s: 0.0,
            target: Target::Reduction { reduction_mpct: 0 },
            ramp: false,
        },
        TargetPoint {
            at_s: 0.005,
            target: Target::Reduction {
                reduction_mpct: 50_000,
            },
            ramp: false,
        },
        TargetPoint {
            at_s: 0.015,
            target: Target::Reduction {
                reduction_mpct: 30_000,
            },
            ramp: true,
        },
        TargetPoint {
            at_s: 0.02,
            target: Target::Coef { coef_ppm: 300_000 },
            ramp: false,
        },
    ];

    #[test]
    fn targets_step_and_ramp() {
        let reduction = |mpct| {
            Some(Target::Reduction {
                reduction_mpct: mpct,
            })
        };
        assert_eq!(target_at(&TARGET, 0.0), reduction(0));
        assert_eq!(target_at(&TARGET, 0.004_9), reduction(0));
        // The step lands at its time; the ramp toward the next point starts from it.
        assert_eq!(target_at(&TARGET, 0.005), reduction(50_000));
        assert_eq!(target_at(&TARGET, 0.01), reduction(40_000));
        assert_eq!(target_at(&TARGET, 0.0125), reduction(35_000));
        assert_eq!(target_at(&TARGET, 0.015), reduction(30_000));
        assert_eq!(target_at(&TARGET, 0.019), reduction(30_000));
        assert_eq!(
            target_at(&TARGET, 0.02),
            Some(Target::Coef { coef_ppm: 300_000 })
        );
        assert_eq!(
            target_at(&TARGET, 5.0),
            Some(Target::Coef { coef_ppm: 300_000 })
        );
        assert_eq!(target_at(&TARGET, -0.001), None);
        assert_eq!(target_at(&[], 0.0), None);
    }
}
