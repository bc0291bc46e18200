//! Instruction counts of every model variant and of the control step per fidelity level,
//! measured in QEMU (build feature `bench`; `scripts/speed-table` runs it and feeds the output
//! to `sonolube speed`).
//!
//! Method. Under `-icount shift=N` one guest instruction advances virtual time by 2^N ns, and
//! one 25 MHz SysTick cycle is 40 ns, so a SysTick interval of c cycles is 40 c / 2^N
//! instructions; the shift is read from the `icount=N` word `scripts/qemu-run` puts on the
//! command line (without it the benchmark refuses to report: it cannot convert). The published
//! counts use shift 0 (+-40 instructions per interval). Each variant is called on the same grid
//! of inputs as its error is measured on (`sonolube::variant::grid`): a kernel on its own input
//! grid, a model on the operating grid of every scene of its family that carries its
//! parameters, built as that scene would build it.
//! Inputs are prepared outside the timed loop, in chunks of up to [`BUFFER`]; each chunk is
//! timed twice, calling the variant and doing the same loop without it, and the difference is
//! summed over the chunks, so the figure is the call alone (call, return and the `black_box`
//! traffic on its arguments and result, a few instructions, included). Every grid point is
//! timed. Between chunks the watchdog is fed (the benchmark holds the executor for seconds of
//! virtual time); chunks are sized from the dearest of a few probe calls to last about 1 ms of
//! virtual time. The SysTick rounding (+-40 instructions at shift 0 per interval, two
//! intervals per chunk) is at most 0.3 instructions per call for the cheap calls (256 per
//! chunk) and below 0.1 % of the expensive ones.
//!
//! The control step is `sonolube_sim::ClosedLoop::control_phase` (target, sensing, estimate,
//! model and its inverse, controller, drive command), timed around every step of a scene whose
//! controller model is set to the fidelity level at its default knob
//! (`ClosedLoop::with_model`, not the variant the scene selects); the plant's phase is not
//! timed.
//!
//! The cube table variants' build (`CubeTable::new`, at scene start) is timed once per cube
//! scene: `bench build NAME: ...`, the mean over the scenes. The Dahl table variants (in flash,
//! nothing to build) have their inverse timed over the in-plane scenes' grids, the target being
//! the ratio at each grid point: `bench inverse NAME: ...`.
//!
//! Each control-step row is then run again with its stages marked (`sonolube::stage`,
//! `ClosedLoop::control_phase_marked`): the cycles between marks charged to the stage that ran,
//! the marks' own cost (measured on back-to-back marks) taken off, per step: `bench stage
//! NAME / STAGE: ...`.
//!
//! Output, one line per measurement (parsed by `sonolube speed`):
//! `bench NAME: N.NNN instructions per call (C calls)`.

use core::hint::black_box;
use core::mem::MaybeUninit;

use sonolube::fx::{Q1_31, Q2_30};
use sonolube::model::AnyModel;
use sonolube::model::cube_table::CubeTable;
use sonolube::model::{FrictionModel, OperatingPoint, dahl, littmann};
use sonolube::scene::{ModelKind, ModelSpec, SCENES, Scene};
use sonolube::stage::{Stage, StageMarks};
use sonolube::variant::budget::step_scene;
use sonolube::variant::fixed::fixed_model;
use sonolube::variant::float_inplane::{dahl_update, littmann as float_littmann};
use sonolube::variant::grid::{
    DAHL_UPDATE_POINTS, DahlUpdateInput, LITTMANN_POINTS, SceneGrid, dahl_update_input,
    littmann_input,
};
use sonolube::variant::model::FloatModel;
use sonolube::variant::real::{Libm, Maths, Micromath, Real};
use sonolube::variant::{
    CATALOGUE, CONTROL_STEPS, Family, Fidelity, Form, Model, Variant, lookup_table,
};
use sonolube_sim::{ClosedLoop, SimError};

use crate::{time_driver, watchdog};

/// Nanoseconds of virtual time per 25 MHz core cycle.
const NS_PER_CYCLE: u64 = 40;
/// Inputs prepared per chunk.
const BUFFER: usize = 256;
/// Core cycles (2 ms of virtual time, a small fraction of the watchdog's timeout) of which a
/// timed chunk is sized to take half, the margin for calls dearer than the probes found.
const CHUNK_CYCLES: u64 = 50_000;
/// Single calls timed to size the chunks.
const PROBES: usize = 9;

/// QEMU's `-icount` shift, from the `icount=N` word of the command line (semihosting
/// `SYS_GET_CMDLINE`); `None` when absent or malformed.
fn icount_shift() -> Option<u32> {
    let mut buffer = [MaybeUninit::<u8>::uninit(); 256];
    let bytes = semihosting::sys::arm_compat::sys_get_cmdline_uninit(&mut buffer).ok()?;
    core::str::from_utf8(bytes)
        .ok()?
        .split_ascii_whitespace()
        .find_map(|word| word.strip_prefix("icount="))
        .and_then(|shift| shift.parse().ok())
        .filter(|&shift| shift <= 10)
}

/// Thousandths of an instruction per call for `cycles` over `calls` at `-icount shift`.
fn milli_instructions(cycles: i64, calls: u64, shift: u32) -> Option<u64> {
    ((cycles.max(0) as u64 * NS_PER_CYCLE * 1000) >> shift).checked_div(calls)
}

/// Net cycles and calls of one variant.
#[derive(Default)]
struct Tally {
    cycles: i64,
    calls: u64,
}

impl Tally {
    /// Prints `bench NAME: N.NNN instructions per call (C calls)`.
    fn report(&self, name: &str, shift: u32) {
        let Some(milli) = milli_instructions(self.cycles, self.calls, shift) else {
            defmt::error!("bench {=str}: no calls", name);
            return;
        };
        defmt::info!(
            "bench {=str}: {=u64}.{=u64:03} instructions per call ({=u64} calls)",
            name,
            milli / 1000,
            milli % 1000,
            self.calls
        );
    }

    /// Prints `bench PREFIXNAME: N.NNN instructions per call (C calls)`.
    fn report_as(&self, prefix: &str, name: &str, shift: u32) {
        let Some(milli) = milli_instructions(self.cycles, self.calls, shift) else {
            defmt::error!("bench {=str}{=str}: no calls", prefix, name);
            return;
        };
        defmt::info!(
            "bench {=str}{=str}: {=u64}.{=u64:03} instructions per call ({=u64} calls)",
            prefix,
            name,
            milli / 1000,
            milli % 1000,
            self.calls
        );
    }
}

/// Core cycles of calling `call` on every input of `inputs`.
fn cycles_of<I: Copy, R>(inputs: &[I], call: &impl Fn(I) -> R) -> u64 {
    let start = time_driver::cycles();
    for &input in inputs {
        black_box(call(black_box(input)));
    }
    time_driver::cycles().saturating_sub(start)
}

/// Times `call` on the inputs `make(i)`, i < `count`, adding the net cycles and the calls to
/// `tally`.
fn time<I: Copy, R>(
    count: usize,
    make: impl Fn(usize) -> I,
    call: impl Fn(I) -> R,
    tally: &mut Tally,
) {
    if count == 0 {
        return;
    }
    let mut buffer = [make(0); BUFFER];
    // The dearest of a few calls spread over the inputs, alone, sizes the chunks (a grid's
    // costs vary: a Dahl steady state without velocity reversal returns at once).
    let dearest = (0..PROBES)
        .map(|k| cycles_of(&[make(k * (count - 1) / (PROBES - 1))], &call))
        .max()
        .unwrap_or(1);
    watchdog::feed();
    let chunk = (CHUNK_CYCLES / (2 * dearest).max(1)).clamp(1, BUFFER as u64) as usize;
    let mut pending = (0..count).peekable();
    while pending.peek().is_some() {
        let mut filled = 0;
        for (slot, index) in buffer.iter_mut().zip(pending.by_ref().take(chunk)) {
            *slot = make(index);
            filled += 1;
        }
        let with = cycles_of(&buffer[..filled], &call);
        let without = cycles_of(&buffer[..filled], &|input: I| input);
        tally.cycles += with as i64 - without as i64;
        tally.calls += filled as u64;
        watchdog::feed();
    }
}

fn kernel(variant: &Variant, shift: u32) {
    let mut tally = Tally::default();
    let zeta = |i| littmann_input(i);
    let zeta_f64 = |i| littmann_input(i).to_f64();
    let update = |i| dahl_update_input(i);
    let update_float = |i| {
        let input = dahl_update_input(i);
        (input.state.to_f64(), input.forward, input.travel.to_f64())
    };
    let (n, l) = (DAHL_UPDATE_POINTS, LITTMANN_POINTS);
    match (variant.fidelity, variant.form) {
        (Fidelity::Littmann, Form::Fixed) => time(l, zeta, littmann::mu_i::<30>, &mut tally),
        (Fidelity::Littmann, Form::F32Micromath) => time(
            l,
            |i| zeta_f64(i) as f32,
            float_littmann::<f32, Micromath>,
            &mut tally,
        ),
        (Fidelity::Littmann, Form::F32Libm) => time(
            l,
            |i| zeta_f64(i) as f32,
            float_littmann::<f32, Libm>,
            &mut tally,
        ),
        (Fidelity::Littmann, Form::F64) => {
            time(l, zeta_f64, float_littmann::<f64, Libm>, &mut tally)
        }
        (Fidelity::DahlUpdate, Form::Fixed) => time(
            n,
            update,
            |u: DahlUpdateInput| dahl::update(u.state, u.forward, u.travel),
            &mut tally,
        ),
        (Fidelity::DahlUpdate, Form::F32Micromath) => time(
            n,
            |i| {
                let (f, forward, y) = update_float(i);
                (f as f32, forward, y as f32)
            },
            |(f, forward, y)| dahl_update::<f32, Micromath>(f, forward, y),
            &mut tally,
        ),
        (Fidelity::DahlUpdate, Form::F32Libm) => time(
            n,
            |i| {
                let (f, forward, y) = update_float(i);
                (f as f32, forward, y as f32)
            },
            |(f, forward, y)| dahl_update::<f32, Libm>(f, forward, y),
            &mut tally,
        ),
        (Fidelity::DahlUpdate, Form::F64) => time(
            n,
            update_float,
            |(f, forward, y)| dahl_update::<f64, Libm>(f, forward, y),
            &mut tally,
        ),
        _ => return,
    }
    tally.report(variant.name, shift);
}

/// The family of a scene's operating grid.
fn family(scene: &Scene<'_>) -> Family {
    if scene.contents.normal_vibration {
        Family::Cube
    } else {
        Family::InPlane
    }
}

/// Times one float model on a scene's grid.
fn float_model<T: Real, M: Maths<T>>(model: &FloatModel<T>, grid: &SceneGrid, tally: &mut Tally) {
    let make = |i| {
        let p = grid.at(i);
        (
            T::of(p.load_n()),
            T::of(p.velocity_m_per_s()),
            T::of(p.amplitude()),
        )
    };
    let call = |(load, v, a): (T, T, T)| model.ratio::<M>(load, v, a);
    time(grid.len(), make, call, tally);
}

/// Times a model-level variant over every scene of its family that can build it; false if a
/// model that should build does not.
fn model(variant: &Variant, shift: u32) -> bool {
    let mut tally = Tally::default();
    for scene in SCENES
        .iter()
        .filter(|s| family(s) == variant.fidelity.family())
    {
        if !sonolube::variant::fixed::variant_buildable(scene, variant) {
            continue;
        }
        let built = match Model::new(scene, variant) {
            Ok(model) => model,
            Err(error) => {
                defmt::error!(
                    "bench {=str}: scene {=str}: {}",
                    variant.name,
                    scene.name,
                    error
                );
                return false;
            }
        };
        let grid = SceneGrid::new(scene);
        match &built {
            Model::Fixed(model) => {
                let make = |i| {
                    let p = grid.at(i);
                    (p.point, p.amplitude)
                };
                let call =
                    |(point, amplitude): (OperatingPoint, Q1_31)| model.ratio(&point, amplitude);
                time(grid.len(), make, call, &mut tally);
            }
            Model::F32Micromath(model) => float_model::<f32, Micromath>(model, &grid, &mut tally),
            Model::F32Libm(model) => float_model::<f32, Libm>(model, &grid, &mut tally),
            Model::F64(model) => float_model::<f64, Libm>(model, &grid, &mut tally),
        }
    }
    tally.report(variant.name, shift);
    true
}

/// Times the inverse of a Dahl table variant over every in-plane scene that can build it, the
/// target at each grid point being the model's ratio there (so every inverse has an answer);
/// prints `bench inverse NAME: ...`. False if the model cannot be built.
fn inverse(variant: &Variant, shift: u32) -> bool {
    let mut tally = Tally::default();
    for scene in SCENES.iter().filter(|s| family(s) == Family::InPlane) {
        if !sonolube::variant::fixed::variant_buildable(scene, variant) {
            continue;
        }
        let Ok(model) = fixed_model(scene, variant) else {
            defmt::error!(
                "bench inverse {=str}: scene {=str}",
                variant.name,
                scene.name
            );
            return false;
        };
        let grid = SceneGrid::new(scene);
        let make = |i| {
            let p = grid.at(i);
            let target = model.ratio(&p.point, p.amplitude).unwrap_or(Q2_30::ONE);
            (p.point, target)
        };
        let call = |(point, target): (OperatingPoint, Q2_30)| model.invert(&point, target);
        time(grid.len(), make, call, &mut tally);
    }
    tally.report_as("inverse ", variant.name, shift);
    true
}

/// Times building the table of a table variant (`CubeTable::new` on a copy of the exact model,
/// the copy included: about 1 KB, a few hundred instructions) once for every cube scene that can
/// build it; prints `bench build NAME: ...`. False if a table cannot be built.
fn table_build(variant: &Variant, shift: u32) -> bool {
    let mut tally = Tally::default();
    let exact = Variant {
        table: 0,
        ..*variant
    };
    for scene in SCENES.iter().filter(|s| family(s) == Family::Cube) {
        if !sonolube::variant::fixed::buildable(scene, variant.fidelity) {
            continue;
        }
        let Ok(AnyModel::Cube(model)) = fixed_model(scene, &exact) else {
            defmt::error!("bench build {=str}: scene {=str}", variant.name, scene.name);
            return false;
        };
        let range = (scene.contents.load_min_n, scene.contents.load_max_n);
        watchdog::feed();
        let start = time_driver::cycles();
        let built = black_box(CubeTable::new(
            black_box(model.clone()),
            range,
            usize::from(variant.table),
        ));
        tally.cycles += time_driver::cycles().saturating_sub(start) as i64;
        tally.calls += 1;
        watchdog::feed();
        if built.is_err() {
            defmt::error!("bench build {=str}: scene {=str}", variant.name, scene.name);
            return false;
        }
    }
    let Some(milli) = milli_instructions(tally.cycles, tally.calls, shift) else {
        defmt::error!("bench build {=str}: no scene", variant.name);
        return false;
    };
    defmt::info!(
        "bench build {=str}: {=u64}.{=u64:03} instructions per call ({=u64} calls)",
        variant.name,
        milli / 1000,
        milli % 1000,
        tally.calls
    );
    true
}

/// The controller model kind of a fidelity level.
fn kind(fidelity: Fidelity) -> Option<ModelKind> {
    match fidelity {
        Fidelity::Coulomb => Some(ModelKind::Coulomb),
        Fidelity::DahlSteady => Some(ModelKind::Dahl),
        Fidelity::CubeElastic => Some(ModelKind::CubeElastic),
        Fidelity::CubeElasticPlastic => Some(ModelKind::CubeElasticPlastic),
        Fidelity::Littmann | Fidelity::DahlUpdate => None,
    }
}

/// Times the control phase of `scene_name` run with a controller model of `fidelity`; false if
/// the run cannot be built.
fn control_step(name: &str, scene_name: &str, fidelity: Fidelity, table: u8, shift: u32) -> bool {
    let (Some(scene), Some(kind)) = (sonolube::scene::find(scene_name), kind(fidelity)) else {
        defmt::error!("bench {=str}: no scene {=str}", name, scene_name);
        return false;
    };
    let scene = Scene {
        controller: ModelSpec {
            kind,
            ..scene.controller
        },
        ..*scene
    };
    // The level's own model at its default knob (or the named table variant), not the variant
    // the scene selects: the row times the level.
    let model = match lookup_table(fidelity, table) {
        Some(variant) => fixed_model(&scene, variant),
        None => AnyModel::new(&scene, &scene.controller),
    };
    let run = model
        .map_err(SimError::Model)
        .and_then(|model| ClosedLoop::with_model(&scene, model));
    let mut closed_loop = match run {
        Ok(run) => run,
        Err(error) => {
            defmt::error!("bench {=str}: {}", name, error);
            return false;
        }
    };
    let (tally, longest) = time_control_phases(&mut closed_loop);
    let Some(milli) = milli_instructions(tally.cycles, tally.calls, shift) else {
        defmt::error!("bench {=str}: no steps", name);
        return false;
    };
    defmt::info!(
        "bench {=str}: {=u64}.{=u64:03} instructions per call ({=u64} calls, longest {=u64})",
        name,
        milli / 1000,
        milli % 1000,
        tally.calls,
        (longest * NS_PER_CYCLE) >> shift
    );
    // The same run again with its stages marked (a fresh run: the same steps, bit for bit).
    let rerun = match lookup_table(fidelity, table) {
        Some(variant) => fixed_model(&scene, variant),
        None => AnyModel::new(&scene, &scene.controller),
    }
    .map_err(SimError::Model)
    .and_then(|model| ClosedLoop::with_model(&scene, model));
    match rerun {
        Ok(mut run) => stage_breakdown("", name, &mut run, tally.calls, shift),
        Err(error) => {
            defmt::error!("bench stage {=str}: {}", name, error);
            false
        }
    }
}

/// Charges the time between a control step's stage marks (`sonolube::stage`) to the stage
/// that ran. Each interval between two marks also holds one mark's own cost (the end of the
/// mark that opened it, the start of the one that closed it): [`StageClock::calibrate`]
/// measures that cost on back-to-back marks, and [`StageClock::report`] takes it off.
struct StageClock {
    last: u64,
    current: Option<Stage>,
    cycles: [u64; Stage::ALL.len()],
    intervals: [u64; Stage::ALL.len()],
}

impl StageClock {
    fn new() -> Self {
        Self {
            last: time_driver::cycles(),
            current: None,
            cycles: [0; Stage::ALL.len()],
            intervals: [0; Stage::ALL.len()],
        }
    }

    /// `next` begins now (`None`: outside a step, not charged).
    #[inline(never)]
    fn switch(&mut self, next: Option<Stage>) {
        let now = time_driver::cycles();
        if let Some(stage) = self.current {
            self.cycles[stage.index()] += now.saturating_sub(self.last);
            self.intervals[stage.index()] += 1;
        }
        self.current = next;
        self.last = now;
    }

    /// The cost of one mark in core cycles, as (cycles, marks): the mean over `MARKS`
    /// back-to-back marks (each interval holds one mark's cost and nothing else).
    fn calibrate() -> (u64, u64) {
        const MARKS: u64 = 4096;
        let mut clock = Self::new();
        clock.switch(Some(Stage::Script));
        for _ in 0..MARKS {
            clock.enter(black_box(Stage::Script));
        }
        clock.switch(None);
        watchdog::feed();
        (
            clock.cycles[Stage::Script.index()],
            clock.intervals[Stage::Script.index()],
        )
    }

    /// Prints `bench stage PREFIXNAME / STAGE: N.NNN instructions per call (S calls)` for
    /// every stage, per step of `steps`, the marks' cost `(cycles, marks)` taken off.
    fn report(&self, prefix: &str, name: &str, steps: u64, mark: (u64, u64), shift: u32) {
        for stage in Stage::ALL {
            let i = stage.index();
            let marks_cost = (self.intervals[i] * mark.0)
                .checked_div(mark.1)
                .unwrap_or(0);
            let net = self.cycles[i] as i64 - marks_cost as i64;
            // A stage a scene never enters (no resonance loop) is reported as 0.
            let milli = milli_instructions(net, steps, shift).unwrap_or(0);
            defmt::info!(
                "bench stage {=str}{=str} / {=str}: {=u64}.{=u64:03} instructions per call ({=u64} calls)",
                prefix,
                name,
                stage.name(),
                milli / 1000,
                milli % 1000,
                steps
            );
        }
    }
}

impl StageMarks for StageClock {
    #[inline(always)]
    fn enter(&mut self, stage: Stage) {
        self.switch(Some(stage));
    }
}

/// Runs `closed_loop` to its end with its control phases' stages marked, and prints the
/// instructions per step of each stage; false unless it ran `steps` steps, as the unmarked
/// run did.
fn stage_breakdown(
    prefix: &str,
    name: &str,
    closed_loop: &mut ClosedLoop,
    steps: u64,
    shift: u32,
) -> bool {
    let mark = StageClock::calibrate();
    let mut clock = StageClock::new();
    let mut marked = 0;
    while !closed_loop.is_finished() {
        if closed_loop.plant_phase().is_none() {
            break;
        }
        watchdog::feed();
        clock.switch(None);
        let control = closed_loop.control_phase_marked(&mut clock);
        clock.switch(None);
        if control.is_none() || closed_loop.finish_step().is_none() {
            break;
        }
        marked += 1;
    }
    if marked != steps {
        defmt::error!(
            "bench stage {=str}{=str}: {=u64} steps marked, {=u64} timed",
            prefix,
            name,
            marked,
            steps
        );
        return false;
    }
    clock.report(prefix, name, steps, mark, shift);
    true
}

/// Runs every benchmark; returns false if a model or a run could not be built, or if the
/// `-icount` shift is unknown.
pub fn run() -> bool {
    let Some(shift) = icount_shift() else {
        defmt::error!("bench: no icount=N on the command line: cycles cannot become instructions");
        return false;
    };
    defmt::info!("bench: -icount shift={=u32}", shift);
    let mut ok = true;
    for variant in CATALOGUE {
        watchdog::feed();
        if variant.fidelity.family() == Family::Kernel {
            kernel(variant, shift);
        } else {
            ok &= model(variant, shift);
        }
    }
    for variant in CATALOGUE.iter().filter(|v| v.table > 0) {
        watchdog::feed();
        ok &= if variant.fidelity.family() == Family::Cube {
            table_build(variant, shift)
        } else {
            inverse(variant, shift)
        };
    }
    for &(name, scene, fidelity, table) in CONTROL_STEPS {
        ok &= control_step(name, scene, fidelity, table, shift);
    }
    ok &= variant_steps(shift);
    ok
}

/// The control step with every fixed-point model variant, for the period budget
/// (`sonolube::variant::budget`): `bench step NAME: ...`, the variant set as the controller's
/// model of its step scene ([`step_scene`]), timed as [`control_step`] times a level.
fn variant_steps(shift: u32) -> bool {
    let mut ok = true;
    for variant in CATALOGUE {
        let Some(scene_name) = step_scene(variant) else {
            continue;
        };
        watchdog::feed();
        ok &= variant_step(variant, scene_name, shift);
    }
    ok
}

/// Times the control phase of `scene_name` run with `variant` as its controller model.
fn variant_step(variant: &Variant, scene_name: &str, shift: u32) -> bool {
    let Some(scene) = sonolube::scene::find(scene_name) else {
        defmt::error!(
            "bench step {=str}: no scene {=str}",
            variant.name,
            scene_name
        );
        return false;
    };
    let run = fixed_model(scene, variant)
        .map_err(SimError::Model)
        .and_then(|model| ClosedLoop::with_model(scene, model));
    let mut closed_loop = match run {
        Ok(run) => run,
        Err(error) => {
            defmt::error!("bench step {=str}: {}", variant.name, error);
            return false;
        }
    };
    let (tally, longest) = time_control_phases(&mut closed_loop);
    let Some(milli) = milli_instructions(tally.cycles, tally.calls, shift) else {
        defmt::error!("bench step {=str}: no steps", variant.name);
        return false;
    };
    defmt::info!(
        "bench step {=str}: {=u64}.{=u64:03} instructions per call ({=u64} calls, longest {=u64})",
        variant.name,
        milli / 1000,
        milli % 1000,
        tally.calls,
        (longest * NS_PER_CYCLE) >> shift
    );
    // Its stages, on a fresh run of the same steps.
    let rerun = fixed_model(scene, variant)
        .map_err(SimError::Model)
        .and_then(|model| ClosedLoop::with_model(scene, model));
    match rerun {
        Ok(mut run) => stage_breakdown("step ", variant.name, &mut run, tally.calls, shift),
        Err(error) => {
            defmt::error!("bench stage step {=str}: {}", variant.name, error);
            false
        }
    }
}

/// Runs `closed_loop` to its end, timing each control phase (the plant's phase and the step's
/// end are not timed): the tally of cycles and the longest phase.
fn time_control_phases(closed_loop: &mut ClosedLoop) -> (Tally, u64) {
    let (mut tally, mut longest) = (Tally::default(), 0u64);
    while !closed_loop.is_finished() {
        if closed_loop.plant_phase().is_none() {
            break;
        }
        watchdog::feed();
        let start = time_driver::cycles();
        let control = closed_loop.control_phase();
        let cycles = time_driver::cycles().saturating_sub(start);
        if control.is_none() || closed_loop.finish_step().is_none() {
            break;
        }
        tally.cycles += cycles as i64;
        tally.calls += 1;
        longest = longest.max(cycles);
    }
    (tally, longest)
}
