//! Independent double-precision reference of the friction model (host only).
//!
//! Written from the source papers (`/work/shared/seeds/`) and the project's reading of them
//! (`physics-notes.md`), never from the fixed-point code: it is the yardstick the firmware's
//! results are tested against. Closed forms are used wherever they are exact (Littmann law,
//! Dahl relaxation, contact constants, steady-state fixed point); the remaining averages are
//! adaptive Gauss-Legendre integrals converged to about 1e-15 absolute, and root searches are
//! bisections to 1 ulp. Formulas that cancel catastrophically when printed (physics-notes §1,
//! §3) are evaluated through series or half-angle forms.
//!
//! Units are SI throughout (m, s, N, Pa, m^2, Hz); percentages are marked `_pct`.
//!
//! | module | models |
//! |---|---|
//! | [`coulomb`] | `littmann_mu_i`, `coulomb_avg_friction`, `coulomb_sampled_avg_sign`, `exp_coulomb_law` |
//! | [`dahl_models`] (engine in `dahl`) | `dahl_steady`, `dahl_window`, `dahl_delta_transient` |
//! | [`contact`] | `contact_ep`, `contact_el`, `contact_ep_of_d` |
//! | [`cube`] | `cube_reduction`, `horn_kinematics`, `B_from_A` |
//! | [`actuator`] | `actuator` |
//!
//! [`eval_named`] is the uniform, string-keyed entry point; the typed functions of each module
//! are the same models with named fields.

pub mod actuator;
#[cfg(test)]
mod checks;
pub mod contact;
pub mod coulomb;
#[cfg(test)]
mod cross_checks;
pub mod cube;
mod dahl;
pub mod dahl_models;
pub mod dahl_ode;
mod error;
mod examples;
mod keys;
mod named;
pub mod numerics;

pub use error::RefError;
pub use examples::example_inputs;
pub use named::{MODELS, Outputs, eval_named};
