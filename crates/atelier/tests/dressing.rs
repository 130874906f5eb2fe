//! Dressing by sewing on the mannequin (thesis §5.6): the dress's three skirt panels wrapped
//! on a cone around the 9AR mannequin's hips, sewn with gravity off, then left to hang — every pair sewn,
//! no node inside the body at any step, nothing non-finite.

use std::path::PathBuf;

use atelier::{Chain, GarmentCloth, Sewing, SewingParams};
use atelier_collide::ContactParams;
use atelier_collide::distance::BodyDistance;
use atelier_fabric::{AnisotropyForm, Fabric, STANDARD_GRAVITY};
use atelier_grid::ImproveParams;
use atelier_grid::pattern::load_garment;
use atelier_solver::{BodyContact, ClothState, Solver, StepParams};
use nalgebra::Vector3;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
#[ignore = "issue 7, not working yet: without the body the side and centre-back seams sew in about 200 steps but the four darts do not close (legs stay 1-6 cm apart; closing a dart needs the cloth around its apex to compress or shear, which the solver's locked six-constraint cells forbid, the open problem of issue 3); with the body the right side seam also stays open by up to 12 cm after 300 steps"]
fn the_skirt_is_sewn_around_the_mannequin_and_hangs_without_entering_it() {
    let garment = load_garment(
        &root().join("fixtures/patterns/dress/skirt.ron"),
        ImproveParams::default(),
    )
    .expect("garment");
    let fabric = Fabric::load(&root().join("fixtures/fabrics/cotton_broad.ron")).expect("fabric");
    let g = GarmentCloth::new(&garment, &fabric, AnisotropyForm::PlateTheory).expect("cloth");
    let mannequin = atelier_body::build::jis_9ar();
    let body = mannequin.labelled_mesh();
    // Wrap the panels on a cone around the body's axis, the waist edge at the body's waist level
    // (0.98 m): at each height the circle is 5 % longer than the three panels are wide there (79
    // cm at the waist with the dart openings, 111 cm at the hem), the front in front and the back
    // halves behind; each pattern's x becomes arc length on its circle.
    let radius = |y: f64| (0.79 + (1.11 - 0.79) * (-y / 0.6)) / (2.0 * std::f64::consts::PI) * 1.05;
    let waist = 0.98;
    let rest: Vec<[f64; 2]> = g.cloth.topology().rest_positions().to_vec();
    let mut state = ClothState::placed(&g.cloth, |p: [f64; 2]| Vector3::new(p[0], p[1], 0.0));
    let first_back = g.offsets[1] as usize;
    for (i, (x, q)) in state.positions.iter_mut().zip(&rest).enumerate() {
        let r = radius(q[1]);
        let (a, y) = (q[0] / r, waist + q[1]);
        *x = if i < first_back {
            Vector3::new(r * a.sin(), y, r * a.cos())
        } else {
            Vector3::new(-r * a.sin(), y, -r * a.cos())
        };
    }
    let mut sewing = Sewing::new(g.pairs.clone(), SewingParams::default());
    let mut contact = BodyContact::new(&g.cloth, ContactParams::default()).expect("contact");
    let dt = 0.01;
    contact
        .set_body(&body.vertices, &body.vertices, &body.triangles, dt)
        .expect("body");
    let inside: Vec<BodyDistance> = mannequin
        .parts
        .iter()
        .map(|p| BodyDistance::new(&p.vertices, &p.triangles).expect("closed part"))
        .collect();
    let mut params = StepParams {
        dt,
        gravity: [0.0, 0.0, 0.0],
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let (mut sewn_at, mut worst) = (None, 0.0f64);
    for step in 0..300 {
        {
            let mut hooks = Chain(vec![&mut sewing, &mut contact]);
            solver
                .step_with(&g.cloth, &mut state, &params, &mut hooks)
                .unwrap_or_else(|e| panic!("step {step}: {e}"));
        }
        for d in &inside {
            for p in &state.positions {
                worst = worst.max(-d.signed_distance(p));
            }
        }
        if sewn_at.is_none() && sewing.done() {
            sewn_at = Some(step);
            params.gravity = [0.0, -STANDARD_GRAVITY, 0.0];
        }
        if sewn_at.is_some_and(|s| step > s + 100) {
            break;
        }
    }
    let sewn_at = sewn_at.unwrap_or_else(|| {
        let open: Vec<String> = sewing
            .unsewn()
            .iter()
            .map(|&k| {
                let (a, b) = g.pairs[k];
                format!(
                    "{} ({:.3} m)",
                    g.pair_names[k],
                    (state.positions[a as usize] - state.positions[b as usize]).norm()
                )
            })
            .collect();
        panic!("sewn {:?}; open: {open:?}", sewing.progress())
    });
    eprintln!(
        "sewn after {sewn_at} steps; deepest node inside the body {:.2} mm",
        worst * 1e3
    );
    assert!(
        state
            .positions
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite()))
    );
    assert!(sewing.largest_gap(&state.positions) < 1e-6);
    assert!(
        worst < 2e-3,
        "a node went {:.1} mm into the body",
        worst * 1e3
    );
    // The skirt hangs on the hips: its waist edge came down and in from the wrap.
    let waist_nodes = state.positions.iter().filter(|p| p.y > 0.9).count();
    assert!(waist_nodes > 0);
}
