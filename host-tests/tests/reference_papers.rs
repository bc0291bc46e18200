//! Every paper case of `sonolube_host::papers` against the reference model: the model value
//! must match `expected` within the case's tolerance, and the stated agreement with the
//! printed number (reproduced / differs) must hold. A wrong formula, constant or protocol
//! breaks these (e.g. the steady-state Dahl value in place of the switch-on window, or the
//! exact Littmann law in place of the sampled one, misses by more than 0.5 points).

use std::collections::BTreeSet;

use sonolube_host::papers::{Agreement, PAPER_CASES, Quantity, Tolerance};
use sonolube_host::reference::MODELS;

#[test]
fn every_case_matches_its_expected_model_value() {
    let mut failures = Vec::new();
    for case in PAPER_CASES {
        match case.model_value() {
            Ok(value) if case.tolerance.accepts(value, case.expected) => {}
            Ok(value) => failures.push(format!(
                "{}: model {value:.12e}, expected {:.12e} ({:?})",
                case.id, case.expected, case.tolerance
            )),
            Err(error) => failures.push(format!("{}: {error}", case.id)),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_case_states_its_agreement_with_the_paper_truthfully() {
    let mut failures = Vec::new();
    for case in PAPER_CASES {
        let value = case.model_value().expect("model value");
        let (claim_holds, claim) = match (case.agreement, case.paper_value) {
            (Agreement::Reproduces(tolerance), Some(paper)) => {
                (tolerance.accepts(value, paper), "reproduces")
            }
            (Agreement::Differs(tolerance), Some(paper)) => {
                (!tolerance.accepts(value, paper), "differs")
            }
            (Agreement::NoPrintedValue, None) => (true, "no printed value"),
            _ => (false, "agreement inconsistent with paper_value"),
        };
        if !claim_holds {
            failures.push(format!(
                "{}: claim `{claim}` false (model {value:e}, paper {:?})",
                case.id, case.paper_value
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn cases_are_well_formed() {
    let mut ids = BTreeSet::new();
    for case in PAPER_CASES {
        assert!(ids.insert(case.id), "duplicate id {}", case.id);
        assert!(MODELS.contains(&case.evaluation.model), "{}", case.id);
        assert!(
            case.source.contains("seed") || case.source.contains("physics-notes"),
            "{}: source must cite a seed or physics-notes",
            case.id
        );
        assert!(
            !case.note.is_empty() && !case.printed.is_empty(),
            "{}",
            case.id
        );
        let tight = match case.tolerance {
            Tolerance::Abs(amount) => amount <= 1e-6 * case.expected.abs().max(1.0),
            Tolerance::Rel(fraction) => fraction <= 1e-6,
        };
        assert!(tight, "{}: model tolerance must be tight", case.id);
        if let Quantity::MinusOther(other) | Quantity::OverOther(other) = case.quantity {
            assert!(MODELS.contains(&other.model), "{}", case.id);
        }
    }
    assert!(PAPER_CASES.len() >= 40);
}

/// The two Coulomb protocols of seed 003 are different numbers; the paper's column is the
/// sampled one (physics-notes §1), and the Dahl column is the window, not the steady state
/// (physics-notes §2). Guards against swapping protocols in the table.
#[test]
fn protocols_are_not_confused() {
    let value = |id: &str| {
        let case = PAPER_CASES.iter().find(|case| case.id == id).expect(id);
        case.model_value().expect(id)
    };
    let sampled = value("s003-t2-coulomb-sampled");
    let exact = value("s003-t2-coulomb-exact");
    assert!((sampled - 63.21).abs() < (exact - 63.21).abs());
    assert!((sampled - exact).abs() > 0.5);
    for load in ["0N", "2N", "5N", "10N"] {
        let window = value(&format!("s003-t2-dahl-window-{load}"));
        let steady = value(&format!("notes-dahl-steady-{load}"));
        assert!((24.6..=24.9).contains(&steady), "steady {steady}");
        assert!(
            window < steady,
            "{load}: window {window} vs steady {steady}"
        );
    }
    // Window values fall with load (paper: "decreases with an increase in normal load").
    let windows: Vec<f64> = ["0N", "2N", "5N", "10N"]
        .iter()
        .map(|load| value(&format!("s003-t2-dahl-window-{load}")))
        .collect();
    assert!(windows.windows(2).all(|pair| pair[1] < pair[0]));
}
