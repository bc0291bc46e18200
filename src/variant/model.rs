//! A variant ready to evaluate: [`Model`] for the friction-model levels (at a scene's grid
//! points), [`Kernel`] for the two kernels.
//!
//! The enum cases hold each form's own model, so a benchmark can run one form's native call
//! (fixed point on Q formats, float on its float type) without conversions in the timed loop;
//! [`Model::ratio`] and [`Kernel`]'s methods are the uniform entry points for error
//! measurement (inputs from the grid, result as `f64`).

use super::fixed::{buildable, cube_params, fixed_model};
use super::float_cube::FloatCube;
use super::float_inplane::{FloatCoulomb, FloatDahl, dahl_update, littmann};
use super::grid::{DahlUpdateInput, GridPoint};
use super::real::{Libm, Maths, Micromath, Real};
use super::{Fidelity, Form, Variant};
use crate::model::AnyModel;
use crate::model::{FrictionModel, ModelError, dahl, littmann};
use crate::scene::Scene;

/// A friction-model level in one float type.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum FloatModel<T> {
    /// Coulomb ratio.
    Coulomb(FloatCoulomb<T>),
    /// Dahl steady state.
    Dahl(FloatDahl<T>),
    /// Cube model (either contact).
    Cube(FloatCube<T>),
}

impl<T: Real> FloatModel<T> {
    /// The level of `variant` (a model level, float form) for `scene`.
    fn new(scene: &Scene<'_>, variant: &Variant) -> Result<Self, ModelError> {
        let frequency_hz = scene.transducer.drive_hz;
        let amplitude_m = scene.actuator.full_scale_amplitude_m;
        match variant.fidelity {
            Fidelity::Coulomb => Ok(Self::Coulomb(FloatCoulomb::new(frequency_hz, amplitude_m)?)),
            Fidelity::DahlSteady => {
                let p = super::fixed::dahl_params(scene, u32::from(variant.points))?;
                if p.shape_exponent != 1.0 {
                    return Err(ModelError::OutOfDomain {
                        input: "alpha",
                        reason: "the float forms implement alpha = 1 only",
                    });
                }
                Ok(Self::Dahl(FloatDahl::new(
                    p.friction_coefficient,
                    p.tangential_stiffness,
                    p.frequency_hz,
                    p.full_scale_amplitude_m,
                    p.quadrature_points,
                )?))
            }
            Fidelity::CubeElastic | Fidelity::CubeElasticPlastic => Ok(Self::Cube(FloatCube::new(
                &cube_params(scene, variant.fidelity, variant.points.into())?,
            )?)),
            Fidelity::Littmann | Fidelity::DahlUpdate => Err(kernel_error()),
        }
    }

    /// F'/F at load `load_n` (N), velocity `v` (m/s), `amplitude` (fraction of full scale),
    /// with the maths library `M`.
    pub fn ratio<M: Maths<T>>(&self, load_n: T, v: T, amplitude: T) -> Result<T, ModelError> {
        match self {
            Self::Coulomb(model) => model.ratio::<M>(v, amplitude),
            Self::Dahl(model) => model.ratio::<M>(load_n, v, amplitude),
            Self::Cube(model) => model.ratio::<M>(load_n, amplitude),
        }
    }
}

fn kernel_error() -> ModelError {
    ModelError::OutOfDomain {
        input: "variant",
        reason: "a kernel, not a friction model",
    }
}

/// A model-level variant built for one scene.
#[derive(Debug, Clone, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum Model {
    /// Fixed point: the controller's model.
    Fixed(AnyModel),
    /// `f32` with `micromath`.
    F32Micromath(FloatModel<f32>),
    /// `f32` with `libm`.
    F32Libm(FloatModel<f32>),
    /// `f64` with `libm`.
    F64(FloatModel<f64>),
}

impl Model {
    /// `variant` (a model level) for `scene`. Errors: a kernel variant, a level the scene's
    /// controller spec has no parameters for, or the model's validation.
    pub fn new(scene: &Scene<'_>, variant: &Variant) -> Result<Self, ModelError> {
        if !buildable(scene, variant.fidelity) {
            return Err(ModelError::OutOfDomain {
                input: "variant",
                reason: "the scene's controller spec lacks this fidelity's parameters",
            });
        }
        Ok(match variant.form {
            Form::Fixed => Self::Fixed(fixed_model(scene, variant)?),
            Form::F32Micromath => Self::F32Micromath(FloatModel::new(scene, variant)?),
            Form::F32Libm => Self::F32Libm(FloatModel::new(scene, variant)?),
            Form::F64 => Self::F64(FloatModel::new(scene, variant)?),
        })
    }

    /// F'/F at a grid point, as `f64`: the fixed point on the point's Q values, the float
    /// forms on the same values rounded to their type.
    pub fn ratio(&self, at: &GridPoint) -> Result<f64, ModelError> {
        let (load, v, a) = (at.load_n(), at.velocity_m_per_s(), at.amplitude());
        match self {
            Self::Fixed(model) => Ok(model.ratio(&at.point, at.amplitude)?.to_f64()),
            Self::F32Micromath(model) => float_ratio::<f32, Micromath>(model, load, v, a),
            Self::F32Libm(model) => float_ratio::<f32, Libm>(model, load, v, a),
            Self::F64(model) => float_ratio::<f64, Libm>(model, load, v, a),
        }
    }
}

fn float_ratio<T: Real, M: Maths<T>>(
    model: &FloatModel<T>,
    load: f64,
    v: f64,
    a: f64,
) -> Result<f64, ModelError> {
    model
        .ratio::<M>(T::of(load), T::of(v), T::of(a))
        .map(Real::to_f64)
}

/// A kernel variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Kernel {
    /// Which kernel (Littmann or Dahl update).
    pub fidelity: Fidelity,
    /// In which form.
    pub form: Form,
}

impl Kernel {
    /// The kernel of `variant`; `None` for a model-level variant.
    pub fn new(variant: &Variant) -> Option<Self> {
        matches!(variant.fidelity, Fidelity::Littmann | Fidelity::DahlUpdate).then_some(Self {
            fidelity: variant.fidelity,
            form: variant.form,
        })
    }

    /// mu_i(zeta) for a Q2.30 `zeta`, as `f64`. Error: not the Littmann kernel.
    pub fn littmann(&self, zeta: crate::fx::Q2_30) -> Result<f64, ModelError> {
        if self.fidelity != Fidelity::Littmann {
            return Err(kernel_error());
        }
        let z = zeta.to_f64();
        Ok(match self.form {
            Form::Fixed => littmann::mu_i(zeta)?.to_f64(),
            Form::F32Micromath => f64::from(littmann::<f32, Micromath>(z as f32)),
            Form::F32Libm => f64::from(littmann::<f32, Libm>(z as f32)),
            Form::F64 => littmann::<f64, Libm>(z),
        })
    }

    /// One Dahl update, as `f64`. Error: not the Dahl-update kernel, or a negative travel.
    pub fn dahl_update(&self, input: &DahlUpdateInput) -> Result<f64, ModelError> {
        if self.fidelity != Fidelity::DahlUpdate {
            return Err(kernel_error());
        }
        let (f, y) = (input.state.to_f64(), input.travel.to_f64());
        Ok(match self.form {
            Form::Fixed => dahl::update(input.state, input.forward, input.travel)?.to_f64(),
            Form::F32Micromath => f64::from(dahl_update::<f32, Micromath>(
                f as f32,
                input.forward,
                y as f32,
            )?),
            Form::F32Libm => {
                f64::from(dahl_update::<f32, Libm>(f as f32, input.forward, y as f32)?)
            }
            Form::F64 => dahl_update::<f64, Libm>(f, input.forward, y)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{SCENES, find};
    use crate::variant::grid::{SceneGrid, dahl_update_inputs, littmann_inputs};
    use crate::variant::{CATALOGUE, Family};

    /// Every model variant builds for every scene of its family whose spec carries its
    /// parameters, and every form agrees with the f64 form to its expected accuracy over the
    /// whole grid (micromath loosely: its approximations are percent-level at worst).
    #[test]
    fn every_form_agrees_with_f64_over_the_scene_grids() {
        for scene in SCENES {
            let family = if scene.contents.normal_vibration {
                Family::Cube
            } else {
                Family::InPlane
            };
            let grid = SceneGrid::new(scene);
            for variant in CATALOGUE.iter().filter(|v| v.fidelity.family() == family) {
                if !buildable(scene, variant.fidelity) {
                    assert!(Model::new(scene, variant).is_err());
                    continue;
                }
                let model = Model::new(scene, variant).expect(variant.name);
                let twin = Model::new(scene, variant.f64_twin().unwrap()).unwrap();
                let bound = match variant.form {
                    // The tables' interpolation error (bounded per size in
                    // `model::cube_table`'s tests): 6e-3 at 5 x 5 nodes.
                    Form::Fixed if variant.table > 0 => 7e-3,
                    Form::Fixed => 2e-3,
                    Form::F32Micromath => 5e-2,
                    Form::F32Libm => 1e-4,
                    // The f64 form is the yardstick here: its twin is itself (issue 18).
                    Form::F64 => continue,
                };
                for at in grid.points() {
                    let got = model.ratio(&at).expect(variant.name);
                    let want = twin.ratio(&at).unwrap();
                    assert!(
                        (got - want).abs() <= bound,
                        "{} {}: {got} vs {want} at {at:?}",
                        scene.name,
                        variant.name
                    );
                }
            }
        }
        let reference = find("reference").unwrap();
        assert!(Model::new(reference, crate::variant::find("Dahl update").unwrap()).is_err());
    }

    #[test]
    fn kernels_agree_with_f64() {
        for variant in CATALOGUE
            .iter()
            .filter(|v| v.fidelity.family() == Family::Kernel)
        {
            let kernel = Kernel::new(variant).unwrap();
            let twin = Kernel::new(variant.f64_twin().unwrap()).unwrap();
            // f32 holds 1 - 2^-24 below 1, so zeta = 1 - 2^-25 rounds to 1: mu_i moves by up
            // to (2/pi) sqrt(2^-24) = 1.6e-4 there.
            let bound = match variant.form {
                Form::F32Micromath => 2e-2,
                Form::F32Libm => 2e-4,
                // The f64 form is the yardstick here: its twin is itself (issue 18).
                Form::F64 => continue,
                Form::Fixed => 1e-8,
            };
            if variant.fidelity == Fidelity::Littmann {
                assert!(
                    kernel
                        .dahl_update(&dahl_update_inputs().next().unwrap())
                        .is_err()
                );
                for z in littmann_inputs() {
                    let (got, want) = (kernel.littmann(z).unwrap(), twin.littmann(z).unwrap());
                    assert!((got - want).abs() <= bound, "{}: {z:?}", variant.name);
                }
            } else {
                assert!(kernel.littmann(crate::fx::Q2_30::ZERO).is_err());
                for input in dahl_update_inputs() {
                    let got = kernel.dahl_update(&input).unwrap();
                    let want = twin.dahl_update(&input).unwrap();
                    assert!((got - want).abs() <= bound, "{}: {input:?}", variant.name);
                }
            }
        }
        assert!(Kernel::new(crate::variant::find("Coulomb ratio").unwrap()).is_none());
    }
}
