//! The thesis's collision claim (§5.4–5.6) on a swinging leg in a cloth tube: the staged model
//! lets no node into the leg at Δt 0.01 s.

use atelier_collide::ContactParams;
use atelier_solver::leg::{LegScene, run_leg};

use crate::common::fabric;

#[test]
fn the_staged_model_lets_no_node_into_a_swinging_leg() {
    let f = fabric("cotton_broad");
    let staged = run_leg(&LegScene::default(), &f).expect("runs");
    eprintln!("staged, dt 0.01: {staged:?}");
    // The leg does push the tube: contacts happen and the transfer moves cloth with the leg.
    assert!(
        staged.contacts > 100 && staged.transfers > 1000,
        "{staged:?}"
    );
    assert_eq!(
        staged.frames_with_penetration,
        0,
        "staged: {} frames with nodes inside, up to {} nodes, {:.1} mm deep",
        staged.frames_with_penetration,
        staged.max_inside,
        staged.max_depth * 1e3
    );
}

#[test]
#[ignore = "a measurement for docs/validation.md (about a minute): cargo test --release -- --ignored leg_measurements --nocapture"]
fn leg_measurements() {
    let f = fabric("cotton_broad");
    use atelier_collide::narrow::NarrowTest;
    for narrow in [NarrowTest::Thesis, NarrowTest::Exact] {
        for (staged, dt) in [
            (true, 0.01),
            (false, 0.01),
            (false, 0.005),
            (false, 0.002),
            (false, 0.001),
        ] {
            let scene = LegScene {
                dt,
                contact: ContactParams {
                    staged,
                    narrow,
                    ..ContactParams::default()
                },
                ..LegScene::default()
            };
            let r = run_leg(&scene, &f).expect("runs");
            eprintln!(
                "| {narrow:?} | {} | {dt} | {} | {} of {} | {} | {:.1} | {} | {:.2} | {:.2} |",
                if staged { "staged" } else { "physical" },
                r.nodes,
                r.frames_with_penetration,
                r.steps,
                r.max_inside,
                r.max_depth * 1e3,
                r.contacts,
                r.wall.as_secs_f64(),
                r.collision.as_secs_f64()
            );
        }
    }
}
