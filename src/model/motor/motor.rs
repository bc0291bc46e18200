//! Motor-effect model (seed 001 §2, §3.2, Table 1, Figs 2, 4, 5; physics-notes §4, §8) in fixed
//! point: the net tangential force the vibrating horn exerts on a block at position x along its
//! bottom face, averaged over one vibration period.
//!
//! # Physics
//!
//! Horn kinematics (seed 000 eqs 16-17, seed 001 eqs 4-10, `super::horn`), x from the node, the
//! amplitudes scaled by the drive fraction a: u = a A P_u(theta) sin(pi x / L),
//! v = a B cos(theta) cos(pi x / L), theta = 2 pi f t, v > 0 opening the gap. Eqs 16-17 print u
//! and v in phase: the locus is a straight line. Seed 000 §3.1 and seed 001 §2 (Fig. 2) report
//! ellipses (wave reflections in the horn), which the project models as u in quadrature,
//! P_u = sin theta ([`UPhase::Quadrature`], the default here); the in-phase variant is kept.
//!
//! Contact law, three parts:
//! - *normal*: the rough contact of seed 000 eqs 4-8, whose every force term is a constant times
//!   e^(-lambda d / R_q) (physics-notes §3). At ultrasonic frequency the block cannot follow the
//!   horn (its inertia filters 20 kHz), so its mean gap settles where the mean normal force is
//!   the applied load F_n: N(theta) = F_n e^(-k cos theta) / I0(k), k = a lambda B cos(pi x/L) / R_q.
//!   The surfaces press hardest when the horn face comes closest (v < 0) and the asperity load
//!   falls off exponentially as it recedes: contact only while the surfaces press. Without load
//!   (F_n = 0) the surfaces are apart over the whole cycle and no force acts.
//! - *tangential*: Coulomb friction mu N(theta) opposing the relative velocity of the block
//!   (velocity v_b, along +x) with respect to the horn face (du/dt = a A omega sin(pi x/L) P_u').
//! - *average*: the block sees the mean over one period (its inertia again):
//!   F_t = mu F_n phi, phi = < e^(-k cos theta) sgn(du/dt - v_b) > / I0(k), phi in [-1, 1].
//!
//! Consequences (tested here and in host-tests against the f64 reference):
//! - F_t is exactly linear in F_n (phi does not depend on it): seed 001 Fig. 5;
//! - with the quadrature phase and the block held (v_b = 0), phi = -sgn(x) L0(k) / I0(k)
//!   (L0 the modified Struve function): towards the centerline on both sides (seed 001 §2, §3.2);
//! - with the in-phase locus of eqs 16-17 and v_b = 0, phi = 0 (a straight stroke pushes both
//!   ways equally): the ellipse is what makes the motor;
//! - at the node (x = 0) there is no tangential motion: phi = 0 for a held block, and plain
//!   friction -sgn(v_b) for a sliding one; likewise at zero amplitude;
//! - where the horn face is slower than the block (a A omega |sin(pi x/L)| <= |v_b|) the force
//!   is plain friction opposing the sliding: the model's transition region for a sliding block
//!   (docs/models.md compares it with Table 1).
//!
//! # Fixed point
//!
//! Per scene (f64, once): mu (Q2.30), K0 = lambda B / R_q (Q8.24, at most [`MAX_DECAY`]), the
//! face's peak tangential speed A omega (Q8.24 m/s, < 128 m/s), the Gauss-Legendre rule.
//! Per evaluation: k = a K0 cos(pi x/L) and w = a A omega |sin(pi x/L)| (Q8.24), z = sgn(S) v_b / w
//! (Q2.30) when |v_b| < w, the half width theta_0 = acos z (Q2.30 rad, as a turn fraction of 2^32)
//! of the phase interval where du/dt > v_b. The two means of h(theta) = e^(-k (1 + cos theta)),
//! in [e^(-2k), 1] (the factor e^(-k) cancels in the ratio and keeps every term at most 1), over
//! the interval where the face outruns the block (P) and its complement (M) are
//! [`MOTOR_QUADRATURE_POINTS`]-point Gauss-Legendre sums on pieces of at most a quarter turn
//! (Q.30 sums in i64), and phi = sgn(S) (P - M) / (P + M) (Q2.30). F_t = phi mu F_n in Q16.16:
//! `Overflow` when |F_t| >= 32768 N, never a wrap. P + M >= e^(-k) I0(k) >= 0.13 for k <= 8: the
//! division is well conditioned.
//!
//! Cost: one `asin`, and per node one `cos` and one `exp_neg`: 4 or 5 pieces of 12 nodes (none
//! when the block outruns the face). Not yet measured in QEMU (`docs/speed.md` has no row).

use core::f64::consts::PI;

use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16, cos};

use super::contact_constants::{non_negative, positive};
use super::fx_error;
use super::horn::{HornShape, UPhase};
use super::quadrature::legendre_half;

pub use super::motor_regions::{
    ALUMINIUM_HORN_REGIONS, HornRegion, MeasuredRegions, STAINLESS_HORN_REGIONS, classify,
};
use super::{ModelError, Reach};

/// Gauss-Legendre points per piece (a piece spans at most a quarter period).
pub const MOTOR_QUADRATURE_POINTS: usize = 12;

/// Largest accepted contact group K0 = lambda B / R_q: the range over which the rule is checked
/// against the reference (within 1e-6 of mu F_n at 8, `motor_tests` and host-tests). The normal
/// force narrows to a spike of width about 1 / sqrt(K0) around the closest approach as K0
/// grows, which a fixed rule resolves ever worse. Seed 000 Table 1 gives 0.55 (B = 1.1 um,
/// R_q = 6 um, lambda = 3): 15 times below the limit.
pub const MAX_DECAY: f64 = 8.0;

/// Scene inputs of the motor model, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorParams {
    /// Friction coefficient mu, in (0, 2) (0.55 in seed 001 §3.3, 0.54 in seed 000 §4.2).
    pub friction_coefficient: f64,
    /// Full-scale longitudinal amplitude A in m (>= 0; 11.46 um in seed 000 Table 1).
    pub longitudinal_amplitude: f64,
    /// Full-scale vertical amplitude B in m (>= 0; 1.1 um in seed 000 Table 1).
    pub vertical_amplitude: f64,
    /// Horn length L in m (> 0; 127 mm).
    pub horn_length: f64,
    /// Drive frequency f in Hz (> 0; 20 kHz).
    pub frequency: f64,
    /// Asperity height deviation R_q in m (> 0; 6 um in seed 000 Table 2).
    pub roughness_rq: f64,
    /// Exponential height-distribution constant lambda (> 0; 3, seed 000 eq 2).
    pub distribution_lambda: f64,
}

impl MotorParams {
    /// Seed 000 Tables 1-2 (aluminium horn, test 1: A = 11.46 um, B = 1.1 um, 20 kHz, L = 127
    /// mm; stainless block, R_q = 6 um, lambda = 3) with seed 001's mu = 0.55 (its §3.3): the
    /// one definition of the set in the firmware core. The f64 reference keeps its own copy
    /// (`sonolube_host::reference::motor`) so that the two are written independently.
    pub const SEED_001_AL_HORN_SS_BLOCK: Self = Self {
        friction_coefficient: 0.55,
        longitudinal_amplitude: 11.46e-6,
        vertical_amplitude: 1.1e-6,
        horn_length: 0.127,
        frequency: 20e3,
        roughness_rq: 6e-6,
        distribution_lambda: 3.0,
    };
}

/// The motor model of one scene: its constants in fixed point and its quadrature rule.
#[derive(Debug, Clone, PartialEq)]
pub struct MotorScene {
    /// mu, Q2.30 in (0, 2).
    friction_coefficient: Q2_30,
    /// K0 = lambda B / R_q, Q8.24 in [0, MAX_DECAY].
    decay: Q8_24,
    /// A omega in m/s, Q8.24 in [0, 128).
    face_speed: Q8_24,
    u_phase: UPhase,
    horn_length: f64,
    /// Node positions (1 + t_i) / 2 on a piece, Q.32 fractions.
    nodes: [u32; MOTOR_QUADRATURE_POINTS],
    /// Mean weights w_i / 2, Q.30, summing to exactly 2^30.
    weights: [i64; MOTOR_QUADRATURE_POINTS],
}

/// The net tangential force at one operating point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotorForce {
    /// phi = F_t / (mu F_n), Q2.30 in [-1, 1]: the slope of the force in the Coulomb force.
    pub drive_ratio: Q2_30,
    /// F_t = phi mu F_n in N along +x (towards +x positive), Q16.16.
    pub force: Q16_16,
}

/// Result of [`MotorScene::amplitude_for_force`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ForceInversion {
    /// Drive amplitude, Q1.31 fraction of full scale in [0, 1).
    pub amplitude: Q1_31,
    /// The force the model gives at `amplitude`.
    pub force: MotorForce,
    /// Whether the target was reachable.
    pub reach: Reach,
}

/// Where the block is and how it is loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotorPoint {
    /// Mode-shape factors at the block's position.
    pub shape: HornShape,
    /// Normal load F_n in N, Q16.16, >= 0.
    pub normal_force: Q16_16,
    /// Block velocity v_b along +x in m/s, Q8.24.
    pub block_velocity: Q8_24,
}

const ONE_Q30: i64 = 1 << 30;
/// 2 / pi in Q.32: radians (Q2.30) to a turn fraction of 2^32 is a multiplication by 2 / pi.
const TWO_OVER_PI_Q32: u64 = 2_734_261_102;
/// A quarter turn as a phase: the longest piece of the composite rule.
const QUARTER_TURN: u64 = 1 << 30;
const FULL_TURN: u64 = 1 << 32;

/// The motor model of a horn scene's contact with `spec`'s parameters (mu, and R_q and lambda
/// of its rough surface; the controller's spec for the station, the plant's for the simulated
/// plant), with the scene's full-scale amplitude A, the horn's B and L and the drive
/// frequency, the ellipse ([`UPhase::Quadrature`]), and Table 1's measured regions for the
/// horn's material ([`MeasuredRegions::for_horn_modulus`]). `Ok(None)` for a scene without a
/// horn, whose horn does not ask for the regions (`motor_regions`, false for a contact that
/// stays put), without a rough surface, or whose horn Table 1 did not measure. Errors: the model's
/// ([`MotorScene::new`]).
pub fn scene_motor(
    scene: &crate::scene::Scene<'_>,
    spec: &crate::scene::ModelSpec,
) -> Result<Option<(MotorScene, MeasuredRegions)>, ModelError> {
    let (Some(horn), Some(surface)) = (scene.horn, spec.surface) else {
        return Ok(None);
    };
    if !horn.motor_regions {
        return Ok(None);
    }
    let Some(regions) = MeasuredRegions::for_horn_modulus(surface.young_1_pa) else {
        return Ok(None);
    };
    let params = MotorParams {
        friction_coefficient: spec.mu,
        longitudinal_amplitude: scene.actuator.full_scale_amplitude_m,
        vertical_amplitude: horn.vertical_amplitude_m,
        horn_length: horn.length_m,
        frequency: scene.transducer.drive_hz,
        roughness_rq: surface.rq_m,
        distribution_lambda: surface.distribution_lambda,
    };
    Ok(Some((
        MotorScene::new(&params, UPhase::Quadrature)?,
        regions,
    )))
}

impl MotorScene {
    /// Builds the scene constants (f64, once per scene). Errors: non-finite inputs, mu outside
    /// (0, 2), negative amplitudes, L, f, R_q or lambda <= 0, lambda B / R_q > [`MAX_DECAY`],
    /// A 2 pi f >= 128 m/s.
    pub fn new(params: &MotorParams, u_phase: UPhase) -> Result<Self, ModelError> {
        let mu = positive("mu", params.friction_coefficient)?;
        let friction_coefficient = Q2_30::from_f64(mu).map_err(|_| ModelError::OutOfDomain {
            input: "mu",
            reason: "must be below 2",
        })?;
        let a = non_negative("A", params.longitudinal_amplitude)?;
        let b = non_negative("B", params.vertical_amplitude)?;
        let horn_length = positive("L", params.horn_length)?;
        let f = positive("f", params.frequency)?;
        let rq = positive("Rq", params.roughness_rq)?;
        let lambda = positive("lam", params.distribution_lambda)?;
        let decay = lambda * b / rq;
        if decay > MAX_DECAY {
            return Err(ModelError::OutOfDomain {
                input: "B",
                reason: "lambda B / R_q must be at most 8 (the contact spike outruns the rule)",
            });
        }
        let decay = Q8_24::from_f64(decay).map_err(fx_error("lambda B / R_q"))?;
        let face_speed =
            Q8_24::from_f64(a * 2.0 * PI * f).map_err(|_| ModelError::OutOfDomain {
                input: "A",
                reason: "the face speed A 2 pi f must be below 128 m/s",
            })?;
        let mut t = [0.0; MOTOR_QUADRATURE_POINTS];
        let mut w = [0.0; MOTOR_QUADRATURE_POINTS];
        let half = legendre_half(MOTOR_QUADRATURE_POINTS, &mut t, &mut w);
        let mut nodes = [0u32; MOTOR_QUADRATURE_POINTS];
        let mut weights = [0i64; MOTOR_QUADRATURE_POINTS];
        // legendre_half gives the nodes t >= 0 (descending); mirror them for the full rule.
        for i in 0..half {
            let fraction = |node: f64| libm::round(0.5 * (1.0 + node) * FULL_TURN as f64) as u64;
            let weight = libm::round(0.5 * w[i] * ONE_Q30 as f64) as i64;
            let (upper, lower) = (i, MOTOR_QUADRATURE_POINTS - 1 - i);
            nodes[upper] = fraction(t[i]).min(FULL_TURN - 1) as u32;
            nodes[lower] = fraction(-t[i]) as u32;
            weights[upper] = weight;
            weights[lower] = weight;
        }
        // Normalise the rounded weights to sum to exactly 1 (a constant averages to itself).
        let excess: i64 = weights.iter().sum::<i64>() - ONE_Q30;
        weights[0] -= excess;
        Ok(Self {
            friction_coefficient,
            decay,
            face_speed,
            u_phase,
            horn_length,
            nodes,
            weights,
        })
    }

    /// The horn length L in m (for [`HornShape::new`]).
    pub fn horn_length(&self) -> f64 {
        self.horn_length
    }

    /// mu, Q2.30.
    pub fn friction_coefficient(&self) -> Q2_30 {
        self.friction_coefficient
    }

    /// K0 = lambda B / R_q at full amplitude, Q8.24.
    pub fn decay(&self) -> Q8_24 {
        self.decay
    }

    /// Peak tangential face speed at full amplitude A omega (m/s, Q8.24).
    pub fn face_speed(&self) -> Q8_24 {
        self.face_speed
    }

    /// Net tangential force at `point` and drive `amplitude` (Q1.31 fraction of full scale,
    /// [0, 1)). Errors: F_n < 0, a shape with cos(pi x/L) < 0 (|x| > L/2), |F_t| >= 32768 N.
    pub fn force(&self, point: &MotorPoint, amplitude: Q1_31) -> Result<MotorForce, ModelError> {
        let load = point.normal_force.to_bits() as i64;
        if load < 0 {
            return Err(ModelError::OutOfDomain {
                input: "F_n",
                reason: "the normal load must be >= 0",
            });
        }
        let ratio = self.drive_ratio(point, amplitude)?;
        // phi (Q30) mu (Q30) -> Q30, times F_n (Q16) -> Q16, rounded to nearest.
        let slope = (ratio * self.friction_coefficient.to_bits() as i64 + (1 << 29)) >> 30;
        let force = (slope * load + (1 << 29)) >> 30;
        let force = i32::try_from(force).map_err(|_| ModelError::Overflow { quantity: "F_t" })?;
        Ok(MotorForce {
            drive_ratio: Q2_30::from_bits(ratio as i32),
            force: Q16_16::from_bits(force),
        })
    }

    /// The two groups the force depends on at `shape` and `amplitude` (Q1.31, [0, 1)):
    /// k = a K0 cos(pi x/L) in [0, 8] and the peak face speed w = a A omega |sin(pi x/L)| in
    /// m/s, [0, 128), both Q8.24, rounded to nearest (a negative amplitude counts as 0).
    pub fn groups(&self, shape: &HornShape, amplitude: Q1_31) -> (Q8_24, Q8_24) {
        let a = amplitude.to_bits().max(0) as i64;
        let scale = |full: Q8_24, shape: i64| {
            let scaled = (full.to_bits() as i64 * a + (1 << 30)) >> 31;
            Q8_24::from_bits(((scaled * shape + (1 << 30)) >> 31) as i32)
        };
        let cos_shape = (shape.cos_shape.to_bits() as i64).max(0);
        let sin_shape = (shape.sin_shape.to_bits() as i64).abs();
        (
            scale(self.decay, cos_shape),
            scale(self.face_speed, sin_shape),
        )
    }

    /// The drive amplitude at which the net tangential force on the block equals `target`
    /// (N along +x, Q16.16, either sign): to hold a block still against an external load
    /// F_ext, `target = -F_ext` (net force zero). Bisection over the amplitude, 16 halvings
    /// (2^-16 of full scale; about 0.4 mN at 120 N for seed 001's horn).
    ///
    /// The force's component towards the centreline, -sgn(x) F_t, grows with the amplitude
    /// for a held block (L0(k) / I0(k) increases with k) and for a block moving towards the
    /// centreline (the face outruns it over a longer part of the period). For a block moving
    /// away from the centreline it is not monotone: plain friction towards the centre (mu F_n)
    /// while the face is slower than the block, falling beyond the Littmann edge to a least
    /// value, then growing with the motor drive. The inversion then answers on that last,
    /// rising branch (the motor's: the same sense as the other cases, so the hold's PI and its
    /// clamps mean the same), whose foot is found first by bisection on the slope's sign
    /// (16 halvings, two evaluations each: about three times the cost); a target below the
    /// least force is `AboveNatural` at the foot's amplitude. At the node (sin(pi x/L) = 0)
    /// the force towards +x is taken as the centre direction (it is 0 for a held block at
    /// every amplitude). Reach: `AboveNatural` with amplitude 0 when the target's component
    /// towards the centre is at or below the force without vibration; `BelowMinimum` with
    /// full amplitude when it is beyond the force at full amplitude (flagged, never clamped
    /// silently). Errors: as [`Self::force`].
    pub fn amplitude_for_force(
        &self,
        point: &MotorPoint,
        target: Q16_16,
    ) -> Result<ForceInversion, ModelError> {
        let s: i64 = if point.shape.sin_shape.to_bits() < 0 {
            -1
        } else {
            1
        };
        // Components towards the centreline, Q16.16 bits.
        let towards = |force: Q16_16| -s * force.to_bits() as i64;
        let wanted = towards(target);
        // The foot of the rising branch: 0, or for a block moving away the least force's
        // amplitude (the slope test steps right on a flat stretch: the plateau below the
        // Littmann edge and the flat bottom both lie left of the rising branch).
        let mut foot = 0i32;
        if s * point.block_velocity.to_bits() as i64 > 0 {
            const SLOPE_STEP: i32 = 1 << 16; // 3e-5 of full scale
            let (mut low, mut high) = (0i32, Q1_31::MAX.to_bits() - SLOPE_STEP);
            for _ in 0..super::BISECTION_STEPS {
                let mid = low + (high - low) / 2;
                let here = towards(self.force(point, Q1_31::from_bits(mid))?.force);
                let right = towards(self.force(point, Q1_31::from_bits(mid + SLOPE_STEP))?.force);
                if right > here {
                    high = mid;
                } else {
                    low = mid;
                }
            }
            foot = high;
        }
        let none = self.force(point, Q1_31::from_bits(foot))?;
        if wanted <= towards(none.force) {
            return Ok(ForceInversion {
                amplitude: Q1_31::from_bits(foot),
                force: none,
                reach: Reach::AboveNatural,
            });
        }
        let full = self.force(point, Q1_31::MAX)?;
        if wanted >= towards(full.force) {
            return Ok(ForceInversion {
                amplitude: Q1_31::MAX,
                force: full,
                reach: Reach::BelowMinimum,
            });
        }
        // Invariant: towards(force(low)) < wanted <= towards(force(high)).
        let (mut low, mut high) = (foot, Q1_31::MAX.to_bits());
        let mut at_high = full;
        for _ in 0..super::BISECTION_STEPS {
            let mid = low + (high - low) / 2;
            let force = self.force(point, Q1_31::from_bits(mid))?;
            if towards(force.force) < wanted {
                low = mid;
            } else {
                high = mid;
                at_high = force;
            }
        }
        Ok(ForceInversion {
            amplitude: Q1_31::from_bits(high),
            force: at_high,
            reach: Reach::Reached,
        })
    }

    /// phi in Q.30, in [-2^30, 2^30].
    fn drive_ratio(&self, point: &MotorPoint, amplitude: Q1_31) -> Result<i64, ModelError> {
        let sin_shape = point.shape.sin_shape.to_bits() as i64;
        let cos_shape = point.shape.cos_shape.to_bits() as i64;
        if cos_shape < 0 {
            return Err(ModelError::OutOfDomain {
                input: "x",
                reason: "|x| must be <= L/2",
            });
        }
        let (k, w) = self.groups(&point.shape, amplitude);
        let (k, w) = (k.to_bits() as i64, w.to_bits() as i64);
        let s: i64 = if sin_shape < 0 { -1 } else { 1 };
        let v = point.block_velocity.to_bits() as i64;
        if w == 0 {
            // No tangential motion of the face: a held block feels nothing, a sliding block
            // plain friction against its motion.
            return Ok(-v.signum() * ONE_Q30);
        }
        if v.abs() >= w {
            // The face never outruns the block: friction opposes the sliding all period long.
            return Ok(-v.signum() * ONE_Q30);
        }
        let z = ((s * v) << 30) / w; // |z| < 1, Q2.30
        let asin_z = Q2_30::from_bits(z as i32)
            .asin()
            .map_err(fx_error("zeta"))?
            .to_bits() as i64;
        let acos_z = (core::f64::consts::FRAC_PI_2 * ONE_Q30 as f64) as i64 - asin_z; // [0, pi]
        // Half width of the interval where s du/dt > s v_b, as a phase (<= 2^31).
        let half_width = ((acos_z as u64 * TWO_OVER_PI_Q32 + (1 << 31)) >> 32).min(1 << 31);
        // Centre of that interval: where the face's velocity along s is largest.
        let centre: u32 = match self.u_phase {
            UPhase::Quadrature => 0,    // du/dt ~ cos theta
            UPhase::InPhase => 3 << 30, // du/dt ~ -sin theta: largest at 3 pi / 2
        };
        let width = 2 * half_width;
        let ahead_start = centre.wrapping_sub(half_width as u32);
        let behind_start = centre.wrapping_add(half_width as u32);
        let ahead = self.mean_over(ahead_start, width, k)?;
        let behind = self.mean_over(behind_start, FULL_TURN - width, k)?;
        let total = ahead + behind;
        if total <= 0 {
            // Unreachable for k <= 8 (total >= 0.13); kept as an error, never a division by 0.
            return Err(ModelError::OutOfDomain {
                input: "B",
                reason: "the contact force vanished over the period",
            });
        }
        let difference = s * (ahead - behind);
        let numerator = difference << 30;
        let ratio = (numerator + numerator.signum() * (total / 2)) / total; // rounded to nearest
        Ok(ratio.clamp(-ONE_Q30, ONE_Q30))
    }

    /// (1 / 2 pi) times the integral of e^(-k (1 + cos theta)) over the phase interval
    /// [start, start + length) (length <= 2^32, wrapping), Q.30: the composite rule on pieces
    /// of at most a quarter turn. `k` is Q8.24 in [0, 8].
    fn mean_over(&self, start: u32, length: u64, k: i64) -> Result<i64, ModelError> {
        if length == 0 {
            return Ok(0);
        }
        let pieces = length.div_ceil(QUARTER_TURN);
        let mut total = 0i64;
        for piece in 0..pieces {
            let begin = length * piece / pieces;
            let end = length * (piece + 1) / pieces;
            let span = end - begin;
            let mut sum = 0i64; // Q.60
            for (&node, &weight) in self.nodes.iter().zip(&self.weights) {
                let offset = (span * node as u64) >> 32;
                let phase = start.wrapping_add((begin + offset) as u32);
                // k (1 + cos theta) in Q8.24, in [0, 2k] <= 16.
                let one_plus_cos = (1i64 << 31) + cos(phase).to_bits() as i64;
                let argument = (k * one_plus_cos + (1 << 30)) >> 31;
                let h = Q8_24::from_bits(argument as i32)
                    .exp_neg()
                    .map_err(fx_error("k (1 + cos theta)"))?
                    .to_bits() as i64;
                sum += weight * h;
            }
            let mean = (sum + (1 << 29)) >> 30; // Q.30
            total += ((mean as u128 * span as u128 + (1 << 31)) >> 32) as i64;
        }
        Ok(total)
    }
}
