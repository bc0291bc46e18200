//! Horn kinematics (seed 000 eqs 16-17 and appendix A) and the cube friction-reduction model
//! (seed 000 eqs 9, 12-15; physics-notes §4).
//!
//! x is measured from the horn centre (the half-wavelength node): u = A P_u(t) sin(pi x/L),
//! v = B cos(2 pi f t) cos(pi x/L). With d' = d + v, A_r' = A_r e^(-lambda v/R_q) (every contact
//! term scales with e^(-lambda d/R_q)) and delta' = delta + u, seed 000 eq 15 becomes
//! F'/F = < e^(-2 lambda v/R_q) (d/d')^3 (1 + u/delta) > over the slip half-period, a
//! dimensionless average that does not depend on the frequency.

use std::f64::consts::PI;

use super::RefError;
use super::contact::{ContactModel, ContactParameters, EStarRule, contact_from_force};
use super::error::{finite, non_negative, positive, within};
use super::numerics::integrate;

/// Time dependence of the longitudinal projection u.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UPhase {
    /// u in phase with v: cos(2 pi f t), seed 000 eqs 16-17 (default; value `inphase`).
    #[default]
    InPhase,
    /// u in quadrature: sin(2 pi f t), the elliptical locus of seed 000 §3.1 (value `quadrature`).
    Quadrature,
}

/// Which half-period is the slip phase of seed 000 eq 15.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SlipWindow {
    /// The half-period with v >= 0, surfaces apart (physics-notes §4; default; value `vpos`).
    #[default]
    SurfacesApart,
    /// t in [0, T/2] with the cos phase of eqs 16-17, read literally: the approach half, where
    /// friction increases (value `literal_cos`).
    LiteralCos,
}

/// Inputs of [`horn_kinematics`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HornInput {
    /// Position from the horn centre x in m, |x| <= L/2.
    pub position: f64,
    /// Time t in s (finite).
    pub time: f64,
    /// Longitudinal amplitude A in m (>= 0).
    pub longitudinal_amplitude: f64,
    /// Vertical (Poisson) amplitude B in m (>= 0).
    pub vertical_amplitude: f64,
    /// Frequency f in Hz (> 0).
    pub frequency: f64,
    /// Horn length L in m (> 0; 0.127 m in seed 000).
    pub horn_length: f64,
}

/// Outputs of [`horn_kinematics`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HornOutput {
    /// Longitudinal (in-plane, along the sliding direction) displacement u in m.
    pub longitudinal: f64,
    /// Vertical (out-of-plane, Poisson) displacement v in m; v > 0 moves the surfaces apart.
    pub vertical: f64,
}

/// Longitudinal and vertical displacements at (x, t) (seed 000 eqs 16-17; `u_phase` variant).
pub fn horn_kinematics(input: &HornInput, phase: UPhase) -> Result<HornOutput, RefError> {
    let length = positive("L", input.horn_length)?;
    let x = within(
        "x",
        input.position,
        -0.5 * length,
        0.5 * length,
        "|x| must be <= L/2",
    )?;
    let t = finite("t", input.time)?;
    let a = non_negative("A", input.longitudinal_amplitude)?;
    let b = non_negative("B", input.vertical_amplitude)?;
    let f = positive("f", input.frequency)?;
    let cycles = f * t;
    let theta = 2.0 * PI * (cycles - cycles.floor());
    let shape = PI * x / length;
    let u_time = match phase {
        UPhase::InPhase => theta.cos(),
        UPhase::Quadrature => theta.sin(),
    };
    Ok(HornOutput {
        longitudinal: a * u_time * shape.sin(),
        vertical: b * theta.cos() * shape.cos(),
    })
}

/// Poisson-effect vertical amplitude B = D A pi nu / (2 L) in m (seed 000 eq A.9).
/// Inputs: A in m (>= 0), thickness D in m (> 0), nu in (-1, 0.5], L in m (> 0).
pub fn b_from_a(
    amplitude: f64,
    thickness: f64,
    poisson: f64,
    length: f64,
) -> Result<f64, RefError> {
    let a = non_negative("A", amplitude)?;
    let d = positive("D", thickness)?;
    let nu = within(
        "nu",
        poisson,
        -1.0 + f64::EPSILON,
        0.5,
        "must be in (-1, 0.5]",
    )?;
    let l = positive("L", length)?;
    Ok(d * a * PI * nu / (2.0 * l))
}

/// Inputs of [`cube_reduction`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubeInput {
    /// Normal force F_n in N (> 0).
    pub normal_force: f64,
    /// Friction coefficient mu (> 0): F_t0 = mu F_n.
    pub friction_coefficient: f64,
    /// Longitudinal amplitude A in m (>= 0; seed 000 Table 1).
    pub longitudinal_amplitude: f64,
    /// Vertical amplitude B in m (>= 0; seed 000 Table 1).
    pub vertical_amplitude: f64,
    /// Contact position from the horn centre x in m, |x| <= L/2.
    pub position: f64,
    /// Horn length L in m (> 0).
    pub horn_length: f64,
    /// Frequency f in Hz (> 0; validated, does not enter the result).
    pub frequency: f64,
    /// Material and surface parameters.
    pub contact: ContactParameters,
}

/// Variant choices of [`cube_reduction`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CubeOptions {
    /// E* rule.
    pub e_star_rule: EStarRule,
    /// Contact model for d and A_r.
    pub contact_model: ContactModel,
    /// Slip half-period.
    pub window: SlipWindow,
    /// Phase of u.
    pub u_phase: UPhase,
}

/// Outputs of [`cube_reduction`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubeOutput {
    /// Separation d in m.
    pub separation: f64,
    /// Real contact area A_r in m^2.
    pub real_area: f64,
    /// Tangential stiffness K_t in N/m.
    pub tangential_stiffness: f64,
    /// Steady microscopic deformation delta = F_t0 / K_t in m (steady state of eq 10).
    pub deformation: f64,
    /// Friction without vibration F_t0 = mu F_n in N.
    pub friction_without_vibration: f64,
    /// Friction with vibration F_t' = F_t0 F'/F in N (eq 15).
    pub friction_with_vibration: f64,
    /// F'/F, dimensionless.
    pub friction_ratio: f64,
    /// 100 (1 - F'/F) in % (seed 000 eq 18).
    pub reduction_pct: f64,
    /// Amplitude of u over delta, A sin(pi x/L) / delta (dimensionless).
    pub u_over_delta: f64,
}

/// Cube friction-reduction model, seed 000 eqs 12-15 with physics-notes §4's reading.
pub fn cube_reduction(input: &CubeInput, options: CubeOptions) -> Result<CubeOutput, RefError> {
    let mu = positive("mu", input.friction_coefficient)?;
    let a = non_negative("A", input.longitudinal_amplitude)?;
    let b = non_negative("B", input.vertical_amplitude)?;
    let length = positive("L", input.horn_length)?;
    let x = within(
        "x",
        input.position,
        -0.5 * length,
        0.5 * length,
        "|x| must be <= L/2",
    )?;
    positive("f", input.frequency)?;
    let state = contact_from_force(
        input.normal_force,
        &input.contact,
        options.e_star_rule,
        options.contact_model,
    )?;
    let d = state.separation;
    let friction = mu * state.normal_force;
    let delta = friction / state.tangential_stiffness;
    let shape = PI * x / length;
    let u_amplitude = a * shape.sin();
    let v_amplitude = b * shape.cos();
    let (theta_start, theta_end) = match options.window {
        SlipWindow::SurfacesApart if v_amplitude < 0.0 => (0.5 * PI, 1.5 * PI),
        SlipWindow::SurfacesApart => (-0.5 * PI, 0.5 * PI),
        SlipWindow::LiteralCos => (0.0, PI),
    };
    if options.window == SlipWindow::LiteralCos && d <= v_amplitude.abs() {
        return Err(RefError::ModelValidity(format!(
            "vertical amplitude {v_amplitude:e} m >= separation d = {d:e} m: surfaces would \
             interpenetrate (d + v <= 0)"
        )));
    }
    let decay = 2.0 * input.contact.distribution_lambda / input.contact.roughness_rq;
    // G(theta) = (A_r'/A_r)^2 (d/d')^3 = e^(-2 lambda v/R_q) (d/(d+v))^3.
    let weight = |theta: f64| {
        let v = v_amplitude * theta.cos();
        let scale = d / (d + v);
        (-decay * v).exp() * scale * scale * scale
    };
    let u_time = |theta: f64| match options.u_phase {
        UPhase::InPhase => theta.cos(),
        UPhase::Quadrature => theta.sin(),
    };
    let span = theta_end - theta_start;
    let mean_weight = integrate(weight, theta_start, theta_end, 1e-16 * span)? / span;
    let u_over_delta = u_amplitude / delta;
    let mean_u_weight = if u_over_delta == 0.0 {
        0.0
    } else {
        integrate(
            |theta| weight(theta) * u_time(theta),
            theta_start,
            theta_end,
            1e-16 * span,
        )? / span
    };
    let ratio = mean_weight + u_over_delta * mean_u_weight;
    Ok(CubeOutput {
        separation: d,
        real_area: state.real_area,
        tangential_stiffness: state.tangential_stiffness,
        deformation: delta,
        friction_without_vibration: friction,
        friction_with_vibration: friction * ratio,
        friction_ratio: ratio,
        reduction_pct: 100.0 * (1.0 - ratio),
        u_over_delta,
    })
}
