//! The periodic cycle of the Dahl model under v_s + v_a cos(theta) (physics-notes §2): the
//! turning-point geometry and the fixed point f_b (f at the start of the forward stretch).
//!
//! The velocity reverses at cos theta = -zeta (|zeta| < 1): forward over 2 theta_1 =
//! pi + 2 asin(zeta), backward over 2 phi = pi - 2 asin(zeta), travelling D_f and D_b (in
//! units of x_a) per period. With the exact relaxation over whole stretches, f_b is the fixed
//! point of a one-dimensional map:
//! - alpha = 1, in closed form: f_b = (b A - B) / (1 - a b), a = e^(-kappa D_f),
//!   b = e^(-kappa D_b), A = 1 - a, B = 1 - b. Where kappa (D_f + D_b) <= 1 it is evaluated
//!   as (b w_f phi(y_f) - w_b phi(y_b)) / phi(y_f + y_b) with phi(y) = (1 - e^-y) / y and
//!   w = D / (D_f + D_b), so that the kappa x_a -> 0 limit (D_f - D_b) / (D_f + D_b) keeps its
//!   precision; above, the denominator 1 - ab >= 1 - 1/e.
//! - any alpha, by 26 bisection steps (3e-8) of d_f(f_b) = d_b(f_a): the drops of the gap over
//!   each stretch, computed with relative precision (1 - e^-lambda by its series), so that the
//!   root stays accurate however small kappa x_a is.

use core::cmp::Ordering;

use crate::fx::{Q, Q2_30, Q3_29};

use super::ModelError;
use super::dahl_quadrature::{SMALL_DECAY_Q30, phi_small};
use super::dahl_relax::{Decay, RelaxLaw};
use super::dahl_travel::{PI_Q28, Travel};
use super::fx_error;
use crate::fx::Scaled;
use crate::fx::wide;

/// Bisection steps of the alpha != 1 fixed point (2^-25 of [-1, 1]).
const FIXED_POINT_STEPS: u32 = 26;

/// Turning-point geometry of a reversing drive, 0 < zeta < 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Geometry {
    /// mu_i(zeta) = (2/pi) asin(zeta), Q2.30.
    pub mu_i: Q2_30,
    /// 2 theta_1 = pi + 2 asin(zeta), the forward stretch, Q4.28 radians.
    pub forward_length: i32,
    /// 2 phi = pi - 2 asin(zeta), the backward stretch, Q4.28 (sum exactly 2 pi).
    pub backward_length: i32,
    /// Travel law of the forward stretch.
    pub forward: Travel,
    /// Travel law of the backward stretch.
    pub backward: Travel,
    /// D_f / x_a: the travel of the whole forward stretch.
    pub forward_travel: Option<Scaled>,
    /// D_b / x_a: the travel of the whole backward stretch (`None` if below 1e-300).
    pub backward_travel: Option<Scaled>,
}

impl Geometry {
    /// Geometry for |zeta| = `zeta` in (0, 1), Q2.30.
    pub(crate) fn new(zeta: Q2_30) -> Result<Self, ModelError> {
        let angle = zeta.asin().map_err(fx_error("zeta"))?; // [0, pi/2]
        let mu_i = angle
            .checked_mul(Q2_30::FRAC_2_PI)
            .map_err(fx_error("mu_i"))?;
        let two_angle = (angle.to_bits() + 1) >> 1; // 2 asin(zeta) in Q4.28
        let sigma = Q2_30::ONE
            .saturating_sub(zeta)
            .value
            .checked_mul(Q2_30::ONE.saturating_add(zeta).value)
            .and_then(Q2_30::sqrt)
            .map_err(fx_error("sigma"))?;
        let sigma = wide::from_q(sigma).ok_or(ModelError::OutOfDomain {
            input: "zeta",
            reason: "must be below 1 for a reversing drive",
        })?;
        let zeta = wide::from_q(zeta);
        let forward = Travel::Turning {
            zeta,
            sigma,
            backward: false,
        };
        let backward = Travel::Turning {
            zeta,
            sigma,
            backward: true,
        };
        let forward_length = PI_Q28 + two_angle;
        let backward_length = PI_Q28 - two_angle;
        Ok(Self {
            mu_i,
            forward_length,
            backward_length,
            forward,
            backward,
            forward_travel: forward.at(forward_length),
            backward_travel: backward.at(backward_length),
        })
    }
}

/// The gap g = 1 - s f in Q3.29 for f in Q2.30 (`forward`: s = +1).
pub(crate) fn gap(f: Q2_30, forward: bool) -> Q3_29 {
    let signed = if forward { f.to_bits() } else { -f.to_bits() } as i64;
    Q3_29::from_bits((((1i64 << 30) - signed + 1) >> 1) as i32)
}

/// f = s (1 - g) in Q2.30 for a gap in Q3.29 (exact).
pub(crate) fn force_ratio(g: Q3_29, forward: bool) -> Q2_30 {
    let value = (1i64 << 30) - ((g.to_bits() as i64) << 1);
    Q2_30::from_bits((if forward { value } else { -value }).clamp(-(1 << 30), 1 << 30) as i32)
}

/// 1 - e^-y (y = `None` is 0) with relative precision at small y, as a [`Scaled`].
fn one_minus_exp(y: Option<Scaled>) -> Option<Scaled> {
    let y = y?;
    let fine = wide::to_q::<30>(y);
    if !fine.saturated && fine.value.to_bits() < SMALL_DECAY_Q30 as i32 {
        Some(wide::mul(y, small_phi(y)))
    } else {
        let decay = if fine.saturated {
            wide::to_q::<24>(y).value.exp_neg().ok()?
        } else {
            fine.value.exp_neg().ok()?
        };
        wide::from_q(Q2_30::ONE.saturating_sub(decay).value)
    }
}

/// (1 - e^-y) / y for y < 2^-5 by its series, as a [`Scaled`] near 1.
fn small_phi(y: Scaled) -> Scaled {
    let y32 = (wide::to_q::<31>(y).value.to_bits() as u64) << 1;
    let phi = phi_small(y32); // Q.32 in (0.98, 1]
    wide::from_q(Q2_30::from_bits(((phi + 2) >> 2) as i32)).unwrap_or(y)
}

/// (1 - e^-y) / y for y in [0, 1] (`None` = 0), Q2.30 in [0.63, 1].
fn phi(y: Option<Scaled>) -> Scaled {
    const ONE: Scaled = Scaled {
        mantissa: Q2_30::ONE,
        exp2: 0,
    };
    match y {
        None => ONE,
        Some(y) => match one_minus_exp(Some(y)) {
            Some(drop) => wide::mul(drop, wide::recip(y)),
            None => ONE,
        },
    }
}

/// Q2.30 bits of a signed ratio num / den (den > 0), clamped to [-1, 1].
fn signed_ratio(num: i64, den: Scaled) -> i32 {
    let magnitude = wide::from_q(Q::<30>::from_bits(
        num.unsigned_abs().min(i32::MAX as u64) as i32
    ))
    .map_or(0, |n| {
        wide::to_q::<30>(wide::mul(n, wide::recip(den)))
            .value
            .to_bits()
            .min(1 << 30)
    });
    if num < 0 { -magnitude } else { magnitude }
}

/// f_b for alpha = 1 in closed form (module docs).
pub(crate) fn exponential_fixed_point(kxa: Scaled, geometry: &Geometry) -> Q2_30 {
    let (d_f, d_b) = (geometry.forward_travel, geometry.backward_travel);
    let y_f = d_f.map(|d| wide::mul(d, kxa));
    let y_b = d_b.map(|d| wide::mul(d, kxa));
    let y_total = match (y_f, y_b) {
        (Some(f), Some(b)) => Some(wide::add(f, b)),
        (one, other) => one.or(other),
    };
    let q30 = |x: Option<Scaled>| x.map_or(0, |x| wide::to_q::<30>(x).value.to_bits() as i64);
    let bits = if y_total.is_none_or(|y| !wide::at_least_one(y)) {
        // (b w_f phi(y_f) - w_b phi(y_b)) / phi(y_f + y_b), w = D / (D_f + D_b).
        let sum = match (d_f, d_b) {
            (Some(f), Some(b)) => wide::add(f, b),
            (Some(f), None) => f,
            _ => return Q2_30::ZERO,
        };
        let inv_sum = wide::recip(sum);
        let b = Q2_30::ONE.saturating_sub(q30_of(one_minus_exp(y_b))).value;
        let forward = d_f.map(|d| wide::mul(wide::mul(d, inv_sum), phi(y_f)));
        let backward = d_b.map(|d| wide::mul(wide::mul(d, inv_sum), phi(y_b)));
        let num = forward.map_or(0, |f| wide::mul_q::<30, 30>(f, b).value.to_bits() as i64)
            - q30(backward);
        signed_ratio(num, phi(y_total))
    } else {
        // ((1 - B) A - B) / (A + (1 - A) B), the denominator 1 - ab >= 1 - 1/e.
        let a = q30(one_minus_exp(y_f));
        let b = q30(one_minus_exp(y_b));
        let one = 1i64 << 30;
        let num = (((one - b) * a + (1 << 29)) >> 30) - b;
        let den = a + (((one - a) * b + (1 << 29)) >> 30);
        match wide::from_q(Q::<30>::from_bits(den.min(i32::MAX as i64) as i32)) {
            Some(den) => signed_ratio(num, den),
            None => 0,
        }
    };
    Q2_30::from_bits(bits)
}

fn q30_of(x: Option<Scaled>) -> Q2_30 {
    x.map_or(Q2_30::ZERO, |x| wide::to_q::<30>(x).value)
}

/// The drop g0 (1 - e^-lambda) of the gap over a whole stretch of travel exponent `y`.
fn drop(law: &RelaxLaw, g0: Q3_29, y: Option<Scaled>) -> Option<Scaled> {
    let factor = law.stretch_factor(g0)?;
    let g0 = wide::from_q(g0)?;
    match law.decay(y, factor) {
        Decay::None => None,
        Decay::Vanished => Some(g0),
        Decay::Exponent(lambda) => one_minus_exp(Some(lambda)).map(|d| wide::mul(g0, d)),
    }
}

/// f_b for any law by bisection of d_f(f_b) - d_b(f_b + d_f(f_b)), decreasing in f_b: the
/// drops keep their relative precision however small kappa x_a is.
pub(crate) fn bisected_fixed_point(law: &RelaxLaw, kxa: Scaled, geometry: &Geometry) -> Q2_30 {
    let travel = |t: Option<Scaled>| t.map(|d| wide::mul(d, kxa));
    let (y_f, y_b) = (
        travel(geometry.forward_travel),
        travel(geometry.backward_travel),
    );
    let (mut low, mut high) = (-(1i32 << 30), 1i32 << 30);
    for _ in 0..FIXED_POINT_STEPS {
        let mid = ((low as i64 + high as i64) / 2) as i32;
        let f_b = Q2_30::from_bits(mid);
        let d_f = drop(law, gap(f_b, true), y_f);
        let f_a = Q2_30::from_bits((mid + q30_of(d_f).to_bits()).min(1 << 30));
        let d_b = drop(law, gap(f_a, false), y_b);
        if wide::cmp(d_f, d_b) == Ordering::Greater {
            low = mid;
        } else {
            high = mid;
        }
    }
    Q2_30::from_bits(((low as i64 + high as i64) / 2) as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of the fixed point against its f64 value and against the bisection
    /// (which also runs for alpha = 1): from kappa x_a = 1e-9 (the soft limit) to 1e9.
    #[test]
    fn fixed_points_agree() {
        for zeta in [0.1, 0.556, 0.95, 0.9999] {
            let geometry = Geometry::new(Q2_30::from_f64(zeta).unwrap()).unwrap();
            let (d_f, d_b) = (
                geometry.forward_travel.unwrap().to_f64(),
                geometry.backward_travel.unwrap().to_f64(),
            );
            for kxa in [1e-9, 1e-4, 0.1, 1.0, 3.0, 100.0, 1e9] {
                let k = crate::model::scaled_from_f64(kxa, "kxa").unwrap();
                let (a, b) = (-(-kxa * d_f).exp_m1(), -(-kxa * d_b).exp_m1());
                let want = if kxa * (d_f + d_b) < 1e-12 {
                    (d_f - d_b) / (d_f + d_b)
                } else {
                    ((1.0 - b) * a - b) / (a + (1.0 - a) * b)
                };
                let closed = exponential_fixed_point(k, &geometry).to_f64();
                let bisected = bisected_fixed_point(&RelaxLaw::Exponential, k, &geometry).to_f64();
                assert!(
                    (closed - want).abs() < 1e-8,
                    "zeta {zeta} kxa {kxa}: {closed} vs {want}"
                );
                assert!(
                    (bisected - want).abs() < 1e-7,
                    "zeta {zeta} kxa {kxa}: {bisected}"
                );
            }
        }
    }

    #[test]
    fn geometry_and_gaps() {
        let g = Geometry::new(Q2_30::from_f64(0.5).unwrap()).unwrap();
        assert_eq!(g.forward_length + g.backward_length, 2 * PI_Q28);
        let theta = std::f64::consts::FRAC_PI_2 + 0.5f64.asin();
        let d_f = 2.0 * ((0.75f64).sqrt() + 0.5 * theta);
        assert!((g.forward_travel.unwrap().to_f64() / d_f - 1.0).abs() < 1e-7);
        assert!((g.mu_i.to_f64() - 1.0 / 3.0).abs() < 3e-9);
        for f in [-1.0, -0.25, 0.0, 0.7, 1.0] {
            let fq = Q2_30::from_f64(f).unwrap();
            for forward in [true, false] {
                let g = gap(fq, forward);
                let s = if forward { 1.0 } else { -1.0 };
                // Q3.29 holds 1 - s f to half an ulp (9.3e-10); back in Q2.30 exactly that.
                assert!((g.to_f64() - (1.0 - s * fq.to_f64())).abs() <= 9.4e-10);
                assert!((force_ratio(g, forward).to_f64() - fq.to_f64()).abs() <= 9.4e-10);
            }
        }
        assert!(Geometry::new(Q2_30::ONE).is_err());
    }
}
