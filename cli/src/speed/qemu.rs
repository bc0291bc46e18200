//! The instruction counts of the QEMU benchmark build, read from its decoded log.
//!
//! The firmware prints one line per measurement (`board/qemu/src/bench.rs`):
//! `bench NAME: N.NNN instructions per call (C calls[, longest L])`, after defmt-print's
//! timestamp and level; the table variants' builds as `bench build NAME: ...`, the stages of
//! a control-step row as `bench stage NAME / STAGE: ...`. Other lines
//! are ignored. A name printed twice is an error, and so is a
//! catalogued variant or control step without a count (the log is from another build).

use std::collections::BTreeMap;

use sonolube::stage::Stage;
use sonolube::variant::budget::step_scene;
use sonolube::variant::{CATALOGUE, CONTROL_STEPS};

/// One measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Count {
    /// Instructions per call (mean).
    pub instructions: f64,
    /// Calls (or control steps) measured.
    pub calls: u64,
    /// Longest single call, for the control steps.
    pub longest: Option<u64>,
}

/// Counts by name.
pub type Counts = BTreeMap<String, Count>;

/// Parses one line; `None` when it is not a benchmark line.
fn parse_line(line: &str) -> Option<Result<(String, Count), String>> {
    let (_, rest) = line.split_once("bench ")?;
    let (name, rest) = rest.split_once(": ")?;
    let (number, rest) = rest.split_once(" instructions per call")?;
    let parsed = (|| {
        let instructions: f64 = number
            .trim()
            .parse()
            .map_err(|_| format!("bad count {number:?}"))?;
        let inside = rest
            .trim()
            .strip_prefix('(')
            .and_then(|r| r.strip_suffix(')'))
            .ok_or("no (C calls) after the count")?;
        let mut parts = inside.split(", ");
        let calls = parts
            .next()
            .and_then(|p| p.strip_suffix(" calls"))
            .and_then(|c| c.parse().ok())
            .ok_or("no call count")?;
        let longest = match parts.next() {
            Some(p) => Some(
                p.strip_prefix("longest ")
                    .and_then(|l| l.parse().ok())
                    .ok_or("bad longest")?,
            ),
            None => None,
        };
        if !instructions.is_finite() || instructions <= 0.0 || calls == 0 {
            return Err("count must be positive".to_string());
        }
        Ok(Count {
            instructions,
            calls,
            longest,
        })
    })();
    Some(
        parsed
            .map(|count| (name.to_string(), count))
            .map_err(|e| format!("{line:?}: {e}")),
    )
}

/// The name of a table variant's build measurement (`bench build NAME`, once per cube scene).
/// The name of a table variant's extra count: the build of a cube table (at scene start), the
/// inverse of a Dahl table (in flash: nothing to build).
pub fn table_count_name(variant: &sonolube::variant::Variant) -> String {
    if variant.fidelity.family() == sonolube::variant::Family::Cube {
        build_name(variant.name)
    } else {
        inverse_name(variant.name)
    }
}

/// The name of a fixed-point model variant's control-step count (`bench step NAME`, the
/// period budget's, `sonolube::variant::budget`).
pub fn step_name(variant: &str) -> String {
    format!("step {variant}")
}

/// Names of every control-step count of the variants (one per fixed-point model variant).
pub fn step_names() -> Vec<String> {
    CATALOGUE
        .iter()
        .filter(|v| step_scene(v).is_some())
        .map(|v| step_name(v.name))
        .collect()
}

/// The name of a Dahl table variant's inverse count (`bench inverse NAME`).
pub fn inverse_name(variant: &str) -> String {
    format!("inverse {variant}")
}

/// The name of a cube table variant's build count (`bench build NAME`).
pub fn build_name(variant: &str) -> String {
    format!("build {variant}")
}

/// The name of one stage's count in a control-step row's breakdown (`bench stage STEP /
/// STAGE`, `sonolube::stage`).
pub fn stage_name(step: &str, stage: Stage) -> String {
    format!("stage {step} / {}", stage.name())
}

/// Every control step broken down by stage: the control-step rows, then the variants' steps
/// (`step NAME`).
pub fn staged_steps() -> Vec<String> {
    CONTROL_STEPS
        .iter()
        .map(|c| c.0.to_string())
        .chain(step_names())
        .collect()
}

/// Names of every stage count of [`staged_steps`].
pub fn stage_names() -> Vec<String> {
    staged_steps()
        .iter()
        .flat_map(|step| Stage::ALL.iter().map(|&stage| stage_name(step, stage)))
        .collect()
}

/// Every count of a log. Errors: a malformed benchmark line, a name twice, or a catalogued
/// variant or control step missing.
pub fn parse(log: &str) -> Result<Counts, String> {
    let mut counts = Counts::new();
    for line in log.lines() {
        if let Some(parsed) = parse_line(line) {
            let (name, count) = parsed?;
            if counts.insert(name.clone(), count).is_some() {
                return Err(format!("{name}: measured twice"));
            }
        }
    }
    let builds: Vec<String> = CATALOGUE
        .iter()
        .filter(|v| v.table > 0)
        .map(table_count_name)
        .collect();
    let steps = step_names();
    let stages = stage_names();
    let expected = CATALOGUE
        .iter()
        .map(|v| v.name)
        .chain(CONTROL_STEPS.iter().map(|c| c.0))
        .chain(builds.iter().map(String::as_str))
        .chain(steps.iter().map(String::as_str))
        .chain(stages.iter().map(String::as_str));
    let missing: Vec<&str> = expected.filter(|n| !counts.contains_key(*n)).collect();
    if !missing.is_empty() {
        return Err(format!(
            "no instruction count for {} (a log of another build?)",
            missing.join(", ")
        ));
    }
    Ok(counts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn full_log() -> String {
        let mut log = String::from("0.000000 INFO  sonolube 0.1.0 on qemu\n");
        for (i, v) in CATALOGUE.iter().enumerate() {
            log.push_str(&format!(
                "0.5{i:05} INFO  bench {}: {}.250 instructions per call (264 calls)\n",
                v.name,
                100 + i
            ));
        }
        for v in CATALOGUE.iter().filter(|v| v.table > 0) {
            log.push_str(&format!(
                "0.9 INFO  bench {}: 356000.500 instructions per call (3 calls)\n",
                table_count_name(v)
            ));
        }
        for (name, _, _, _) in CONTROL_STEPS {
            log.push_str(&format!(
                "1.0 INFO  bench {name}: 2764.320 instructions per call (250 calls, longest 3040)\n"
            ));
        }
        for name in step_names() {
            log.push_str(&format!(
                "1.1 INFO  bench {name}: 2764.320 instructions per call (250 calls, longest 3040)\n"
            ));
        }
        for name in stage_names() {
            log.push_str(&format!(
                "1.2 INFO  bench {name}: 300.500 instructions per call (250 calls)\n"
            ));
        }
        log
    }

    #[test]
    fn parses_every_line_and_requires_every_name() {
        let counts = parse(&full_log()).unwrap();
        let tables = CATALOGUE.iter().filter(|v| v.table > 0).count();
        assert!(tables > 0);
        assert_eq!(
            counts.len(),
            CATALOGUE.len()
                + CONTROL_STEPS.len()
                + tables
                + step_names().len()
                + (CONTROL_STEPS.len() + step_names().len()) * Stage::ALL.len()
        );
        let name = stage_name(&step_name("Dahl steady T=49x73"), Stage::Inverse);
        assert_eq!(name, "stage step Dahl steady T=49x73 / inverse");
        assert!(counts.contains_key(&name));
        let no_stage = full_log().replace("bench stage control step / inverse:", "bench other:");
        assert!(
            parse(&no_stage)
                .unwrap_err()
                .contains("stage control step / inverse")
        );
        assert_eq!(counts["build cube ep T=17x17"].calls, 3);
        let no_build = full_log().replace("bench build cube ep T=9x9:", "bench other:");
        assert!(
            parse(&no_build)
                .unwrap_err()
                .contains("build cube ep T=9x9")
        );
        let c = counts["cube ep N=16"];
        assert_eq!(c.calls, 264);
        assert!(c.instructions > 100.0 && c.longest.is_none());
        let step = counts["control step"];
        assert_eq!(
            (step.instructions, step.calls, step.longest),
            (2764.32, 250, Some(3040))
        );
        let missing = full_log().replace("bench cube ep N=16:", "bench other:");
        assert!(parse(&missing).unwrap_err().contains("cube ep N=16"));
        let twice = format!("{}{}", full_log(), full_log().lines().nth(1).unwrap());
        assert!(parse(&twice).unwrap_err().contains("twice"));
        let bad = full_log().replace("101.250 instructions", "x instructions");
        assert!(parse(&bad).is_err());
        assert!(parse("").is_err());
    }
}
