//! The uniform entry point [`eval_named`]: model name + input map + variant map -> output map,
//! used by the command-line tool and the paper-number tests. Input and output keys are the
//! papers' symbols in SI units; unknown keys and values are errors, never silently ignored.

use std::collections::{BTreeMap, BTreeSet};

use super::RefError;
use super::actuator::{ActuatorInput, actuator};
use super::contact::{ContactModel, contact_from_force, contact_from_separation};
use super::coulomb::{
    CoulombAvgInput, ExpCoulombInput, SampledSignInput, coulomb_avg_friction,
    coulomb_sampled_avg_sign, exp_coulomb_law, littmann_mu_i,
};
use super::cube::{CubeInput, CubeOptions, HornInput, SlipWindow, UPhase, b_from_a};
use super::cube::{cube_reduction, horn_kinematics};
use super::dahl_models::{
    DahlSteadyInput, DahlWindowInput, DeltaTransientInput, dahl_delta_transient, dahl_steady,
    dahl_window,
};
use super::keys::{Inputs, Variants, contact_outputs, contact_parameters};
use super::motor::{MotorInput, motor_force};

/// Every model name accepted by [`eval_named`].
pub const MODELS: &[&str] = &[
    "littmann_mu_i",
    "coulomb_avg_friction",
    "coulomb_sampled_avg_sign",
    "dahl_steady",
    "dahl_window",
    "dahl_delta_transient",
    "contact_ep",
    "contact_el",
    "contact_ep_of_d",
    "cube_reduction",
    "horn_kinematics",
    "B_from_A",
    "exp_coulomb_law",
    "actuator",
    "motor_force",
];

/// Output map of [`eval_named`]: key -> value in SI units (percent for `*_pct`). A quantity
/// that is undefined at the given inputs (a velocity ratio without vibration, a ratio to or a
/// percent reduction of zero friction) is absent: never a finite stand-in or a limit value.
pub type Outputs = BTreeMap<&'static str, f64>;

/// The outputs that are defined (`Some`), keyed.
fn defined<const N: usize>(pairs: [(&'static str, Option<f64>); N]) -> Outputs {
    pairs
        .into_iter()
        .filter_map(|(key, value)| value.map(|value| (key, value)))
        .collect()
}

/// Evaluates reference model `model` at `inputs` (SI units) with `variant` choices.
///
/// | model | inputs | outputs | variant keys |
/// |---|---|---|---|
/// | `littmann_mu_i` | zeta | mu_i | - |
/// | `coulomb_avg_friction` | mu, W, v, x_a, f | v_a, zeta, F_novib, F_avg, reduction_pct | quadrature_points |
/// | `coulomb_sampled_avg_sign` | v, v_a, f, dt, Tw | mean_sign, reduction_pct | - |
/// | `dahl_steady` | mu, W, k_t, v, v_a, f, alpha (optional, 1) | zeta, x_a, kxa, F_novib, F_avg, ratio, reduction_pct | quadrature_points |
/// | `dahl_window` | mu, W, k_t, v, v_a, f, Tw, f0 | F_avg, reduction_pct | quadrature_points |
/// | `dahl_delta_transient` | F_t0, K_t, v_rel, t, delta0 | delta, delta_ss | - |
/// | `contact_ep` | F_n + contact set | E_star, d, A_r, K_t, ln_KF, omega_c, X, p_c, A_e, A_p, F_e, F_p, A_r_over_An | E_star_rule |
/// | `contact_el` | F_n + contact set (nu_soft, Y0 optional) | E_star, d, A_r, K_t, ln_KF | E_star_rule |
/// | `contact_ep_of_d` | d + contact set | F_n, F_e, F_p, A_r, A_e, A_p, A_r_over_An, K_t | E_star_rule |
/// | `cube_reduction` | F_n, mu, A, B, x, L, f + contact set | d, A_r, K_t, delta, Ft0, Ft_prime, ratio, reduction_pct, u_over_delta | E_star_rule, contact, window, u_phase, quadrature_points |
/// | `horn_kinematics` | x, t, A, B, f, L | u, v | u_phase |
/// | `B_from_A` | A, D, nu, L | B | - |
/// | `exp_coulomb_law` | mu_s, mu_d, alpha_dc, Vs, F_N | F_f | - |
/// | `actuator` | V, f, n, d33, C, K_stack, K_bolt, V_max, I_max | x_a, v_a, I, within_limits, V_limit | - |
/// | `motor_force` | F_n, mu, A, B, x, L, f, Rq, lam, v_b | F_t, phi, kappa, v_face | u_phase (quadrature default) |
///
/// The contact set is Rq, Rs, An, eta, c, lam, E1, nu1, E2, nu2, nu_soft, Y0. Variant values:
/// `E_star_rule` = seed000 (default) | seed001; `contact` = ep (default) | el; `window` = vpos
/// (default) | literal_cos; `u_phase` = inphase (default) | quadrature; `quadrature_points` = a
/// whole number >= 1, accepted and ignored (the reference always uses its converged integral).
///
/// Undefined outputs are left out of the map: `zeta` without vibration (`coulomb_avg_friction`,
/// `dahl_steady`), `reduction_pct` when the friction without vibration is zero
/// (`coulomb_avg_friction`, `coulomb_sampled_avg_sign`, `dahl_steady`, `dahl_window` at v = 0,
/// and mu W = 0 for `coulomb_avg_friction`), `ratio` of `dahl_steady` at v = 0.
///
/// Returns the model's outputs keyed as in the project's model table, or a [`RefError`] for an
/// unknown model, a missing / unknown / non-finite input, an unknown variant key or value, an
/// input outside the domain, a state outside the model's validity, or a non-finite result.
pub fn eval_named(
    model: &str,
    inputs: &BTreeMap<String, f64>,
    variant: &BTreeMap<String, String>,
) -> Result<Outputs, RefError> {
    let name = *MODELS
        .iter()
        .find(|known| **known == model)
        .ok_or_else(|| RefError::UnknownModel(model.to_string()))?;
    let mut i = Inputs {
        model: name,
        map: inputs,
        read: BTreeSet::new(),
    };
    let mut w = Variants {
        model: name,
        map: variant,
        read: BTreeSet::new(),
    };
    let outputs = evaluate(name, &mut i, &mut w)?;
    i.finish()?;
    w.finish()?;
    for (&key, value) in &outputs {
        if !value.is_finite() {
            return Err(RefError::NonFiniteResult {
                model: name,
                output: key,
            });
        }
    }
    Ok(outputs)
}

fn evaluate(
    name: &'static str,
    i: &mut Inputs<'_>,
    w: &mut Variants<'_>,
) -> Result<Outputs, RefError> {
    Ok(match name {
        "littmann_mu_i" => Outputs::from([("mu_i", littmann_mu_i(i.get("zeta")?)?)]),
        "coulomb_avg_friction" => {
            w.quadrature_points()?;
            let o = coulomb_avg_friction(&CoulombAvgInput {
                friction_coefficient: i.get("mu")?,
                normal_load: i.get("W")?,
                sliding_velocity: i.get("v")?,
                vibration_amplitude: i.get("x_a")?,
                frequency: i.get("f")?,
            })?;
            defined([
                ("v_a", Some(o.vibration_velocity)),
                ("zeta", o.velocity_ratio),
                ("F_novib", Some(o.friction_without_vibration)),
                ("F_avg", Some(o.average_friction)),
                ("reduction_pct", o.reduction_pct),
            ])
        }
        "coulomb_sampled_avg_sign" => {
            let o = coulomb_sampled_avg_sign(&SampledSignInput {
                sliding_velocity: i.get("v")?,
                vibration_velocity: i.get("v_a")?,
                frequency: i.get("f")?,
                time_step: i.get("dt")?,
                window: i.get("Tw")?,
            })?;
            defined([
                ("mean_sign", Some(o.mean_sign)),
                ("reduction_pct", o.reduction_pct),
            ])
        }
        "dahl_steady" => {
            w.quadrature_points()?;
            let o = dahl_steady(&DahlSteadyInput {
                friction_coefficient: i.get("mu")?,
                normal_load: i.get("W")?,
                tangential_stiffness: i.get("k_t")?,
                sliding_velocity: i.get("v")?,
                vibration_velocity: i.get("v_a")?,
                frequency: i.get("f")?,
                shape_exponent: i.get_or("alpha", 1.0)?,
            })?;
            defined([
                ("zeta", o.velocity_ratio),
                ("x_a", Some(o.vibration_amplitude)),
                ("kxa", Some(o.stiffness_amplitude_product)),
                ("F_novib", Some(o.friction_without_vibration)),
                ("F_avg", Some(o.average_friction)),
                ("ratio", o.friction_ratio),
                ("reduction_pct", o.reduction_pct),
            ])
        }
        "dahl_window" => {
            w.quadrature_points()?;
            let o = dahl_window(&DahlWindowInput {
                friction_coefficient: i.get("mu")?,
                normal_load: i.get("W")?,
                tangential_stiffness: i.get("k_t")?,
                sliding_velocity: i.get("v")?,
                vibration_velocity: i.get("v_a")?,
                frequency: i.get("f")?,
                window: i.get("Tw")?,
                initial_force_ratio: i.get("f0")?,
            })?;
            defined([
                ("F_avg", Some(o.average_friction)),
                ("reduction_pct", o.reduction_pct),
            ])
        }
        "dahl_delta_transient" => {
            let o = dahl_delta_transient(&DeltaTransientInput {
                static_friction: i.get("F_t0")?,
                tangential_stiffness: i.get("K_t")?,
                relative_velocity: i.get("v_rel")?,
                time: i.get("t")?,
                initial_deformation: i.get("delta0")?,
            })?;
            Outputs::from([("delta", o.deformation), ("delta_ss", o.steady_deformation)])
        }
        "contact_ep" | "contact_el" => {
            let elastic = name == "contact_el";
            let rule = w.e_star_rule()?;
            let params = contact_parameters(i, elastic)?;
            let model = if elastic {
                ContactModel::Elastic
            } else {
                ContactModel::ElasticPlastic
            };
            let state = contact_from_force(i.get("F_n")?, &params, rule, model)?;
            contact_outputs(&state, !elastic, params.nominal_area)
        }
        "contact_ep_of_d" => {
            let rule = w.e_star_rule()?;
            let params = contact_parameters(i, false)?;
            let s =
                contact_from_separation(i.get("d")?, &params, rule, ContactModel::ElasticPlastic)?;
            Outputs::from([
                ("F_n", s.normal_force),
                ("F_e", s.elastic_force),
                ("F_p", s.plastic_force),
                ("A_r", s.real_area),
                ("A_e", s.elastic_area),
                ("A_p", s.plastic_area),
                ("A_r_over_An", s.real_area / params.nominal_area),
                ("K_t", s.tangential_stiffness),
            ])
        }
        "cube_reduction" => cube_named(i, w)?,
        "horn_kinematics" => {
            let phase = w.u_phase()?;
            let o = horn_kinematics(
                &HornInput {
                    position: i.get("x")?,
                    time: i.get("t")?,
                    longitudinal_amplitude: i.get("A")?,
                    vertical_amplitude: i.get("B")?,
                    frequency: i.get("f")?,
                    horn_length: i.get("L")?,
                },
                phase,
            )?;
            Outputs::from([("u", o.longitudinal), ("v", o.vertical)])
        }
        "B_from_A" => Outputs::from([(
            "B",
            b_from_a(i.get("A")?, i.get("D")?, i.get("nu")?, i.get("L")?)?,
        )]),
        "exp_coulomb_law" => Outputs::from([(
            "F_f",
            exp_coulomb_law(&ExpCoulombInput {
                static_coefficient: i.get("mu_s")?,
                dynamic_coefficient: i.get("mu_d")?,
                decay_coefficient: i.get("alpha_dc")?,
                slip_velocity: i.get("Vs")?,
                normal_force: i.get("F_N")?,
            })?,
        )]),
        "actuator" => {
            let o = actuator(&ActuatorInput {
                voltage: i.get("V")?,
                frequency: i.get("f")?,
                discs: i.get("n")?,
                d33: i.get("d33")?,
                capacitance: i.get("C")?,
                stack_stiffness: i.get("K_stack")?,
                bolt_stiffness: i.get("K_bolt")?,
                max_voltage: i.get("V_max")?,
                max_current: i.get("I_max")?,
            })?;
            Outputs::from([
                ("x_a", o.displacement_amplitude),
                ("v_a", o.vibration_velocity),
                ("I", o.current),
                ("within_limits", if o.within_limits { 1.0 } else { 0.0 }),
                ("V_limit", o.voltage_limit),
            ])
        }
        "motor_force" => {
            let phase = w.choose(
                "u_phase",
                &[
                    ("quadrature", UPhase::Quadrature),
                    ("inphase", UPhase::InPhase),
                ],
                "quadrature (default for motor_force), inphase",
            )?;
            let o = motor_force(
                &MotorInput {
                    friction_coefficient: i.get("mu")?,
                    normal_force: i.get("F_n")?,
                    longitudinal_amplitude: i.get("A")?,
                    vertical_amplitude: i.get("B")?,
                    position: i.get("x")?,
                    horn_length: i.get("L")?,
                    frequency: i.get("f")?,
                    roughness_rq: i.get("Rq")?,
                    distribution_lambda: i.get("lam")?,
                    block_velocity: i.get("v_b")?,
                },
                phase,
            )?;
            Outputs::from([
                ("F_t", o.net_force),
                ("phi", o.drive_ratio),
                ("kappa", o.decay),
                ("v_face", o.face_speed),
            ])
        }
        _ => return Err(RefError::UnknownModel(name.to_string())),
    })
}

fn cube_named(i: &mut Inputs<'_>, w: &mut Variants<'_>) -> Result<Outputs, RefError> {
    w.quadrature_points()?;
    let options = CubeOptions {
        e_star_rule: w.e_star_rule()?,
        contact_model: w.choose(
            "contact",
            &[
                ("ep", ContactModel::ElasticPlastic),
                ("el", ContactModel::Elastic),
            ],
            "ep (default), el",
        )?,
        window: w.choose(
            "window",
            &[
                ("vpos", SlipWindow::SurfacesApart),
                ("literal_cos", SlipWindow::LiteralCos),
            ],
            "vpos (default), literal_cos",
        )?,
        u_phase: w.u_phase()?,
    };
    let o = cube_reduction(
        &CubeInput {
            normal_force: i.get("F_n")?,
            friction_coefficient: i.get("mu")?,
            longitudinal_amplitude: i.get("A")?,
            vertical_amplitude: i.get("B")?,
            position: i.get("x")?,
            horn_length: i.get("L")?,
            frequency: i.get("f")?,
            contact: contact_parameters(i, options.contact_model == ContactModel::Elastic)?,
        },
        options,
    )?;
    Ok(Outputs::from([
        ("d", o.separation),
        ("A_r", o.real_area),
        ("K_t", o.tangential_stiffness),
        ("delta", o.deformation),
        ("Ft0", o.friction_without_vibration),
        ("Ft_prime", o.friction_with_vibration),
        ("ratio", o.friction_ratio),
        ("reduction_pct", o.reduction_pct),
        ("u_over_delta", o.u_over_delta),
    ]))
}
