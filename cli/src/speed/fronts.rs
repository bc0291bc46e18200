//! Pareto fronts of the trade: per scene and reference level, which variants are not beaten
//! in both instructions (QEMU) and maximum error (against that level's exact model).
//!
//! A *set* is one scene measured against one level (the scene's required level and the levels
//! below it that it carries parameters for), or a kernel's own grid. Its members are every
//! variant measured in it, in every numeric form. A variant on no front of any set it belongs
//! to is *dominated on every scene*.

use sonolube::variant::{CATALOGUE, Family, Fidelity, Variant};

use super::errors::Errors;
use super::qemu::Counts;
use crate::plot::pareto_front;

/// One set of competing variants.
#[derive(Debug, Clone, PartialEq)]
pub struct Set {
    /// Scene name, or the kernel's name for a kernel grid.
    pub scene: &'static str,
    /// The level the errors are measured against.
    pub reference: Fidelity,
    /// Members: variant, instructions, maximum error.
    pub members: Vec<(&'static Variant, f64, f64)>,
    /// Indices into `members` of the front, by increasing instructions.
    pub front: Vec<usize>,
}

impl Set {
    /// Whether `variant` is on this set's front.
    pub fn on_front(&self, variant: &str) -> bool {
        self.front
            .iter()
            .any(|&i| self.members[i].0.name == variant)
    }

    /// Front members that break the front's defining property: a front member must be the
    /// fastest of the members at most as inaccurate, and the most accurate of the members at
    /// most as costly. Empty when the front is right.
    pub fn violations(&self) -> Vec<&'static str> {
        self.front
            .iter()
            .map(|&i| self.members[i])
            .filter(|&(_, cost, error)| {
                let faster_as_good = self
                    .members
                    .iter()
                    .any(|&(_, c, e)| e.is_finite() && e <= error && c < cost);
                let better_as_cheap = self.members.iter().any(|&(_, c, e)| c <= cost && e < error);
                faster_as_good || better_as_cheap
            })
            .map(|(v, _, _)| v.name)
            .collect()
    }
}

/// Every set of a run, kernels first, then scenes in the errors' order.
pub fn sets(errors: &Errors, counts: &Counts) -> Vec<Set> {
    let cost = |v: &Variant| counts.get(v.name).map_or(f64::NAN, |c| c.instructions);
    let mut sets = Vec::new();
    for kernel in [Fidelity::Littmann, Fidelity::DahlUpdate] {
        let members = CATALOGUE
            .iter()
            .filter(|v| v.fidelity == kernel)
            .filter_map(|v| Some((v, cost(v), errors.own(v.name)?.max)))
            .collect();
        sets.push(finish(kernel.name(), kernel, members));
    }
    let mut keys: Vec<(&'static str, Fidelity)> = Vec::new();
    for e in &errors.scenes {
        if !keys.contains(&(e.scene, e.reference)) {
            keys.push((e.scene, e.reference));
        }
    }
    for (scene, reference) in keys {
        let members = errors
            .scenes
            .iter()
            .filter(|e| e.scene == scene && e.reference == reference)
            .map(|e| (e.variant, cost(e.variant), e.stats.max))
            .collect();
        sets.push(finish(scene, reference, members));
    }
    sets
}

fn finish(
    scene: &'static str,
    reference: Fidelity,
    members: Vec<(&'static Variant, f64, f64)>,
) -> Set {
    let xy: Vec<(f64, f64)> = members.iter().map(|&(_, c, e)| (c, e)).collect();
    Set {
        scene,
        reference,
        front: pareto_front(&xy),
        members,
    }
}

/// How a variant fares across the sets it belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Standing {
    /// On the front of this many of its sets (of `of`).
    Front {
        /// Sets where it is on the front.
        fronts: usize,
        /// Sets it belongs to.
        of: usize,
    },
    /// In some sets, on no front: dominated on every scene.
    Dominated {
        /// Sets it belongs to.
        of: usize,
    },
    /// In no set (never measured against a scene).
    Unranked,
}

/// The standing of `variant` across `sets`.
pub fn standing(sets: &[Set], variant: &Variant) -> Standing {
    let of = sets
        .iter()
        .filter(|s| s.members.iter().any(|m| m.0.name == variant.name))
        .count();
    let fronts = sets.iter().filter(|s| s.on_front(variant.name)).count();
    match (of, fronts) {
        (0, _) => Standing::Unranked,
        (of, 0) => Standing::Dominated { of },
        (of, fronts) => Standing::Front { fronts, of },
    }
}

/// Whether a set belongs to the kernels.
pub fn is_kernel(set: &Set) -> bool {
    set.reference.family() == Family::Kernel
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::variant::find;

    #[test]
    fn fronts_minimise_both_and_standings_follow() {
        let v = |name| find(name).unwrap();
        let set = finish(
            "s",
            Fidelity::CubeElasticPlastic,
            vec![
                (v("cube ep N=4"), 600.0, 1e-2),
                (v("cube ep N=8"), 900.0, 1e-4),
                (v("cube ep N=8 f64"), 15000.0, 1e-4),
                (v("cube ep N=16"), 1500.0, 1e-6),
                (v("cube ep N=16 f32 libm"), 650.0, 1e-6),
                (v("cube ep N=32 f64"), 50000.0, f64::INFINITY),
            ],
        );
        let names: Vec<&str> = set.front.iter().map(|&i| set.members[i].0.name).collect();
        assert_eq!(names, ["cube ep N=4", "cube ep N=16 f32 libm"]);
        assert!(set.violations().is_empty());
        // A wrong front is caught.
        let mut wrong = set.clone();
        wrong.front.push(1);
        assert_eq!(wrong.violations(), ["cube ep N=8"]);
        let sets = [set];
        assert_eq!(
            standing(&sets, v("cube ep N=4")),
            Standing::Front { fronts: 1, of: 1 }
        );
        assert_eq!(
            standing(&sets, v("cube ep N=8 f64")),
            Standing::Dominated { of: 1 }
        );
        assert_eq!(standing(&sets, v("cube el N=4")), Standing::Unranked);
    }
}
