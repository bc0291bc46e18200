//! The cube model (seed 000 eqs 9, 12-15; physics-notes §4) in float forms, for the default
//! slip window (surfaces apart) and an in-phase u, generic over the float type and the maths
//! library ([`super::real`]).
//!
//! Same formulation as the fixed point (`crate::model::cube`): every contact term is a
//! constant times e^(-lambda d / R_q), so d / R_q = (ln K_F - ln F_n) / lambda, and
//! F'/F = W0 + a (u/delta)_max W1 with W0 = `<G>`, W1 = `<G cos theta>`,
//! G = e^(-a K c) (1 + a Y c)^-3, c = cos theta, K = 2 lambda V / R_q, Y = V / d, and
//! (u/delta)_max = U E* F_n / (mu p_eff^2 d^3), V = B cos(pi x/L), U = A sin(pi x/L). The
//! contact constants (ln K_F, p_eff, E*) come from the fixed model's scene-load `f64` code
//! ([`crate::model::contact::ContactConstants`]): elastic and elastic-plastic differ in those
//! constants only, so "no plastic terms" saves nothing per evaluation in this formulation.

use super::gauss::{HalfRule, MAX_POINTS, half_rule};
use super::real::{Maths, Real};
use crate::model::ModelError;
use crate::model::contact::{ContactConstants, ContactKind, ContactParams, EStarRule};

/// Scene inputs of the float cube model (SI, f64).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloatCubeParams {
    /// Materials and surface.
    pub contact: ContactParams,
    /// Elastic or elastic-plastic contact.
    pub contact_kind: ContactKind,
    /// Friction coefficient mu (> 0).
    pub friction_coefficient: f64,
    /// Full-scale longitudinal amplitude A, m (>= 0).
    pub longitudinal_amplitude: f64,
    /// Full-scale vertical amplitude B, m (>= 0).
    pub vertical_amplitude: f64,
    /// Contact position from the horn centre x, m, |x| <= L/2.
    pub position: f64,
    /// Horn length L, m (> 0).
    pub horn_length: f64,
    /// Quadrature points N, 1..=64.
    pub points: usize,
}

/// The cube model of one scene in a float form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloatCube<T> {
    ln_force_constant: T,
    inv_lambda: T,
    /// ln(p_eff A_n): the largest load (A_r = A_n).
    ln_full_area_load: T,
    /// V / R_q at full scale.
    lift_rq: T,
    /// K = 2 lambda V / R_q at full scale.
    decay: T,
    /// ln |U E* / (mu p_eff^2 R_q^3)|, `None` at the node (u = 0).
    ln_u_prefactor: Option<T>,
    u_negative: bool,
    cos: [T; MAX_POINTS / 2],
    weight: [T; MAX_POINTS / 2],
    len: usize,
}

fn check(input: &'static str, value: f64, strictly_positive: bool) -> Result<f64, ModelError> {
    if !value.is_finite() {
        return Err(ModelError::NonFinite { input });
    }
    let ok = if strictly_positive {
        value > 0.0
    } else {
        value >= 0.0
    };
    if ok {
        Ok(value)
    } else {
        Err(ModelError::OutOfDomain {
            input,
            reason: if strictly_positive {
                "must be > 0"
            } else {
                "must be >= 0"
            },
        })
    }
}

impl<T: Real> FloatCube<T> {
    /// The model (f64, scene load). Errors: invalid inputs, N outside 1..=64, and the contact
    /// constants' own validation.
    pub fn new(params: &FloatCubeParams) -> Result<Self, ModelError> {
        let mu = check("mu", params.friction_coefficient, true)?;
        let a = check("A", params.longitudinal_amplitude, false)?;
        let b = check("B", params.vertical_amplitude, false)?;
        let length = check("L", params.horn_length, true)?;
        let x = params.position;
        if !x.is_finite() {
            return Err(ModelError::NonFinite { input: "x" });
        }
        if x.abs() > 0.5 * length {
            return Err(ModelError::OutOfDomain {
                input: "x",
                reason: "|x| must be <= L/2",
            });
        }
        let rule: HalfRule = half_rule(params.points).ok_or(ModelError::OutOfDomain {
            input: "quadrature_points",
            reason: "must be 1..=64",
        })?;
        let constants =
            ContactConstants::new(&params.contact, EStarRule::Seed000, params.contact_kind)?;
        let s = constants.scene();
        let shape = core::f64::consts::PI * x / length;
        let lift_rq = b * libm::cos(shape) / s.roughness_rq;
        let u_amplitude = a * libm::sin(shape);
        let ln_u_prefactor = (u_amplitude != 0.0).then(|| {
            T::of(
                libm::log(u_amplitude.abs()) + libm::log(s.e_star)
                    - libm::log(mu)
                    - 2.0 * libm::log(s.mean_pressure)
                    - 3.0 * libm::log(s.roughness_rq),
            )
        });
        let mut cos = [T::ZERO; MAX_POINTS / 2];
        let mut weight = [T::ZERO; MAX_POINTS / 2];
        for i in 0..rule.len {
            cos[i] = T::of(rule.cos[i]);
            weight[i] = T::of(rule.weight[i]);
        }
        Ok(Self {
            ln_force_constant: T::of(s.ln_force_constant),
            inv_lambda: T::of(1.0 / s.distribution_lambda),
            ln_full_area_load: T::of(s.ln_full_area_load),
            lift_rq: T::of(lift_rq),
            decay: T::of(2.0 * s.distribution_lambda * lift_rq),
            ln_u_prefactor,
            u_negative: u_amplitude < 0.0,
            cos,
            weight,
            len: rule.len,
        })
    }

    /// F'/F at load `load_n` (N, > 0) and `amplitude` (fraction of full scale, [0, 1]).
    /// Errors: F_n <= 0, A_r > A_n, d <= 0, amplitude outside [0, 1].
    pub fn ratio<M: Maths<T>>(&self, load_n: T, amplitude: T) -> Result<T, ModelError> {
        if !(amplitude >= T::ZERO && amplitude <= T::ONE) {
            return Err(ModelError::OutOfDomain {
                input: "amplitude",
                reason: "must be in [0, 1] of full scale",
            });
        }
        if !load_n.is_positive() {
            return Err(ModelError::OutOfDomain {
                input: "F_n",
                reason: "must be > 0",
            });
        }
        let ln_load = M::ln(load_n);
        if ln_load > self.ln_full_area_load {
            return Err(ModelError::OutOfDomain {
                input: "F_n",
                reason: "above p_eff A_n: the real contact area would exceed the nominal area",
            });
        }
        let separation_rq = (self.ln_force_constant - ln_load) * self.inv_lambda;
        if !separation_rq.is_positive() {
            return Err(ModelError::OutOfDomain {
                input: "F_n",
                reason: "at or above K_F: the cube height d would be <= 0",
            });
        }
        if amplitude == T::ZERO {
            return Ok(T::ONE); // G = 1 at every node, exactly (the weights' sum may round)
        }
        let decay = amplitude * self.decay;
        let lift = amplitude * self.lift_rq / separation_rq;
        let with_u = self.ln_u_prefactor.is_some() && amplitude > T::ZERO;
        let (mut mean, mut u_mean) = (T::ZERO, T::ZERO);
        for i in 0..self.len {
            let c = self.cos[i];
            let z = T::ONE + lift * c;
            let g = M::exp(-decay * c) / (z * z * z);
            let wg = self.weight[i] * g;
            mean = mean + wg;
            if with_u {
                u_mean = u_mean + wg * c;
            }
        }
        let Some(prefactor) = self.ln_u_prefactor.filter(|_| with_u) else {
            return Ok(mean);
        };
        let u_over_delta = M::exp(prefactor + ln_load - T::of(3.0) * M::ln(separation_rq));
        let term = amplitude * u_over_delta * u_mean;
        Ok(if self.u_negative {
            mean - term
        } else {
            mean + term
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variant::real::{Libm, Micromath};

    fn params(kind: ContactKind, points: usize, position: f64) -> FloatCubeParams {
        FloatCubeParams {
            contact: ContactParams::SEED_000_TABLE_2_AL_ON_SS,
            contact_kind: kind,
            friction_coefficient: 0.54,
            longitudinal_amplitude: 11.46e-6,
            vertical_amplitude: 1.1e-6,
            position,
            horn_length: 0.127,
            points,
        }
    }

    #[test]
    fn matches_the_papers_reading_at_the_node() {
        // Values of the host's f64 reference (adaptive quadrature) at 40 N and full amplitude:
        // elastic-plastic 0.480623, elastic 0.492557 (physics-notes §4 reading).
        let ep = FloatCube::<f64>::new(&params(ContactKind::ElasticPlastic, 32, 0.0)).unwrap();
        let el = FloatCube::<f64>::new(&params(ContactKind::Elastic, 32, 0.0)).unwrap();
        let r = ep.ratio::<Libm>(40.0, 1.0).unwrap();
        assert!((r - 0.480_622_553).abs() < 1e-6, "{r}");
        let r = el.ratio::<Libm>(40.0, 1.0).unwrap();
        assert!((r - 0.492_557_153).abs() < 1e-6, "{r}");
        assert_eq!(ep.ratio::<Libm>(40.0, 0.0), Ok(1.0));
        let ep32 = FloatCube::<f32>::new(&params(ContactKind::ElasticPlastic, 16, 0.0)).unwrap();
        let r32 = f64::from(ep32.ratio::<Libm>(240.0, 0.5).unwrap());
        let r64 = ep.ratio::<Libm>(240.0, 0.5).unwrap();
        assert!((r32 - r64).abs() < 1e-5, "{r32} vs {r64}");
        let approx = f64::from(ep32.ratio::<Micromath>(240.0, 0.5).unwrap());
        assert!((approx - r64).abs() < 2e-2, "{approx} vs {r64}");
    }

    #[test]
    fn off_the_node_the_u_term_raises_friction_and_inputs_are_checked() {
        let node = FloatCube::<f64>::new(&params(ContactKind::ElasticPlastic, 16, 0.0)).unwrap();
        let off = FloatCube::<f64>::new(&params(ContactKind::ElasticPlastic, 16, 1e-9)).unwrap();
        let (r0, r1) = (
            node.ratio::<Libm>(40.0, 0.5).unwrap(),
            off.ratio::<Libm>(40.0, 0.5).unwrap(),
        );
        assert!(r1 > r0, "{r1} vs {r0}");
        let below = FloatCube::<f64>::new(&params(ContactKind::ElasticPlastic, 16, -1e-9)).unwrap();
        assert!(below.ratio::<Libm>(40.0, 0.5).unwrap() < r0);
        assert!(node.ratio::<Libm>(0.0, 0.5).is_err());
        assert!(node.ratio::<Libm>(40.0, 1.5).is_err());
        assert!(node.ratio::<Libm>(40.0, f64::NAN).is_err());
        assert!(node.ratio::<Libm>(f64::NAN, 0.5).is_err());
        assert!(node.ratio::<Libm>(f64::INFINITY, 0.5).is_err());
        assert!(node.ratio::<Libm>(1e6, 0.5).is_err());
        assert!(FloatCube::<f32>::new(&params(ContactKind::Elastic, 0, 0.0)).is_err());
        assert!(FloatCube::<f32>::new(&params(ContactKind::Elastic, 16, 0.1)).is_err());
    }
}
