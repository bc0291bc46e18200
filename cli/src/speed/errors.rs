//! Errors of every variant against the exact `f64` models, over the fixed grids
//! ([`sonolube::variant::grid`]).
//!
//! - Kernels on their own input grids, against the reference closed forms.
//! - Model levels on each scene's operating grid, against the exact model of every level at or
//!   above the variant's own in its family that the scene carries parameters for: its own level
//!   (the numerical error of the variant: arithmetic, maths library, quadrature), and the higher
//!   levels (the error of leaving parts out: the elastic contact against the elastic-plastic
//!   one, the Coulomb ratio against the Dahl steady state).
//!
//! Errors are absolute, in units of the friction ratio F'/F (a fraction of the natural
//! friction; x 100 for the % of the scenes' `model_pct`). A point the variant cannot evaluate
//! where the reference can counts as an infinite error; a point the reference cannot evaluate
//! is a measurement failure, reported and not skipped silently.

use sonolube::scene::{SCENES, Scene};
use sonolube::variant::fixed::{buildable, variant_buildable};
use sonolube::variant::grid::{SceneGrid, dahl_update_inputs, littmann_inputs};
use sonolube::variant::{CATALOGUE, Family, Fidelity, Kernel, Model, Variant};

use super::reference;

/// Maximum and RMS of a set of absolute errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Largest |error| (infinite if the variant failed where the reference did not).
    pub max: f64,
    /// Root mean square of the errors (infinite likewise).
    pub rms: f64,
    /// Points.
    pub points: usize,
}

/// Accumulates errors.
#[derive(Debug, Clone, Copy, Default)]
pub struct Accumulator {
    max: f64,
    sum_squares: f64,
    points: usize,
}

impl Accumulator {
    /// Adds one |error| (`f64::INFINITY` for a failed evaluation).
    pub fn add(&mut self, error: f64) {
        let e = if error.is_nan() {
            f64::INFINITY
        } else {
            error.abs()
        };
        self.max = self.max.max(e);
        self.sum_squares += e * e;
        self.points += 1;
    }

    /// Merges another accumulator in.
    pub fn merge(&mut self, other: &Accumulator) {
        self.max = self.max.max(other.max);
        self.sum_squares += other.sum_squares;
        self.points += other.points;
    }

    /// The statistics (zero points give zeros).
    pub fn stats(&self) -> Stats {
        Stats {
            max: self.max,
            rms: if self.points == 0 {
                0.0
            } else {
                (self.sum_squares / self.points as f64).sqrt()
            },
            points: self.points,
        }
    }
}

/// Error of one variant against one level's exact model over one scene's grid.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneErrors {
    /// Scene name.
    pub scene: &'static str,
    /// The variant.
    pub variant: &'static Variant,
    /// The level of the exact model.
    pub reference: Fidelity,
    /// The errors.
    pub stats: Stats,
}

/// All errors of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct Errors {
    /// Per variant, against its own level over every grid it is measured on (catalogue order).
    pub own: Vec<(&'static Variant, Stats)>,
    /// Per scene, variant and reference level.
    pub scenes: Vec<SceneErrors>,
}

impl Errors {
    /// The error of `variant` against its own level.
    pub fn own(&self, variant: &str) -> Option<Stats> {
        self.own
            .iter()
            .find(|(v, _)| v.name == variant)
            .map(|(_, s)| *s)
    }

    /// The error of `variant` against `reference` on `scene`.
    pub fn scene(&self, scene: &str, variant: &str, reference: Fidelity) -> Option<Stats> {
        self.scenes
            .iter()
            .find(|e| e.scene == scene && e.variant.name == variant && e.reference == reference)
            .map(|e| e.stats)
    }
}

/// The model family of a scene's contents.
pub fn scene_family(scene: &Scene<'_>) -> Family {
    if scene.contents.normal_vibration {
        Family::Cube
    } else {
        Family::InPlane
    }
}

/// The levels of a family, lowest first.
pub fn levels(family: Family) -> &'static [Fidelity] {
    match family {
        Family::InPlane => &[Fidelity::Coulomb, Fidelity::DahlSteady],
        Family::Cube => &[Fidelity::CubeElastic, Fidelity::CubeElasticPlastic],
        Family::Kernel => &[],
    }
}

/// Errors of a kernel over its grid.
fn kernel_errors(variant: &Variant) -> Result<Accumulator, String> {
    let kernel = Kernel::new(variant).ok_or("not a kernel")?;
    let mut acc = Accumulator::default();
    match variant.fidelity {
        Fidelity::Littmann => {
            for zeta in littmann_inputs() {
                let want = reference::littmann(zeta.to_f64());
                acc.add(
                    kernel
                        .littmann(zeta)
                        .map_or(f64::INFINITY, |got| got - want),
                );
            }
        }
        _ => {
            for input in dahl_update_inputs() {
                let want = reference::dahl_update(&input);
                acc.add(
                    kernel
                        .dahl_update(&input)
                        .map_or(f64::INFINITY, |got| got - want),
                );
            }
        }
    }
    Ok(acc)
}

/// The errors of every variant of `scene`'s family against every level at or above its own
/// that the scene carries parameters for (fixed-point variants only with `fixed_only`), over
/// the scene's grid: the measurement
/// [`measure`] makes for each built-in scene, and the host makes for a scene file when it is
/// loaded (`sonolube scene --file`, [`crate::commands::scene`]). Errors: as [`measure`].
pub fn scene_errors(
    scene: &Scene<'_>,
    fixed_only: bool,
) -> Result<Vec<(&'static Variant, Accumulator, SceneErrors)>, String> {
    let family = scene_family(scene);
    let grid = SceneGrid::new(scene);
    let points: Vec<_> = grid.points().collect();
    let name: &'static str = match sonolube::scene::find(scene.name) {
        Some(built) => built.name,
        None => Box::leak(scene.name.to_owned().into_boxed_str()),
    };
    let mut out = Vec::new();
    for &level in levels(family)
        .iter()
        .filter(|&&level| buildable(scene, level))
    {
        let exact: Vec<f64> = points
            .iter()
            .map(|at| reference::ratio(scene, level, at))
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{}: reference {:?}: {e}", scene.name, level))?;
        for variant in CATALOGUE.iter().filter(|v| {
            v.fidelity.family() == family
                && v.fidelity <= level
                && variant_buildable(scene, v)
                && (!fixed_only || v.form == sonolube::variant::Form::Fixed)
        }) {
            let model = Model::new(scene, variant)
                .map_err(|e| format!("{} {}: {e}", scene.name, variant.name))?;
            let mut acc = Accumulator::default();
            for (at, want) in points.iter().zip(&exact) {
                acc.add(model.ratio(at).map_or(f64::INFINITY, |got| got - want));
            }
            out.push((
                variant,
                acc,
                SceneErrors {
                    scene: name,
                    variant,
                    reference: level,
                    stats: acc.stats(),
                },
            ));
        }
    }
    Ok(out)
}

/// Measures every error. Errors: a reference that cannot evaluate a grid point, or a variant
/// that cannot be built where its parameters are present (messages).
pub fn measure() -> Result<Errors, String> {
    let mut own: Vec<(&'static Variant, Accumulator)> = CATALOGUE
        .iter()
        .map(|v| (v, Accumulator::default()))
        .collect();
    for (variant, acc) in own.iter_mut() {
        if variant.fidelity.family() == Family::Kernel {
            *acc = kernel_errors(variant).map_err(|e| format!("{}: {e}", variant.name))?;
        }
    }
    let mut scenes = Vec::new();
    for scene in SCENES {
        for (variant, acc, errors) in scene_errors(scene, false)? {
            if variant.fidelity == errors.reference
                && let Some((_, own_acc)) = own.iter_mut().find(|(v, _)| v.name == variant.name)
            {
                own_acc.merge(&acc);
            }
            scenes.push(errors);
        }
    }
    Ok(Errors {
        own: own.into_iter().map(|(v, acc)| (v, acc.stats())).collect(),
        scenes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accumulator_takes_max_and_rms_and_counts_failures_as_infinite() {
        let mut acc = Accumulator::default();
        for e in [3.0, -4.0] {
            acc.add(e);
        }
        let s = acc.stats();
        assert_eq!((s.max, s.points), (4.0, 2));
        assert!((s.rms - (12.5f64).sqrt()).abs() < 1e-15);
        acc.add(f64::NAN);
        assert_eq!(acc.stats().max, f64::INFINITY);
        assert_eq!(Accumulator::default().stats().rms, 0.0);
    }
}
