//! The sliding contact of the plant: friction from the plant's own model.
//!
//! `friction = ratio(a) x mu_natural(|v|) x F_n x sgn(v)`: the plant's [`FrictionModel`] gives
//! the ratio F'/F at the vibration amplitude `a`, the plant's spec gives the natural (undriven)
//! coefficient (mu, or seed 002 eq 10's mu(v) for the exponential law), and the friction force
//! opposes sliding, read positive by the tangential cell for positive sliding velocity. The
//! models are symmetric in the sliding direction, so they are evaluated at |v|.
//!
//! A Dahl contact built with [`Contact::in_time`] (the plant's) is not evaluated through the
//! periodic steady state: its state f = F / (mu W) is integrated in time across substeps
//! ([`super::dahl_state`]), and the friction of a substep is mu W times the time average of f
//! over the last vibration period ending with it. The other models (Coulomb, cube,
//! exponential Coulomb) have no state of their own and are evaluated as above at every
//! substep.

use sonolube::fx::{Q1_31, Q8_24, Q16_16};
use sonolube::model::{FrictionModel, ModelError, OperatingPoint};
use sonolube::scene::{ModelKind, ModelSpec};

use super::dahl_state::DahlState;

/// The contact's state at one instant (ground truth).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ContactTruth {
    /// Friction force, N, signed like the sliding velocity; 0 without sliding.
    pub friction_n: f32,
    /// Friction the contact would have without vibration, N, >= 0 (mu_natural F_n).
    pub natural_friction_n: f32,
    /// The model's friction ratio F'/F, normally in [0, 1]; 1 when the model could not be
    /// evaluated or nothing slides.
    pub ratio: f32,
    /// Why the model could not be evaluated, if it could not (the contact then shows its
    /// natural friction).
    pub error: Option<ModelError>,
}

/// The plant's contact: a friction model and the natural-friction law of its spec.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact<M> {
    model: M,
    mu: f32,
    /// (mu_s, alpha_dc in s/m) of the exponential law, `None` for other models.
    exponential: Option<(f32, f32)>,
    /// The Dahl state integrated in time ([`Contact::in_time`] on a Dahl spec).
    dahl: Option<DahlState>,
}

impl<M: FrictionModel> Contact<M> {
    /// The contact of `spec` evaluated by `model` (built from the same spec).
    pub fn new(model: M, spec: &ModelSpec) -> Self {
        let exponential = match (spec.kind, spec.mu_static, spec.decay_s_per_m) {
            (ModelKind::ExpCoulomb, Some(mu_s), Some(decay)) => Some((mu_s as f32, decay as f32)),
            _ => None,
        };
        Self {
            model,
            mu: spec.mu as f32,
            exponential,
            dahl: None,
        }
    }

    /// The plant's contact: as [`Self::new`], and for a Dahl spec the state integrated in time
    /// ([`super::dahl_state`]), starting in steady sliding at `normal_n` (N) and
    /// `velocity_m_per_s` (m/s) without vibration; `full_scale_amplitude_m` is the actuator's
    /// x_a at amplitude 1. Errors: the Dahl spec's values out of their domain (mu, k_t, x_a
    /// <= 0, alpha outside (0, 20]).
    pub fn in_time(
        model: M,
        spec: &ModelSpec,
        full_scale_amplitude_m: f64,
        normal_n: f32,
        velocity_m_per_s: f32,
    ) -> Result<Self, ModelError> {
        let mut contact = Self::new(model, spec);
        if spec.kind == ModelKind::Dahl {
            let stiffness = spec.k_t_n_per_m.ok_or(ModelError::OutOfDomain {
                input: "k_t",
                reason: "a Dahl contact needs its tangential stiffness",
            })?;
            contact.dahl = Some(DahlState::new(
                spec.mu,
                stiffness,
                spec.dahl_alpha.unwrap_or(1.0),
                full_scale_amplitude_m,
                normal_n,
                velocity_m_per_s,
            )?);
        }
        Ok(contact)
    }

    /// The Dahl state integrated in time, if this contact has one.
    pub fn dahl_state(&self) -> Option<&DahlState> {
        self.dahl.as_ref()
    }

    /// The contact over a substep of `dt_s` with the load `normal_n` (N), the sliding velocity
    /// `velocity_m_per_s` (m/s, signed), the vibration amplitude `amplitude` (fraction of full
    /// scale) and its frequency `frequency_hz` held. A contact with a Dahl state steps it
    /// through the substep and reports mu W times the time average of f over the last
    /// vibration period (the ratio is that average times sgn(v), 1 without sliding); the
    /// others are [`Self::evaluate`]d.
    pub fn advance(
        &mut self,
        normal_n: f32,
        velocity_m_per_s: f32,
        amplitude: f32,
        frequency_hz: f32,
        dt_s: f32,
    ) -> ContactTruth {
        let Some(state) = self.dahl.as_mut() else {
            return self.evaluate(normal_n, velocity_m_per_s, amplitude);
        };
        let mean = state.advance(normal_n, velocity_m_per_s, amplitude, frequency_hz, dt_s);
        let natural_friction_n = self.mu * normal_n.max(0.0);
        let ratio = if velocity_m_per_s > 0.0 {
            mean
        } else if velocity_m_per_s < 0.0 {
            -mean
        } else {
            1.0
        };
        ContactTruth {
            // The elastic force is there whether or not the contact slides (F = k_t z).
            friction_n: if natural_friction_n > 0.0 {
                mean * natural_friction_n
            } else {
                0.0
            },
            natural_friction_n,
            ratio,
            error: None,
        }
    }

    /// The friction model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// Natural friction coefficient at sliding speed `speed_m_per_s` (>= 0): mu, or
    /// mu_d + (mu_s - mu_d) exp(-alpha_dc |v|) for the exponential law (seed 002 eq 10).
    pub fn natural_coefficient(&self, speed_m_per_s: f32) -> f32 {
        match self.exponential {
            Some((mu_s, decay)) => {
                self.mu + (mu_s - self.mu) * libm::expf(-decay * libm::fabsf(speed_m_per_s))
            }
            None => self.mu,
        }
    }

    /// The contact at normal load `normal_n` (N), sliding velocity `velocity_m_per_s` (m/s,
    /// signed) and vibration amplitude `amplitude` (fraction of full scale, [0, 1]). Inputs
    /// are converted with saturation to the model's formats (Q16.16 N, Q8.24 m/s, Q1.31).
    pub fn evaluate(&self, normal_n: f32, velocity_m_per_s: f32, amplitude: f32) -> ContactTruth {
        let speed = libm::fabsf(velocity_m_per_s);
        let natural_friction_n = self.natural_coefficient(speed) * normal_n.max(0.0);
        if !(normal_n > 0.0 && speed > 0.0) {
            // No load or no sliding: no kinetic friction force, nothing for the model to say.
            return ContactTruth {
                friction_n: 0.0,
                natural_friction_n,
                ratio: 1.0,
                error: None,
            };
        }
        let point = OperatingPoint {
            normal_force: Q16_16::from_f32_saturating(normal_n).value,
            sliding_velocity: Q8_24::from_f32_saturating(speed).value,
        };
        let amplitude = Q1_31::from_f32_saturating(amplitude.max(0.0)).value;
        let (ratio, error) = match self.model.ratio(&point, amplitude) {
            Ok(ratio) => (ratio.to_f32(), None),
            Err(error) => (1.0, Some(error)),
        };
        let magnitude = ratio * natural_friction_n;
        ContactTruth {
            friction_n: if velocity_m_per_s < 0.0 {
                -magnitude
            } else {
                magnitude
            },
            natural_friction_n,
            ratio,
            error,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::fx::Q2_30;

    /// A stand-in model whose ratio is 1 - amplitude, failing above 100 N: the contact's own
    /// arithmetic is tested here, the real models in `any_model.rs` and `sonolube::model`.
    struct Linear;

    impl FrictionModel for Linear {
        fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
            if point.normal_force > Q16_16::from_int_const(100) {
                return Err(ModelError::OutOfDomain {
                    input: "F_n",
                    reason: "test limit",
                });
            }
            Ok(Q2_30::from_f64_const(1.0 - amplitude.to_f64()))
        }
    }

    const COULOMB: ModelSpec = ModelSpec {
        kind: ModelKind::Coulomb,
        mu: 0.2,
        mu_static: None,
        decay_s_per_m: None,
        k_t_n_per_m: None,
        dahl_alpha: None,
        surface: None,
    };

    #[test]
    fn friction_is_ratio_times_natural_with_the_sign_of_sliding() {
        let contact = Contact::new(Linear, &COULOMB);
        let forward = contact.evaluate(10.0, 0.038, 0.25);
        assert!((forward.natural_friction_n - 2.0).abs() < 1e-6);
        assert!((forward.ratio - 0.75).abs() < 1e-6);
        assert!((forward.friction_n - 1.5).abs() < 1e-6);
        let backward = contact.evaluate(10.0, -0.038, 0.25);
        assert_eq!(backward.friction_n, -forward.friction_n);
        let still = contact.evaluate(10.0, 0.0, 0.25);
        assert_eq!((still.friction_n, still.ratio), (0.0, 1.0));
        let unloaded = contact.evaluate(0.0, 0.038, 0.25);
        assert_eq!(unloaded.friction_n, 0.0);
    }

    #[test]
    fn a_model_error_leaves_the_natural_friction_and_is_reported() {
        let contact = Contact::new(Linear, &COULOMB);
        let truth = contact.evaluate(150.0, 0.01, 0.5);
        assert!(truth.error.is_some());
        assert!((truth.friction_n - 30.0).abs() < 1e-4);
    }

    #[test]
    fn the_exponential_law_sets_the_natural_coefficient() {
        // Seed 002 Table 1: mu_s = 0.42, mu_d = 0.32, alpha_dc = 0.01 s/m.
        let spec = ModelSpec {
            kind: ModelKind::ExpCoulomb,
            mu: 0.32,
            mu_static: Some(0.42),
            decay_s_per_m: Some(0.01),
            ..COULOMB
        };
        let contact = Contact::new(Linear, &spec);
        assert!((contact.natural_coefficient(0.0) - 0.42).abs() < 1e-7);
        // At the table's slip velocity V_s = 0.11 m/s: 0.32 + 0.1 e^-0.0011 = 0.419890.
        assert!((contact.natural_coefficient(0.11) - 0.419_890).abs() < 1e-6);
        assert!((contact.natural_coefficient(-0.11) - 0.419_890).abs() < 1e-6);
        assert!((spec.natural_coefficient(0.11) - 0.419_890).abs() < 1e-6);
        assert_eq!(Contact::new(Linear, &COULOMB).natural_coefficient(5.0), 0.2);
    }
}
