//! The fixed-point contact, horn and cube models (`sonolube::model::{contact, horn, cube}`)
//! evaluated from SI inputs, with exactly the model names and input, output and variant keys of
//! the reference (`reference::eval_named`), so that the two can be compared key by key.
//!
//! Path of every evaluation: SI f64 inputs -> the scene constants (f64, once per scene, as the
//! firmware does at scene load) -> the fixed-point hot path -> SI outputs. The conversions at
//! both ends are exact or documented:
//! - loads enter as ln(F_n / 1 N) in Q6.26, through an exact split of the f64 into integer and
//!   power of two and the fixed-point `ln` (1 mN to 50 kN at 1.5e-8 relative resolution);
//! - d leaves as d / R_q (Q8.24) times R_q; A_r, A_e, A_p, F_e, F_p, F_n(d) and u/delta leave
//!   as logarithms turned into `mantissa * 2^exp2` in fixed point, then scaled exactly in f64;
//! - quantities never formed in fixed point are computed here in f64 from the fixed-point
//!   results: K_t = E* A_r^2 / d^3 (up to 1e19 N/m), delta = mu F_n / K_t, p_c = F_n / A_r,
//!   F_t0 = mu F_n, F_t' = F_t0 F'/F and the percent reduction 100 (1 - F'/F);
//! - E*, omega_c and X are scene constants (f64) and are reported as such.
//!
//! Differences from the reference: `quadrature_points` selects the fixed-point N-point rule
//! (1..=64, default 16) where the reference ignores it; F'/F outside [-128, 128) (off the node)
//! is an error (flagged saturation of the Q8.24 ratio) where the reference returns the number.

use std::collections::BTreeMap;

use super::keys::Keys;
use sonolube::fx::Q2_30;
use sonolube::fx::scaled::Scaled;
use sonolube::model::ModelError;
use sonolube::model::contact::{
    ContactConstants, ContactKind, ContactParams, ContactState, EStarRule, ln_load_from_si,
};
use sonolube::model::cube::{CubeOptions, CubeParams, CubeScene, DEFAULT_QUADRATURE_POINTS};
use sonolube::model::horn::{HornShape, PoissonGain, UPhase, amplitude_um, time_phase};
use sonolube::model::quadrature::SlipWindow;

pub use super::Outputs;

/// The models this module evaluates.
pub const MODELS: &[&str] = &[
    "contact_ep",
    "contact_el",
    "contact_ep_of_d",
    "cube_reduction",
    "horn_kinematics",
    "B_from_A",
];

/// Evaluates the fixed-point version of `model` at `inputs` (SI) with `variant` choices.
/// Returns `None` when `model` is not one of [`MODELS`], otherwise the outputs (same keys as the
/// reference) or an error message (unknown, missing or non-finite input, unknown variant,
/// input outside the domain, state outside the model's validity or its fixed-point range).
pub fn eval_fixed_contact_cube(
    model: &str,
    inputs: &BTreeMap<String, f64>,
    variant: &BTreeMap<String, String>,
) -> Option<Result<Outputs, String>> {
    let name = *MODELS.iter().find(|known| **known == model)?;
    let mut keys = Keys::new(name, inputs, variant);
    let result = match name {
        "contact_ep" => contact(&mut keys, false),
        "contact_el" => contact(&mut keys, true),
        "contact_ep_of_d" => contact_of_separation(&mut keys),
        "cube_reduction" => cube(&mut keys),
        "horn_kinematics" => horn(&mut keys),
        _ => poisson_amplitude(&mut keys),
    };
    Some(result.and_then(|outputs| keys.finish().map(|_| outputs)))
}

impl Keys<'_> {
    fn quadrature_nodes(&mut self) -> Result<usize, String> {
        self.quadrature_points(DEFAULT_QUADRATURE_POINTS as u32)
            .map(|n| n as usize)
    }

    fn e_star_rule(&mut self) -> Result<EStarRule, String> {
        self.choose(
            "E_star_rule",
            &[
                ("seed000", EStarRule::Seed000),
                ("seed001", EStarRule::Seed001),
            ],
        )
    }

    /// The contact set; `nu_soft` and `Y0` are optional (and unread) for the elastic model.
    fn contact_params(&mut self, elastic: bool) -> Result<ContactParams, String> {
        let soft = |keys: &mut Self, key| match elastic {
            true => keys.optional(key).map(|v| v.unwrap_or(f64::NAN)),
            false => keys.get(key),
        };
        Ok(ContactParams {
            poisson_soft: soft(self, "nu_soft")?,
            yield_strength: soft(self, "Y0")?,
            roughness_rq: self.get("Rq")?,
            summit_radius: self.get("Rs")?,
            nominal_area: self.get("An")?,
            asperity_density: self.get("eta")?,
            distribution_c: self.get("c")?,
            distribution_lambda: self.get("lam")?,
            young_1: self.get("E1")?,
            poisson_1: self.get("nu1")?,
            young_2: self.get("E2")?,
            poisson_2: self.get("nu2")?,
        })
    }
}

fn model_error(model: &str) -> impl Fn(ModelError) -> String + '_ {
    move |e| format!("{model}: {e}")
}

fn wide(value: Option<Scaled>) -> f64 {
    value.map_or(0.0, Scaled::to_f64)
}

/// d and A_r in SI from a fixed-point state, and K_t = E* A_r^2 / d^3 in f64.
fn geometry(constants: &ContactConstants, state: &ContactState) -> (f64, f64, f64) {
    let s = constants.scene();
    let d = state.separation_rq.to_f64() * s.roughness_rq;
    let area = state.area_scaled().to_f64() * s.nominal_area;
    (d, area, s.e_star * area * area / (d * d * d))
}

fn contact(keys: &mut Keys<'_>, elastic: bool) -> Result<Outputs, String> {
    let rule = keys.e_star_rule()?;
    let params = keys.contact_params(elastic)?;
    let load = keys.get("F_n")?;
    let err = model_error(keys.model);
    let kind = if elastic {
        ContactKind::Elastic
    } else {
        ContactKind::ElasticPlastic
    };
    let constants = ContactConstants::new(&params, rule, kind).map_err(&err)?;
    let state = constants
        .state(ln_load_from_si(load).map_err(&err)?)
        .map_err(&err)?;
    let (d, area, stiffness) = geometry(&constants, &state);
    let s = constants.scene();
    let mut out = Outputs::from([
        ("E_star", s.e_star),
        ("d", d),
        ("A_r", area),
        ("K_t", stiffness),
        ("ln_KF", constants.ln_force_constant().to_f64()),
    ]);
    if !elastic {
        let split = constants.split(&state);
        out.extend([
            ("omega_c", s.critical_interference),
            ("X", s.interference_ratio),
            ("p_c", load / area),
            ("A_e", wide(split.elastic_area_ratio) * s.nominal_area),
            ("A_p", wide(split.plastic_area_ratio) * s.nominal_area),
            ("F_e", wide(split.elastic_force)),
            ("F_p", wide(split.plastic_force)),
            ("A_r_over_An", area / s.nominal_area),
        ]);
    }
    Ok(out)
}

fn contact_of_separation(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let rule = keys.e_star_rule()?;
    let params = keys.contact_params(false)?;
    let separation = keys.get("d")?;
    let err = model_error(keys.model);
    let constants =
        ContactConstants::new(&params, rule, ContactKind::ElasticPlastic).map_err(&err)?;
    let ratio = sonolube::fx::Q8_24::from_f64(separation / params.roughness_rq)
        .map_err(|_| format!("{}: d / R_q must be below 128", keys.model))?;
    let state = constants.state_at_separation(ratio).map_err(&err)?;
    let (_, area, stiffness) = geometry(&constants, &state);
    let an = constants.scene().nominal_area;
    let split = constants.split(&state);
    Ok(Outputs::from([
        ("F_n", state.load_scaled().to_f64()),
        ("F_e", wide(split.elastic_force)),
        ("F_p", wide(split.plastic_force)),
        ("A_r", area),
        ("A_e", wide(split.elastic_area_ratio) * an),
        ("A_p", wide(split.plastic_area_ratio) * an),
        ("A_r_over_An", area / an),
        // From the fixed-point d / R_q (the input rounded to Q8.24), like every other output.
        ("K_t", stiffness),
    ]))
}

fn cube(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let points = keys.quadrature_nodes()?;
    let options = CubeOptions {
        e_star_rule: keys.e_star_rule()?,
        contact_kind: keys.choose(
            "contact",
            &[
                ("ep", ContactKind::ElasticPlastic),
                ("el", ContactKind::Elastic),
            ],
        )?,
        window: keys.choose(
            "window",
            &[
                ("vpos", SlipWindow::SurfacesApart),
                ("literal_cos", SlipWindow::LiteralCos),
            ],
        )?,
        u_phase: keys.choose(
            "u_phase",
            &[
                ("inphase", UPhase::InPhase),
                ("quadrature", UPhase::Quadrature),
            ],
        )?,
        quadrature_points: points,
    };
    let load = keys.get("F_n")?;
    let params = CubeParams {
        friction_coefficient: keys.get("mu")?,
        longitudinal_amplitude: keys.get("A")?,
        vertical_amplitude: keys.get("B")?,
        position: keys.get("x")?,
        horn_length: keys.get("L")?,
        frequency: keys.get("f")?,
        contact: keys.contact_params(options.contact_kind == ContactKind::Elastic)?,
    };
    let err = model_error(keys.model);
    let scene = CubeScene::new(&params, &options).map_err(&err)?;
    let point = scene
        .prepare(ln_load_from_si(load).map_err(&err)?)
        .map_err(&err)?;
    // The host evaluates at full scale: A and B are the scene's full-scale amplitudes.
    let ratio = scene.evaluate(&point, Q2_30::ONE).map_err(&err)?;
    if ratio.saturated {
        return Err(format!(
            "{}: F'/F saturates Q8.24 (outside [-128, 128): off the node, u/delta is huge)",
            keys.model
        ));
    }
    let ratio = ratio.value.to_f64();
    let (d, area, stiffness) = geometry(scene.contact(), &point.contact);
    let friction = scene.friction_coefficient() * load;
    let u_over_delta = match point.u_over_delta {
        None => 0.0,
        Some(u) if scene.u_negative() => -u.to_f64(),
        Some(u) => u.to_f64(),
    };
    Ok(Outputs::from([
        ("d", d),
        ("A_r", area),
        ("K_t", stiffness),
        ("delta", friction / stiffness),
        ("Ft0", friction),
        ("Ft_prime", friction * ratio),
        ("ratio", ratio),
        ("reduction_pct", 100.0 * (1.0 - ratio)),
        ("u_over_delta", u_over_delta),
    ]))
}

fn horn(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let u_phase = keys.choose(
        "u_phase",
        &[
            ("inphase", UPhase::InPhase),
            ("quadrature", UPhase::Quadrature),
        ],
    )?;
    let err = model_error(keys.model);
    let shape = HornShape::new(keys.get("x")?, keys.get("L")?).map_err(&err)?;
    let a = amplitude_um("A", keys.get("A")?).map_err(&err)?;
    let b = amplitude_um("B", keys.get("B")?).map_err(&err)?;
    let phase = time_phase(keys.get("f")?, keys.get("t")?).map_err(&err)?;
    let out = shape.displacement(a, b, phase, u_phase);
    Ok(Outputs::from([
        ("u", out.longitudinal_um.to_f64() * 1e-6),
        ("v", out.vertical_um.to_f64() * 1e-6),
    ]))
}

fn poisson_amplitude(keys: &mut Keys<'_>) -> Result<Outputs, String> {
    let err = model_error(keys.model);
    let amplitude = amplitude_um("A", keys.get("A")?).map_err(&err)?;
    let gain = PoissonGain::new(keys.get("D")?, keys.get("nu")?, keys.get("L")?).map_err(&err)?;
    let b = gain.vertical_amplitude(amplitude).map_err(&err)?;
    Ok(Outputs::from([("B", b.to_f64() * 1e-6)]))
}
