//! The travel of the sliding body along one stretch of the drive v = v_s + v_a cos(theta)
//! (seed 003 eq 3), in closed form and with relative precision at every scale (physics-notes
//! §2): the Dahl relaxation depends on the travel only, and a stiff contact (kappa x_a up to
//! 1e13) needs the tiny travel of the first node after a turning point (T ~ h^2 / 2, h down to
//! 1e-8) to a few digits. Phases are Q4.28 radians; travels are [`Scaled`] values in units of
//! x_a; sin and cos come from one `fx::sin_cos` of h/2 (sin h = 2 sin(h/2) cos(h/2),
//! 1 - cos h = 2 sin^2(h/2)), with series for sin(h/2) and h - sin h at small h.

use crate::fx::{Q, Q2_30, sin_cos};

use super::wide::{self, umul};
use crate::fx::scaled::Scaled;

/// Radians up to 8, 3.7e-9 resolution: stretch lengths and phases within a stretch.
pub(crate) type Q4_28 = Q<28>;

/// pi in Q4.28.
pub(crate) const PI_Q28: i32 = Q4_28::PI.to_bits();

/// Half-turn phase per Q4.28 radian unit, Q.31: 2^32 / (2 pi) / 2^28 / 2 turns, so that
/// `h_bits * HALF_TURN_PER_RAD >> 31` is the `u32` phase of h / 2.
const HALF_TURN_PER_RAD: u32 = 2_734_261_102; // round(16 / (2 pi) 2^30)

/// Travel T(h) of a stretch, in units of x_a, as a closed form of the phase h since its start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Travel {
    /// From a turning point (v = 0): T = sigma (1 - cos h) + zeta (h - sin h) forward, with
    /// -zeta backward (zeta = |v_s| / v_a in [0, 1) (`None` = 0), sigma = sqrt(1 - zeta^2)).
    Turning {
        zeta: Option<Scaled>,
        sigma: Scaled,
        backward: bool,
    },
    /// From the velocity crest theta = 0 (v = v_s + v_a), forward, h <= pi: T = zeta h + sin h.
    Crest { zeta: Option<Scaled> },
    /// From the trough theta = pi (v = v_s - v_a < 0), backward, up to the turning point
    /// (h <= phi <= pi/2): T = sin h - zeta h, evaluated as (1 - zeta) h - (h - sin h) so that
    /// small h keep their precision (`one_minus_zeta` = 1 - zeta > 0).
    Trough { one_minus_zeta: Scaled },
}

/// sin h (Q2.30) for h in [0, 2 pi] (Q4.28 bits), and sin(h/2), cos(h/2) (Q1.31).
pub(crate) fn trig(h: i32) -> (i64, i64, i64) {
    let half_phase = (umul(h as u32, HALF_TURN_PER_RAD) >> 31) as u32;
    let (s, c) = sin_cos(half_phase);
    let (s, c) = (s.to_bits() as i64, c.to_bits() as i64);
    ((s * c + (1 << 30)) >> 31, s, c)
}

/// A positive Q.32 fraction (< 2^32) as a [`Scaled`] (`None` for 0).
fn fraction(x32: u32) -> Option<Scaled> {
    wide::from_q(Q2_30::from_bits(((x32 as u64 + 2) >> 2) as i32))
}

/// `round(a b / 2^32)` for two Q.32 fractions: one `UMULL`.
#[inline(always)]
pub(crate) fn mul32(a: u32, b: u32) -> u32 {
    ((umul(a, b) + (1 << 31)) >> 32) as u32
}

/// T(h) pieces with relative precision down to the smallest node: sin(h/2) (by its series
/// below h = 2^-6, where `fx::sin`'s 1e-9 absolute error would dominate) and h - sin h (by
/// its series below h = 1/2).
struct Pieces {
    half_sin: Option<Scaled>,
    half_cos: Q<31>,
    h_minus_sin: Option<Scaled>,
}

fn pieces(h: i32, hs: Scaled) -> Pieces {
    let (sin_h, s, c) = trig(h);
    let hq = ((h as u32) << 4).min(1 << 31); // h in Q.32 (used below h = 1/2 only)
    let h2 = mul32(hq, hq); // h^2, Q.32
    let half_sin = if h < 1 << 22 {
        // sin(h/2) = (h/2)(1 - h^2/24), relative error h^4/1920 < 4e-11
        const INV_24: u32 = ((1u64 << 32) / 24) as u32;
        fraction((1u32 << 31) - (mul32(h2, INV_24) >> 1)).map(|f| wide::mul(hs, f))
    } else {
        wide::from_q(Q::<31>::from_bits(s as i32))
    };
    let h_minus_sin = if h < 1 << 27 {
        // h^3/6 (1 - h^2/20 (1 - h^2/42 (1 - h^2/72))): the next term is below 1e-11. Each
        // bracket 1 - r is held as r (Q.32, small) so that it fits a u32.
        const INV_20: u32 = ((1u64 << 32) / 20) as u32;
        const INV_42: u32 = ((1u64 << 32) / 42) as u32;
        const INV_72: u32 = ((1u64 << 32) / 72) as u32;
        const INV_6: u32 = ((1u64 << 32) / 6) as u32;
        let mut rest = mul32(h2, INV_72);
        for inv in [INV_42, INV_20] {
            let step = mul32(h2, inv);
            rest = step - mul32(step, rest);
        }
        fraction(INV_6 - mul32(INV_6, rest)).map(|t| wide::mul(wide::mul(wide::mul(hs, hs), hs), t))
    } else {
        let rest = h as i64 - ((sin_h + 2) >> 2); // Q4.28, >= 0.02
        wide::from_q(Q4_28::from_bits(rest.clamp(0, i32::MAX as i64) as i32))
    };
    Pieces {
        half_sin,
        half_cos: Q::<31>::from_bits(c as i32),
        h_minus_sin,
    }
}

impl Travel {
    /// T(h) (`None` = 0), for h in [0, 2 pi] (Q4.28 bits), with about 1e-8 relative precision.
    pub(crate) fn at(&self, h: i32) -> Option<Scaled> {
        let hs = wide::from_q(Q4_28::from_bits(h))?;
        let p = pieces(h, hs);
        match *self {
            Self::Turning {
                zeta,
                sigma,
                backward,
            } => {
                // sigma (1 - cos h) = 2 sigma sin^2(h/2)
                let bend = p.half_sin.map(|s| {
                    let b = wide::mul(wide::mul(sigma, s), s);
                    Scaled {
                        exp2: b.exp2.saturating_add(1),
                        ..b
                    }
                });
                let slide = zeta.and_then(|z| p.h_minus_sin.map(|d| wide::mul(z, d)));
                match (bend, slide, backward) {
                    (Some(b), Some(s), false) => Some(wide::add(b, s)),
                    (Some(b), Some(s), true) => wide::sub(b, s),
                    (bend, None, _) => bend,
                    (None, Some(s), false) => Some(s),
                    (None, Some(_), true) => None,
                }
            }
            Self::Trough { one_minus_zeta } => {
                let lead = wide::mul(one_minus_zeta, hs);
                match p.h_minus_sin {
                    Some(bend) => wide::sub(lead, bend),
                    None => Some(lead),
                }
            }
            Self::Crest { zeta } => {
                // sin h = 2 sin(h/2) cos(h/2), h <= pi
                let sin_h = p.half_sin.and_then(|s| {
                    wide::from_q(p.half_cos).map(|c| {
                        let x = wide::mul(s, c);
                        Scaled {
                            exp2: x.exp2.saturating_add(1),
                            ..x
                        }
                    })
                });
                let slide = zeta.map(|z| wide::mul(z, hs));
                match (slide, sin_h) {
                    (Some(a), Some(b)) => Some(wide::add(a, b)),
                    (a, b) => a.or(b),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// T in f64, written without cancellation (1 - cos h = 2 sin^2(h/2), h - sin h by its
    /// series at small h).
    fn h_minus_sin(h: f64) -> f64 {
        if h < 1e-2 {
            h * h * h / 6.0 * (1.0 - h * h / 20.0 * (1.0 - h * h / 42.0))
        } else {
            h - h.sin()
        }
    }

    fn travel_f64(zeta: f64, h: f64, backward: bool) -> f64 {
        let sigma = (1.0 - zeta * zeta).sqrt();
        let slide = zeta * h_minus_sin(h);
        2.0 * sigma * (h / 2.0).sin().powi(2) + if backward { -slide } else { slide }
    }

    /// T(h) keeps its relative precision from the first node of a fine grid (h ~ 1e-8) to a
    /// whole stretch, in both directions and from the crest and trough.
    #[test]
    fn travel_is_relatively_precise_at_every_scale() {
        let mut worst: f64 = 0.0;
        for zeta in [0.0, 0.3, 0.9, 0.9999] {
            let z = Q2_30::from_f64(zeta).unwrap();
            let (zq, sigma) = (z.to_f64(), (1.0 - z.to_f64().powi(2)).sqrt());
            let scaled_zeta = wide::from_q(z);
            let sigma_s = crate::model::scaled_from_f64(sigma, "sigma").unwrap();
            let phi = zq.acos();
            for bits in [
                3i32,
                100,
                5_000,
                1 << 20,
                1 << 25,
                1 << 28,
                3 << 28,
                6 << 28,
            ] {
                let h = Q4_28::from_bits(bits).to_f64();
                for backward in [false, true] {
                    if backward && h > 2.0 * phi {
                        continue;
                    }
                    let travel = Travel::Turning {
                        zeta: scaled_zeta,
                        sigma: sigma_s,
                        backward,
                    };
                    let want = travel_f64(zq, h, backward);
                    let got = travel.at(bits).map_or(0.0, Scaled::to_f64);
                    if want > 1e-300 {
                        worst = worst.max((got / want - 1.0).abs());
                    }
                }
                if h <= std::f64::consts::PI {
                    let crest = Travel::Crest { zeta: scaled_zeta }
                        .at(bits)
                        .unwrap()
                        .to_f64();
                    assert!((crest / (zq * h + h.sin()) - 1.0).abs() < 1e-6);
                }
                if h <= phi {
                    let want = (1.0 - zq) * h - h_minus_sin(h);
                    let one_minus = wide::from_q(Q2_30::ONE.saturating_sub(z).value).unwrap();
                    let trough = Travel::Trough {
                        one_minus_zeta: one_minus,
                    };
                    let got = trough.at(bits);
                    let got = got.map_or(0.0, Scaled::to_f64);
                    assert!((got - want).abs() <= 1e-6 * want + 1e-15, "{zeta} {h}");
                }
            }
        }
        // sigma = 1 - cos: relative 1e-6 everywhere (the cancellation of the backward
        // stretch costs at most a factor 3 near its end).
        assert!(worst < 1e-6, "travel relative error {worst:e}");
    }
}
