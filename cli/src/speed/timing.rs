//! Host time per evaluation of every variant as a ratio to its `f64` twin, from a small
//! benchmark harness.
//!
//! Each variant is called on the same inputs as in QEMU (its kernel grid, or the operating
//! grids of the scenes it applies to), with inputs prepared in its own number type beforehand
//! and arguments and results passed through `black_box`. One pass calls every input once; a
//! sample repeats passes for at least [`SAMPLE_TIME`]. The variant and the `f64` form of the
//! same level and knob are sampled in turn, [`SAMPLES`] times each, and the published figure is
//! the median of the [`SAMPLES`] ratios: a change of machine load during the run hits both
//! sides of a ratio alike. What remains moves from run to run (by a few % on a quiet machine,
//! up to about 20 % on a busy one), so the check that the committed files are current replays
//! the ratios recorded in `docs/speed.md` instead of timing.

use std::hint::black_box;
use std::time::{Duration, Instant};

use sonolube::fx::{Q1_31, Q2_30};
use sonolube::model::AnyModel;
use sonolube::model::{FrictionModel, OperatingPoint, dahl, littmann};
use sonolube::scene::SCENES;
use sonolube::variant::fixed::buildable;
use sonolube::variant::float_inplane::{dahl_update, littmann as float_littmann};
use sonolube::variant::grid::{DahlUpdateInput, SceneGrid, dahl_update_inputs, littmann_inputs};
use sonolube::variant::model::FloatModel;
use sonolube::variant::real::{Libm, Maths, Micromath, Real};
use sonolube::variant::{CATALOGUE, Family, Fidelity, Form, Model, Variant};

use super::errors::scene_family;

/// Samples (ratios) per variant.
pub const SAMPLES: usize = 15;
/// Shortest sample.
pub const SAMPLE_TIME: Duration = Duration::from_millis(4);

/// One pass over a variant's inputs; returns the calls made.
pub type Pass = Box<dyn FnMut() -> usize>;

/// A pass with its repetition count per sample.
struct Timed {
    pass: Pass,
    passes: usize,
}

impl Timed {
    /// Warms `pass` up and sizes its samples to [`SAMPLE_TIME`].
    fn new(mut pass: Pass) -> Self {
        pass(); // caches and branch predictors
        let start = Instant::now();
        pass();
        let once = start.elapsed().max(Duration::from_nanos(1));
        let passes = (SAMPLE_TIME.as_nanos() / once.as_nanos()).max(1) as usize;
        Self { pass, passes }
    }

    /// ns per call over one sample.
    fn sample(&mut self) -> f64 {
        let start = Instant::now();
        let mut calls = 0;
        for _ in 0..self.passes {
            calls += (self.pass)();
        }
        start.elapsed().as_nanos() as f64 / calls.max(1) as f64
    }
}

/// Median of the ratios of `variant`'s samples to `twin`'s, sampled in turn.
fn median_ratio(variant: Pass, twin: Pass) -> f64 {
    let (mut variant, mut twin) = (Timed::new(variant), Timed::new(twin));
    let mut ratios: Vec<f64> = (0..SAMPLES)
        .map(|_| variant.sample() / twin.sample())
        .collect();
    ratios.sort_by(f64::total_cmp);
    ratios[SAMPLES / 2]
}

/// A float model with its inputs (load, velocity, amplitude) in its own type.
type FloatRun<T> = (FloatModel<T>, Vec<(T, T, T)>);

fn float_runs<T: Real>(
    models: &[(Model, SceneGrid)],
    pick: impl Fn(&Model) -> Option<&FloatModel<T>>,
) -> Vec<FloatRun<T>> {
    models
        .iter()
        .filter_map(|(model, grid)| {
            let inputs = grid
                .points()
                .map(|p| {
                    (
                        T::of(p.load_n()),
                        T::of(p.velocity_m_per_s()),
                        T::of(p.amplitude()),
                    )
                })
                .collect();
            pick(model).map(|m| (*m, inputs))
        })
        .collect()
}

fn float_pass<T: Real + 'static, M: Maths<T> + 'static>(runs: Vec<FloatRun<T>>) -> Pass {
    Box::new(move || {
        let mut calls = 0;
        for (model, inputs) in &runs {
            for &(load, v, a) in inputs {
                let _ = black_box(model.ratio::<M>(black_box(load), black_box(v), black_box(a)));
            }
            calls += inputs.len();
        }
        calls
    })
}

fn model_pass(variant: &Variant) -> Result<Pass, String> {
    let family = variant.fidelity.family();
    let models: Vec<(Model, SceneGrid)> = SCENES
        .iter()
        .filter(|s| scene_family(s) == family && buildable(s, variant.fidelity))
        .map(|s| {
            Model::new(s, variant)
                .map(|m| (m, SceneGrid::new(s)))
                .map_err(|e| format!("{} {}: {e}", s.name, variant.name))
        })
        .collect::<Result<_, _>>()?;
    Ok(match variant.form {
        Form::Fixed => {
            let fixed: Vec<(AnyModel, Vec<(OperatingPoint, Q1_31)>)> = models
                .iter()
                .filter_map(|(m, grid)| match m {
                    Model::Fixed(model) => Some((
                        model.clone(),
                        grid.points().map(|p| (p.point, p.amplitude)).collect(),
                    )),
                    _ => None,
                })
                .collect();
            Box::new(move || {
                let mut calls = 0;
                for (model, inputs) in &fixed {
                    for (point, amplitude) in inputs {
                        let _ = black_box(model.ratio(black_box(point), black_box(*amplitude)));
                    }
                    calls += inputs.len();
                }
                calls
            })
        }
        Form::F32Micromath => float_pass::<f32, Micromath>(float_runs(&models, |m| match m {
            Model::F32Micromath(f) => Some(f),
            _ => None,
        })),
        Form::F32Libm => float_pass::<f32, Libm>(float_runs(&models, |m| match m {
            Model::F32Libm(f) => Some(f),
            _ => None,
        })),
        Form::F64 => float_pass::<f64, Libm>(float_runs(&models, |m| match m {
            Model::F64(f) => Some(f),
            _ => None,
        })),
    })
}

/// A pass calling `call` on every input.
fn pass_over<I: Copy + 'static>(inputs: Vec<I>, call: impl Fn(I) + 'static) -> Pass {
    Box::new(move || {
        for &input in &inputs {
            call(black_box(input));
        }
        inputs.len()
    })
}

fn littmann_pass(form: Form) -> Pass {
    let zetas: Vec<Q2_30> = littmann_inputs().collect();
    let narrow: Vec<f32> = zetas.iter().map(|z| z.to_f64() as f32).collect();
    let wide: Vec<f64> = zetas.iter().map(|z| z.to_f64()).collect();
    match form {
        Form::Fixed => pass_over(zetas, |z| {
            let _ = black_box(littmann::mu_i(z));
        }),
        Form::F32Micromath => pass_over(narrow, |z| {
            black_box(float_littmann::<f32, Micromath>(z));
        }),
        Form::F32Libm => pass_over(narrow, |z| {
            black_box(float_littmann::<f32, Libm>(z));
        }),
        Form::F64 => pass_over(wide, |z| {
            black_box(float_littmann::<f64, Libm>(z));
        }),
    }
}

fn update_pass(form: Form) -> Pass {
    let inputs: Vec<DahlUpdateInput> = dahl_update_inputs().collect();
    let narrow: Vec<(f32, bool, f32)> = inputs
        .iter()
        .map(|u| (u.state.to_f64() as f32, u.forward, u.travel.to_f64() as f32))
        .collect();
    let wide: Vec<(f64, bool, f64)> = inputs
        .iter()
        .map(|u| (u.state.to_f64(), u.forward, u.travel.to_f64()))
        .collect();
    match form {
        Form::Fixed => pass_over(inputs, |u| {
            let _ = black_box(dahl::update(u.state, u.forward, u.travel));
        }),
        Form::F32Micromath => pass_over(narrow, |(f, s, y)| {
            let _ = black_box(dahl_update::<f32, Micromath>(f, s, y));
        }),
        Form::F32Libm => pass_over(narrow, |(f, s, y)| {
            let _ = black_box(dahl_update::<f32, Libm>(f, s, y));
        }),
        Form::F64 => pass_over(wide, |(f, s, y)| {
            let _ = black_box(dahl_update::<f64, Libm>(f, s, y));
        }),
    }
}

/// The timed pass of `variant` over its inputs.
pub fn pass(variant: &Variant) -> Result<Pass, String> {
    Ok(match variant.fidelity {
        Fidelity::Littmann => littmann_pass(variant.form),
        Fidelity::DahlUpdate => update_pass(variant.form),
        _ if variant.fidelity.family() != Family::Kernel => model_pass(variant)?,
        _ => return Err(format!("{}: no pass", variant.name)),
    })
}

/// Every catalogued variant's host time as a ratio to its `f64` twin's (same level and knob,
/// sampled in turn), in catalogue order.
pub fn measure() -> Result<Vec<(&'static str, f64)>, String> {
    CATALOGUE
        .iter()
        .map(|variant| {
            let twin = variant
                .f64_twin()
                .ok_or_else(|| format!("{}: no f64 twin", variant.name))?;
            Ok((variant.name, median_ratio(pass(variant)?, pass(twin)?)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pass that sleeps `micros` per call, one call per pass.
    fn sleeper(micros: u64) -> Pass {
        Box::new(move || {
            std::thread::sleep(Duration::from_micros(micros));
            1
        })
    }

    #[test]
    fn ratios_compare_a_variant_with_its_twin_sampled_in_turn() {
        // A pass twice as slow as its twin: the median ratio is near 2 despite sleep jitter.
        let r = median_ratio(sleeper(2_000), sleeper(1_000));
        assert!((1.5..2.6).contains(&r), "{r}");
        let same = median_ratio(sleeper(1_000), sleeper(1_000));
        assert!((0.7..1.4).contains(&same), "{same}");
        // Every variant has a pass that makes calls.
        for variant in CATALOGUE {
            let mut p = pass(variant).expect(variant.name);
            assert!(p() > 0, "{}", variant.name);
        }
    }
}
