//! Quadrature of the Dahl gap g = 1 - s f over one stretch of drive phase travelled in one
//! direction (physics-notes §2), shared by the periodic steady state and the switch-on window.
//!
//! Drive v = v_s + v_a cos(theta). On a stretch starting at phase theta_a, the travel in units
//! of x_a after a further phase h is T(h) (closed forms in `dahl_travel`), so the gap after h
//! is exactly g0 e^(-kappa x_a T(h)) (alpha = 1) or the power law of [`RelaxLaw`]: node
//! values are the exact relaxation from the stretch start, not a chain of approximate steps.
//!
//! Nodes: n per stretch at h_j = L m(j/n), m(x) = x^2 (1 + x) / 2, clustered quadratically at
//! the start of the stretch, where the velocity vanishes, T grows like h^2 and g falls fastest.
//! Between nodes the decay exponent lambda = ln(g0 / g) is taken linear in h, so an interval
//! contributes (h_(j+1) - h_j) (g_j - g_(j+1)) / (lambda_(j+1) - lambda_j) (the logarithmic
//! mean: exact for an exponential), by its series when the interval's decay is below 2^-5. For
//! a power law with alpha < 1, g^p (p = 1 - alpha) is taken linear in h instead (it is exactly
//! linear in the travel), and where g reaches 0 inside an interval the phase h0 at which it
//! does is found by bisection on the exact travel, the interval contributing
//! (h0 - h_j) g_j p / (1 + p), the limit of the same rule. Each interval's contribution is
//! therefore continuous in the inputs, and so is the steady state: monotone in the amplitude
//! wherever the reference is (issue 15; `host-tests/tests/extremes.rs` checks it). The rule
//! keeps the stiff limit exact (kappa x_a -> infinity: every integral -> 0) and converges as
//! 1/n^2. Against the reference the steady-state ratio is within max(1e-3 relative, 3 / N^2
//! absolute) over zeta in [1e-3, 0.999], k_t from 1e3 to 1e10 N/m and alpha in [0.05, 3]:
//! worst absolute error 6.2e-4 at N = 64, 1.4e-4 at N = 128, 3.9e-5 at N = 256, and no break
//! of monotonicity, over 3,000 seeded random points per N and alpha range
//! (`cargo test -p sonolube-cli --test extremes -- --ignored --nocapture dahl_survey`). The
//! floor is absolute because the ratio is mu_i(zeta) minus a difference of two gap integrals
//! of order 1 (over 2 pi): their quadrature error does not shrink with the ratio, so where the
//! ratio is small (zeta near 0) the relative error grows (0.6 % at a ratio of 3.2e-2 for
//! alpha < 1, N = 64); raise N where that matters.

use crate::fx::{Q2_30, Q3_29, Q8_24};

use super::dahl_relax::{Decay, RelaxLaw};
use super::dahl_travel::{Q4_28, Travel, mul32, trig};
use super::wide::{self, umul};
use crate::fx::scaled::Scaled;

/// The node grid of one stretch: n nodes, and 2^32 / n rounded up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Grid {
    nodes: u32,
    inv_nodes: u32,
}

impl Grid {
    /// A grid of `nodes` (2..=2048) nodes per stretch (one division, at scene load).
    pub(crate) fn new(nodes: u32) -> Self {
        let nodes = nodes.clamp(2, 2048);
        Self {
            nodes,
            inv_nodes: (1u64 << 32).div_ceil(nodes as u64) as u32,
        }
    }

    /// Node j of a stretch of length `length` (Q4.28): `length` m(j / n); exact at j = n.
    fn node(&self, j: u32, length: i32) -> i32 {
        if j >= self.nodes {
            return length;
        }
        let x = j.wrapping_mul(self.inv_nodes); // j/n in Q.32: < 2^32 for j < n <= 2048
        let x2 = (umul(x, x) >> 32) as u32;
        let m = (x2 >> 1) + (umul(x2, x) >> 33) as u32; // x^2 (1 + x) / 2, Q.32
        (umul(length as u32, m) >> 32) as i32
    }
}

/// How the decay exponent of a stretch is formed at a node.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Exponent {
    /// lambda from the travel T(h) and kappa x_a (any law).
    Travel {
        travel: Travel,
        stiffness_amplitude: Scaled,
    },
    /// Non-reversing drive from the crest, alpha = 1: lambda = R h + (kappa x_a) sin h, with
    /// R = kappa |v_s| / omega (`None` for no vibration: kappa x_a = 0); from the trough
    /// (`trough`), lambda = R h - (kappa x_a) sin h.
    Sliding {
        rate: Scaled,
        stiffness_amplitude: Option<Scaled>,
        trough: bool,
    },
}

/// Result of one stretch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct StretchOutcome {
    /// Integral of g over the stretch's phase, Q.57 in an i64 (<= 2 L).
    pub gap_integral: i64,
    /// g at the end of the stretch, Q3.29.
    pub end_gap: Q3_29,
}

/// Decay state at a node: lambda in Q.30 (i64, capped) or g vanished (alpha < 1).
#[derive(Debug, Clone, Copy)]
struct Node {
    h: i32,
    travel: Option<Scaled>,
    lambda: i64,
    gap: Q3_29,
    vanished: bool,
}

/// Integrates g over a stretch of `length` (Q4.28 radians, <= 2 pi) from the gap `g0`
/// (Q3.29 in [0, 2]) on `grid`, with the decay exponent `exponent` and the law `law`.
/// Cost per node: one `sin_cos`, one `exp_neg`, a reciprocal and about fifteen wide products,
/// about 750 instructions on the Cortex-M4 (measured; the power law adds a `ln` and an `exp`).
/// The loop stops at the first node where g has vanished: stiff contacts cost a few nodes.
pub(crate) fn integrate_stretch(
    exponent: &Exponent,
    length: i32,
    g0: Q3_29,
    law: &RelaxLaw,
    grid: &Grid,
) -> StretchOutcome {
    let Some(factor) = law.stretch_factor(g0) else {
        return StretchOutcome {
            gap_integral: 0,
            end_gap: Q3_29::ZERO,
        };
    };
    // alpha < 1: the travel at which g reaches 0, T_zero = 1 / (p kappa x_a g0^-p).
    let (vanish_travel, clamp_share) = match (*law, exponent) {
        (
            RelaxLaw::Power {
                p,
                abs_p,
                clamp_share,
                ..
            },
            Exponent::Travel {
                stiffness_amplitude,
                ..
            },
        ) if p.is_positive() => {
            let rate = wide::mul(wide::mul(abs_p, *stiffness_amplitude), factor);
            (Some(wide::recip(rate)), clamp_share)
        }
        _ => (None, Q2_30::ZERO),
    };
    let mut previous = Node {
        h: 0,
        travel: None,
        lambda: 0,
        gap: g0,
        vanished: false,
    };
    let mut integral: i64 = 0;
    for j in 1..=grid.nodes {
        let node = node_at(grid.node(j, length), exponent, g0, law, factor);
        let width = (node.h - previous.h) as i64; // Q4.28
        let mean = if node.vanished {
            if vanish_travel.is_some() {
                // Where g reaches 0 inside the interval: found on the exact travel (near a
                // turning point the travel is far from linear in h, so a fraction of travel is
                // not a fraction of h).
                integral += vanishing_integral(&previous, &node, exponent, g0, law, factor);
                previous = node;
                break;
            }
            vanishing_mean(&previous, &node, vanish_travel, clamp_share)
        } else {
            interval_mean(&previous, &node, law)
        };
        integral += width * mean.to_bits() as i64; // Q.57
        previous = node;
        if node.gap == Q3_29::ZERO {
            break; // g never recovers within a stretch: the rest contributes nothing
        }
    }
    StretchOutcome {
        gap_integral: integral,
        end_gap: previous.gap,
    }
}

/// Bisection steps locating that phase: the intervals are below 2^31 Q4.28 ulps wide, so 31
/// halvings reach one ulp (3.7e-9 rad).
const VANISHING_BISECTIONS: u32 = 31;

/// Integral (Q.57) of g from node `a` (g > 0) to the phase h0 in (a.h, b.h] where a power law
/// with alpha < 1 makes it vanish (`b` vanished): h0 by bisection on the exact travel, and
/// g^p taken linear in h up to it (the rule of [`interval_mean`]), so (h0 - h_a) g_a p / (1 + p).
/// As h0 approaches a node from either side this equals the interval rule's limit, so the
/// integral moves continuously with the inputs (issue 15: the previous rule took a fraction of
/// travel for a fraction of phase, and the ratio jumped as the vanishing point crossed a node).
fn vanishing_integral(
    a: &Node,
    b: &Node,
    exponent: &Exponent,
    g0: Q3_29,
    law: &RelaxLaw,
    factor: Scaled,
) -> i64 {
    let (mut low, mut high) = (a.h, b.h); // g(low) > 0, g(high) = 0
    for _ in 0..VANISHING_BISECTIONS {
        if high - low <= 1 {
            break;
        }
        let mid = low + (high - low) / 2;
        if node_at(mid, exponent, g0, law, factor).vanished {
            high = mid;
        } else {
            low = mid;
        }
    }
    let share = match *law {
        RelaxLaw::Power { clamp_share, .. } => clamp_share,
        RelaxLaw::Exponential => Q2_30::ZERO,
    };
    let mean: Q3_29 = a.gap.saturating_mul_to(share).value;
    (high - a.h) as i64 * mean.to_bits() as i64
}

/// g at phase `h` of a stretch from the gap `g0` (with its [`RelaxLaw::stretch_factor`]).
fn node_at(h: i32, exponent: &Exponent, g0: Q3_29, law: &RelaxLaw, factor: Scaled) -> Node {
    {
        let (travel, decay) = match *exponent {
            Exponent::Travel {
                travel,
                stiffness_amplitude,
            } => {
                let t = travel.at(h);
                let y = t.map(|t| wide::mul(t, stiffness_amplitude));
                (t, law.decay(y, factor))
            }
            Exponent::Sliding {
                rate,
                stiffness_amplitude,
                trough,
            } => {
                let (sin_h, _, _) = trig(h);
                let sin_h = if trough { -sin_h } else { sin_h };
                let slide = wide::mul_q_q30(rate, Q4_28::from_bits(h));
                let wobble = stiffness_amplitude
                    .map_or(0, |k| wide::mul_q_q30(k, Q2_30::from_bits(sin_h as i32)));
                let lambda = (slide + wobble).max(0);
                (
                    None,
                    wide::from_q30(lambda).map_or(Decay::None, Decay::Exponent),
                )
            }
        };
        match decay {
            Decay::Vanished => Node {
                h,
                travel,
                lambda: wide::Q30_CAP,
                gap: Q3_29::ZERO,
                vanished: true,
            },
            Decay::None => Node {
                h,
                travel,
                lambda: 0,
                gap: g0,
                vanished: false,
            },
            Decay::Exponent(l) => {
                let lambda = wide::mul_q_q30(l, Q2_30::ONE);
                Node {
                    h,
                    travel,
                    lambda,
                    gap: decayed(g0, lambda),
                    vanished: false,
                }
            }
        }
    }
}

/// Decays below 2^-5 (in Q.30) use the series of [`phi_small`].
pub(crate) const SMALL_DECAY_Q30: i64 = 1 << 25;

/// g0 e^-lambda for lambda >= 0 in Q.30 (capped): `exp_neg` in Q2.30 below 2 (9.3e-10
/// resolution), in Q8.24 below 128, 0 beyond; one `UMULL`. Never fails: g0 <= 2 and
/// e^-lambda <= 1.
fn decayed(g0: Q3_29, lambda: i64) -> Q3_29 {
    let factor = exp_neg_q30(lambda);
    Q3_29::from_bits(((umul(g0.to_bits() as u32, factor) + (1 << 29)) >> 30) as i32)
}

/// e^-y for y >= 0 in Q.30 (capped), as Q.30 bits in [0, 2^30]: `exp_neg` in Q2.30 below 2,
/// in Q8.24 below 128, 0 beyond.
fn exp_neg_q30(y: i64) -> u32 {
    let factor = if y < 1 << 31 {
        Q2_30::from_bits(y.max(0) as i32).exp_neg()
    } else if y < 1 << 37 {
        Q8_24::from_bits((y >> 6) as i32).exp_neg()
    } else {
        Ok(Q2_30::ZERO)
    };
    factor.map_or(0, |f| f.to_bits()) as u32 // y >= 0: never Err
}

/// (1 - e^-y) / y for y >= 0 in Q.30 (capped), as a wide value in (0, 1]: the series of
/// [`phi_small`] below 2^-5, else one `exp_neg` and one reciprocal.
fn phi(y: i64) -> Scaled {
    if y < SMALL_DECAY_Q30 {
        let q30 = ((phi_small((y.max(0) as u64) << 2) + 2) >> 2) as i32;
        return wide::from_q(Q2_30::from_bits(q30)).unwrap_or(Scaled::from_ln(Q8_24::ZERO));
    }
    let rest = (1i64 << 30) - exp_neg_q30(y) as i64; // > 0 for y >= 2^-5
    match (wide::from_q30(rest), wide::from_q30(y)) {
        (Some(rest), Some(y)) => wide::mul(rest, wide::recip(y)),
        _ => Scaled::from_ln(Q8_24::ZERO),
    }
}

/// (1 - e^-x) / x = 1 - x/2 + x^2/6 - x^3/24 + x^4/120 for x in [0, 2^-5] given in Q.32
/// (error x^5/720 < 2e-10), in Q.32 (1.0 as `u64` 2^32): the mean of e^-(x s) over s in
/// [0, 1]. Four `UMULL`s.
pub(crate) fn phi_small(x32: u64) -> u64 {
    const INV: [u32; 4] = [
        ((1u64 << 32) / 2) as u32,
        ((1u64 << 32) / 3) as u32,
        ((1u64 << 32) / 4) as u32,
        ((1u64 << 32) / 5) as u32,
    ];
    let x32 = x32.min(1 << 27) as u32;
    // t = 1 - x inv t, starting from t = 1: the brackets stay in (0.98, 1], held as
    // rest = 1 - t in Q.32 so that they fit a u32; x inv t = x inv - x inv rest.
    let mut rest: u32 = 0;
    for &inv in INV.iter().rev() {
        let step = mul32(x32, inv);
        rest = step - mul32(step, rest);
    }
    (1u64 << 32) - rest as u64
}

/// Mean of g over an interval between two nodes where g > 0.
///
/// Exponential law (and alpha > 1): lambda linear in h, g_a (1 - e^-x) / x, x = lambda_b -
/// lambda_a, by its series below 2^-5. Power law with alpha < 1: g^p linear in h (it is
/// exactly linear in the travel), g_a phi((1 + p) x) / phi(p x), phi(y) = (1 - e^-y) / y: the
/// same rule where the decay is small, and where g has fallen close to 0 at the interval's end
/// it tends to g_a p / (1 + p), the mean of [`vanishing_mean`] (the logarithmic mean tends to 0
/// there instead; issue 15: that made the ratio jump by up to 8e-4 as the point where g
/// vanishes moved across a node).
fn interval_mean(a: &Node, b: &Node, law: &RelaxLaw) -> Q3_29 {
    let x = (b.lambda - a.lambda).max(0); // Q.30
    if let RelaxLaw::Power { p, .. } = *law
        && p.is_positive()
    {
        let p_bits = p.to_bits() as i128; // Q8.24, p in (0, 1)
        let px = ((x as i128 * p_bits) >> 24) as i64;
        let ratio = wide::mul(phi(x.saturating_add(px)), wide::recip(phi(px)));
        return match wide::from_q(a.gap) {
            Some(gap) => wide::to_q::<29>(wide::mul(gap, ratio)).value.min(a.gap),
            None => Q3_29::ZERO,
        };
    }
    if x < SMALL_DECAY_Q30 {
        let phi = Q2_30::from_bits(((phi_small((x as u64) << 2) + 2) >> 2) as i32);
        return a.gap.saturating_mul_to(phi).value; // g <= 2, phi <= 1: never clamped
    }
    let drop = a.gap.saturating_sub(b.gap).value;
    match (wide::from_q(drop), wide::from_q30(x)) {
        (Some(drop), Some(x)) => wide::to_q::<29>(wide::mul(drop, wide::recip(x))).value,
        _ => Q3_29::ZERO,
    }
}

/// Mean of g over an interval where a power law with alpha < 1 reaches g = 0 at the fraction
/// s0 = (T_zero - T_a) / (T_b - T_a): g_a s0 p / (1 + p) (g^p linear in h up to s0).
fn vanishing_mean(a: &Node, b: &Node, vanish_travel: Option<Scaled>, clamp_share: Q2_30) -> Q3_29 {
    let less = |x: Option<Scaled>, y: Option<Scaled>| match (x, y) {
        (Some(x), Some(y)) => wide::sub(x, y),
        (x, None) => x,
        (None, Some(_)) => None,
    };
    let s0 = match (less(vanish_travel, a.travel), less(b.travel, a.travel)) {
        (Some(reach), Some(span)) => wide::to_q::<30>(wide::mul(reach, wide::recip(span)))
            .value
            .min(Q2_30::ONE),
        _ => Q2_30::ZERO,
    };
    let share = s0.saturating_mul(clamp_share).value; // both in [0, 1]
    a.gap.saturating_mul_to(share).value
}

#[cfg(test)]
mod tests {
    use super::*;

    /// e^-y across the three ranges of `exp_neg_q30` and at their joins (y = 2 and 128 in
    /// Q.30): within the resolution of the format each range uses (Q2.30 below 2; Q8.24, 64
    /// units of Q.30, below 128) plus the `exp_neg` error, and 0 beyond.
    #[test]
    fn exp_neg_q30_is_e_to_the_minus_y_on_both_sides_of_each_join() {
        let one = (1u64 << 30) as f64;
        for (y, slack) in [
            (0i64, 1.0),
            (1 << 29, 1.0),
            ((1 << 31) - 1, 1.0),
            (1 << 31, 64.0),
            ((1 << 31) + (1 << 20), 64.0),
            ((1 << 37) - 64, 64.0),
        ] {
            let want = libm::exp(-(y as f64) / one) * one;
            let got = exp_neg_q30(y) as f64;
            assert!((got - want).abs() <= slack + 1.0, "y {y}: {got} vs {want}");
        }
        assert_eq!(exp_neg_q30(1 << 37), 0);
        assert_eq!(exp_neg_q30(i64::MAX), 0);
    }

    #[test]
    fn grid_is_monotone_and_ends_on_the_stretch() {
        for nodes in [2u32, 3, 32, 2048] {
            let grid = Grid::new(nodes);
            let length = Q4_28::PI.to_bits();
            let mut last = 0;
            for j in 1..=nodes {
                let h = grid.node(j, length);
                assert!(h > last || (h == last && h == 0), "n {nodes} j {j}");
                last = h;
                let x = j as f64 / nodes as f64;
                let want = length as f64 * x * x * (1.0 + x) / 2.0;
                assert!((h as f64 - want).abs() <= 2.0 + 1e-6 * want);
            }
            assert_eq!(last, length);
        }
    }

    #[test]
    fn phi_series_and_decay() {
        for x in [0.0f64, 1e-9, 1e-4, 0.01, 1.0 / 32.0] {
            let got = phi_small((x * 4294967296.0) as u64) as f64 / 4294967296.0;
            let want = if x == 0.0 { 1.0 } else { -(-x).exp_m1() / x };
            assert!((got - want).abs() < 2e-9, "{x}: {got} vs {want}");
        }
        let two = Q3_29::from_int(2).unwrap();
        assert_eq!(decayed(two, 0), two);
        assert_eq!(decayed(two, wide::Q30_CAP), Q3_29::ZERO);
        let lambda = (0.7 * 1_073_741_824.0) as i64;
        let got = decayed(two, lambda).to_f64();
        assert!((got - 2.0 * (-0.7f64).exp()).abs() < 4e-9);
        let lambda = (40.5 * 1_073_741_824.0) as i64;
        assert!((decayed(two, lambda).to_f64() - 2.0 * (-40.5f64).exp()).abs() < 4e-9);
    }
}
