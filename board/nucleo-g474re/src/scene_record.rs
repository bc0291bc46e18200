//! A built-in scene as the board holds it: what the station reads at `scene NAME`
//! (`Station::with_selection`: the controller's model spec, the actuator, horn, transducer and
//! contents, the control rate) and the scene's hardware, without the simulation's parts (the
//! plant's model and its mismatch, the normal-load and target profiles, the injected faults,
//! the pass criteria, the description). The board has no simulated plant and runs no profile or
//! criterion: linking the core's whole scene table (872 B a scene, and those parts' slices) cost
//! it 12.2 KB of flash. The board's build script writes one record per compiled scene
//! (`$OUT_DIR/scene_start.rs`) and checks, for every scene the board can start, that the
//! station built from [`SceneRecord::scene`] is the station built from the compiled scene
//! itself (their `Debug` forms are equal): a field the station reads cannot be left out.
//! Compiled into the build script as well (`build.rs`).

use sonolube::scene::{
    Accuracy, Actuator, Breakpoint, Contents, Criterion, Horn, LoadCell, Mismatch, ModelSpec,
    Scene, System, Transducer,
};

/// What the board keeps of a built-in scene (see the module's documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneRecord {
    /// The system of the source papers.
    pub system: System,
    /// Control-loop rate, Hz.
    pub control_rate_hz: f64,
    /// Length of the scene's run, s.
    pub duration_s: f64,
    /// The model the controller uses.
    pub controller: ModelSpec,
    /// Vibration source.
    pub actuator: Actuator,
    /// Horn geometry, for horn systems.
    pub horn: Option<Horn>,
    /// Resonant transducer.
    pub transducer: Transducer,
    /// The normal-load cell.
    pub normal_cell: LoadCell,
    /// The tangential (friction) cell.
    pub tangential_cell: LoadCell,
    /// Sliding velocity over time, m/s: the board drives at its first breakpoint (`rig.rs`).
    pub sliding_velocity_m_per_s: &'static [Breakpoint],
    /// Accuracy the scene needs.
    pub accuracy: Accuracy,
    /// What the scene contains (the cube tables' load range).
    pub contents: Contents,
    /// The scene's run uses commissioned values.
    pub commission: bool,
    /// The model mismatch the scene declares (`[controller] model_mismatch_pct`), a fraction.
    pub model_mismatch: Option<f64>,
    /// The scene's tightest overshoot criterion alone (the station designs a console
    /// commissioning's staged steps by it), or none.
    pub overshoot: &'static [Criterion],
}

/// The plant over controller mismatch of a scene whose plant is the controller's own model.
const NO_MISMATCH: Mismatch = Mismatch {
    mu_ratio: 1.0,
    k_t_ratio: None,
    rq_ratio: None,
};

impl SceneRecord {
    /// The record of `scene` (the build script's).
    #[allow(dead_code)]
    pub fn of(scene: &Scene<'static>) -> Self {
        // The tightest overshoot criterion, as a one-element slice of the scene's own.
        let tightest = scene
            .criteria
            .iter()
            .enumerate()
            .filter_map(|(index, criterion)| match criterion {
                Criterion::Overshoot { max_pct } => Some((index, *max_pct)),
                _ => None,
            })
            .reduce(|a, b| if b.1 < a.1 { b } else { a });
        let overshoot = match tightest {
            Some((index, _)) => &scene.criteria[index..=index],
            None => &[],
        };
        Self {
            system: scene.system,
            control_rate_hz: scene.control_rate_hz,
            duration_s: scene.duration_s,
            controller: scene.controller,
            actuator: scene.actuator,
            horn: scene.horn,
            transducer: scene.transducer,
            normal_cell: scene.normal_cell,
            tangential_cell: scene.tangential_cell,
            sliding_velocity_m_per_s: scene.sliding_velocity_m_per_s,
            accuracy: scene.accuracy,
            contents: scene.contents,
            commission: scene.commission,
            model_mismatch: scene.model_mismatch,
            overshoot,
        }
    }

    /// The scene the station is built from, named `name`: this record's fields, and for the
    /// simulation's parts the board does not hold, the real rig's view: its plant is the
    /// controller's own model (no mismatch; the real contact is what it is), one plant step per
    /// control step, no noise seed, no normal-load or target profile, no injected fault, no
    /// criterion, no description. The station reads none of them (the build script checks it).
    pub fn scene(&self, name: &'static str) -> Scene<'static> {
        Scene {
            name,
            description: "",
            system: self.system,
            materials: "",
            control_rate_hz: self.control_rate_hz,
            duration_s: self.duration_s,
            plant_substeps: 1,
            noise_seed: 0,
            controller: self.controller,
            plant: self.controller,
            mismatch: NO_MISMATCH,
            actuator: self.actuator,
            horn: self.horn,
            transducer: self.transducer,
            normal_cell: self.normal_cell,
            tangential_cell: self.tangential_cell,
            faults: &[],
            normal_load_n: &[],
            sliding_velocity_m_per_s: self.sliding_velocity_m_per_s,
            target: &[],
            accuracy: self.accuracy,
            criteria: self.overshoot,
            contents: self.contents,
            commission: self.commission,
            model_mismatch: self.model_mismatch,
        }
    }
}
