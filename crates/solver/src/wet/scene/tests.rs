//! Tests of [`super`].

use super::*;

fn satin() -> Fabric {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/fabrics/polyester_satin_wet.ron");
    Fabric::load(&path).expect("fixture")
}

/// A PARTY run counts every step's report (0.05 s at 5 ms: 10 steps); Yamada's model has
/// none to count.
#[test]
fn party_runs_count_their_steps_reports() {
    let fabric = satin();
    let scene = WetScene {
        particles: 6,
        picks: vec![Pick {
            at: [0.5, 0.5],
            by: [0.0, 0.0, 0.01],
            start: 0.0,
            speed: 0.05,
            release: None,
        }],
        duration: 0.05,
        ..WetScene::default()
    };
    let params = WetPartyParams {
        dt: 0.005,
        ..WetPartyParams::default()
    };
    let party = run(&scene, &fabric, &WetSolver::Party(params.clone())).expect("runs");
    let stats = party.stats.expect("the PARTY step's stats");
    assert!(party.failure.is_none());
    assert_eq!((stats.steps, party.steps), (10, 10));
    assert!(stats.unconverged <= stats.steps && stats.shape_unconverged <= stats.unconverged);
    assert!(stats.worst_violation.is_finite());
    assert_eq!(
        stats.tolerance.to_bits(),
        params.step.shape.tolerance.to_bits()
    );
    let yamada = WetSolver::Yamada(YamadaParams::default());
    let short = WetScene {
        duration: 0.001,
        ..scene
    };
    assert!(run(&short, &fabric, &yamada).expect("runs").stats.is_none());
}
