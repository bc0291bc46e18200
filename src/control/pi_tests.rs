//! The PI's limits under changing gains (issue 18): a frozen step and a retune both bound the
//! integral by the limit in force *now*, and a property test that retunes gains and limits
//! while the loop runs, against a straightforward f64 model of the documented rules.

use super::pi::{Clamp, Pi, PiGains};
use crate::fx::Q2_30;
use proptest::prelude::*;
use std::vec::Vec;

fn q(x: f64) -> Q2_30 {
    Q2_30::from_f64(x).unwrap()
}

/// `kp`, `ki` (1/s) at T = 100 us, and the integral's bound.
fn gains(kp: f64, ki: f64, limit: f64) -> PiGains {
    PiGains::new(kp, ki, 1e-4, limit).unwrap()
}

/// A PI whose integral sits at +0.5 (ki T = 1, limit 0.5), last error +0.4.
fn wound_up(kp: f64) -> (Pi, PiGains) {
    let g = gains(kp, 10_000.0, 0.5);
    let mut pi = Pi::new();
    for _ in 0..3 {
        let c = pi.candidate(&g, q(0.4));
        pi.commit(&g, c, Clamp::Free);
    }
    assert_eq!(pi.integral(), q(0.5));
    (pi, g)
}

#[test]
fn a_frozen_step_bounds_the_integral_by_a_limit_lowered_since() {
    let (mut pi, _) = wound_up(0.0);
    // The limit drops to 0.2 while the drive sits at its floor: the integral is frozen, and
    // still may not stay above the new limit, nor may the correction built on it.
    let low = gains(0.0, 10_000.0, 0.2);
    let c = pi.candidate(&low, q(0.3));
    assert_eq!(pi.commit(&low, c, Clamp::Upper), q(0.2));
    assert!(pi.frozen());
    assert_eq!(pi.integral(), q(0.2));
    // The same from below, with a proportional part: c = kp e + I.
    let g = gains(0.5, 10_000.0, 0.5);
    let mut pi = Pi::new();
    for _ in 0..3 {
        let c = pi.candidate(&g, q(-0.4));
        pi.commit(&g, c, Clamp::Free);
    }
    assert_eq!(pi.integral(), q(-0.5));
    let low = gains(0.5, 10_000.0, 0.1);
    let c = pi.candidate(&low, q(-0.2));
    let out = pi.commit(&low, c, Clamp::Lower);
    assert!(pi.frozen());
    assert_eq!(pi.integral(), q(-0.1));
    assert!((out.to_f64() - (0.5 * -0.2 - 0.1)).abs() < 2e-9, "{out:?}");
}

#[test]
fn a_retune_to_a_lower_limit_cuts_the_integral_and_the_output() {
    let (pi, old) = wound_up(0.0);
    // Same kp: no bumpless shift; only the limit moves the integral (0.5 -> 0.2).
    let mut p = pi;
    p.retune(&old, &gains(0.0, 10_000.0, 0.2));
    assert_eq!(p.integral(), q(0.2));
    assert_eq!(p.correction(), q(0.2));
    // kp 1 -> 0.5 at e = 0.4 shifts the integral by +0.2 (bumpless), then the new limit 0.3
    // cuts it: the output is 0.5 * 0.4 + 0.3 = 0.5 instead of the 0.9 it was.
    let (pi, old) = wound_up(1.0);
    assert!((pi.correction().to_f64() - 0.9).abs() < 2e-9);
    let mut p = pi;
    p.retune(&old, &gains(0.5, 10_000.0, 0.3));
    assert_eq!(p.integral(), q(0.3));
    assert!((p.correction().to_f64() - 0.5).abs() < 2e-9);
    // A limit that still holds the shifted integral leaves the output where it was.
    let mut p = pi;
    p.retune(&old, &gains(0.5, 10_000.0, 0.8));
    assert!((p.integral().to_f64() - 0.7).abs() < 2e-9);
    assert!((p.correction().to_f64() - 0.9).abs() < 4e-9);
}

/// The PI's rules in f64: the integral is bounded by the limit in force, the output is
/// `sat(sat(kp e) + I)` (Q2.30's range), and a retune shifts the integral by
/// `sat((kp_old - kp_new) e)` before bounding it.
#[derive(Debug, Clone, Copy)]
struct Model {
    integral: f64,
    error: f64,
    correction: f64,
}

const TOP: f64 = 2.0 - 1.0 / (1u64 << 30) as f64;

fn sat(x: f64) -> f64 {
    x.clamp(-2.0, TOP)
}

fn bound(x: f64, limit: f64) -> f64 {
    x.clamp(-limit, limit)
}

impl Model {
    fn output(g: &PiGains, error: f64, integral: f64) -> f64 {
        sat(sat(g.kp().to_f64() * error) + integral)
    }

    fn step(&mut self, g: &PiGains, error: f64, clamp: Clamp) {
        let frozen = match clamp {
            Clamp::Free => false,
            Clamp::Upper => error > 0.0,
            Clamp::Lower => error < 0.0,
        };
        let limit = g.integral_limit().to_f64();
        self.integral = if frozen {
            bound(self.integral, limit)
        } else {
            bound(self.integral + g.ki_step().to_f64() * error, limit)
        };
        self.error = error;
        self.correction = Self::output(g, error, self.integral);
    }

    fn retune(&mut self, old: &PiGains, new: &PiGains) {
        // The shift saturates to Q2.30's range first (then the output is saturated anyway).
        let shift = sat((old.kp().to_f64() - new.kp().to_f64()) * self.error);
        self.integral = bound(sat(self.integral + shift), new.integral_limit().to_f64());
        self.correction = Self::output(new, self.error, self.integral);
    }
}

#[derive(Debug, Clone)]
enum Op {
    Step(i32, u8),
    Retune(f64, f64, f64),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        4 => (any::<i32>(), 0u8..3).prop_map(|(e, c)| Op::Step(e, c)),
        1 => (0.0f64..20.0, 0.0f64..10_000.0, 0.0f64..1.99)
            .prop_map(|(kp, ki, limit)| Op::Retune(kp, ki, limit)),
    ]
}

proptest! {
    /// Steps and retunes in any order: the fixed-point PI follows the f64 model of its rules
    /// (each step rounds once or twice, by at most one unit of Q2.30 each; 1e-6 leaves room
    /// for a few hundred such roundings and is far below any rule's effect), the integral
    /// never leaves the limit in force, and a retune moves the output only when the new limit
    /// cuts the integral.
    #[test]
    fn gains_and_limits_changed_while_running(
        kp in 0.0f64..20.0, ki in 0.0f64..10_000.0, limit in 0.0f64..1.99,
        ops in proptest::collection::vec(op(), 1..300),
    ) {
        let mut g = gains(kp, ki, limit);
        let mut pi = Pi::new();
        let mut model = Model { integral: 0.0, error: 0.0, correction: 0.0 };
        let mut trace: Vec<Op> = Vec::new();
        for op in ops {
            trace.push(op.clone());
            match op {
                Op::Step(bits, clamp) => {
                    let clamp = [Clamp::Free, Clamp::Upper, Clamp::Lower][clamp as usize];
                    let e = Q2_30::from_bits(bits);
                    let c = pi.candidate(&g, e);
                    pi.commit(&g, c, clamp);
                    model.step(&g, e.to_f64(), clamp);
                }
                Op::Retune(kp, ki, limit) => {
                    let new = gains(kp, ki, limit);
                    let before = pi.correction().to_f64();
                    let cut = sat(model.integral
                        + sat((g.kp().to_f64() - new.kp().to_f64()) * model.error))
                        .abs()
                        > new.integral_limit().to_f64();
                    let old_kp = g.kp().to_f64();
                    pi.retune(&g, &new);
                    model.retune(&g, &new);
                    g = new;
                    // Bumpless unless the limit cut the integral or the output saturates.
                    let near_rail = |x: f64| x.abs() >= 2.0 - 1e-6;
                    let saturated = near_rail(old_kp * model.error)
                        || near_rail(new.kp().to_f64() * model.error)
                        || near_rail(before)
                        || near_rail(pi.correction().to_f64());
                    if !cut && !saturated {
                        prop_assert!((pi.correction().to_f64() - before).abs() < 1e-6,
                            "bump {} -> {} after {:?}", before, pi.correction().to_f64(), trace);
                    }
                }
            }
            let limit = g.integral_limit().to_bits() as u32;
            prop_assert!(pi.integral().to_bits().unsigned_abs() <= limit, "{:?}", trace);
            prop_assert!((pi.integral().to_f64() - model.integral).abs() < 1e-6,
                "integral {} vs {} after {:?}", pi.integral().to_f64(), model.integral, trace);
            prop_assert!((pi.correction().to_f64() - model.correction).abs() < 1e-6,
                "correction {} vs {} after {:?}", pi.correction().to_f64(), model.correction, trace);
        }
    }
}

#[test]
fn reset_returns_to_rest() {
    let (mut pi, g) = wound_up(1.0);
    let c = pi.candidate(&g, q(0.3));
    pi.commit(&g, c, Clamp::Upper);
    assert!(pi.frozen() && pi.integral() != Q2_30::ZERO);
    pi.reset();
    assert_eq!(pi, Pi::new());
    assert_eq!(
        (pi.integral(), pi.correction(), pi.frozen()),
        (Q2_30::ZERO, Q2_30::ZERO, false)
    );
    // And the next step starts from nothing: c = kp e + ki T e.
    let c = pi.candidate(&g, q(0.1));
    assert!((pi.commit(&g, c, Clamp::Free).to_f64() - 0.2).abs() < 2e-9);
}
