//! Dressing by sewing on the mannequin (thesis §5.6): the dress's three skirt panels placed
//! around the 9AR mannequin's hips (`atelier::place`), sewn with gravity off, then left to hang.

use std::path::PathBuf;

use atelier::place::{PlaceParams, Placement, place};
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

/// The skirt (front, back right, back left) on the mannequin, placed around the hips with the
/// waist at the body's waist line (0.98 m).
fn placed_skirt() -> (
    GarmentCloth,
    atelier_body::model::Mannequin,
    Vec<Vector3<f64>>,
) {
    let garment = load_garment(
        &root().join("fixtures/patterns/dress/skirt.ron"),
        ImproveParams::default(),
    )
    .expect("garment");
    let fabric = Fabric::load(&root().join("fixtures/fabrics/cotton_broad.ron")).expect("fabric");
    let g = GarmentCloth::new(&garment, &fabric, AnisotropyForm::PlateTheory).expect("cloth");
    let mannequin = atelier_body::build::jis_9ar();
    let body = mannequin.labelled_mesh();
    let trunk = |facing_deg: f64| Placement::Trunk {
        facing_deg,
        y0: 0.98,
        x0: 0.0,
    };
    let placed = place(
        &g,
        &[trunk(0.0), trunk(180.0), trunk(180.0)],
        &mannequin,
        &body,
        &PlaceParams::default(),
    )
    .expect("placed");
    (g, mannequin, placed)
}

fn part_distances(mannequin: &atelier_body::model::Mannequin) -> Vec<BodyDistance> {
    mannequin
        .parts
        .iter()
        .map(|p| BodyDistance::new(&p.vertices, &p.triangles).expect("closed part"))
        .collect()
}

/// The wrap keeps every node at least the clearance's worth outside the body, and keeps the
/// pattern's lengths along the wrap: on average within 1.5 % (measured 1.1 % across, 0.9 % along) (the chord of an arc is shorter than
/// the arc; the wrap's radius changes with height), at worst within 10 % (edges across a height
/// where the wrap widens, and the dart wedges' edges).
#[test]
fn the_skirt_panels_are_placed_around_the_body_outside_it() {
    let (g, mannequin, placed) = placed_skirt();
    let parts = part_distances(&mannequin);
    let nearest = placed
        .iter()
        .map(|p| {
            parts
                .iter()
                .map(|d| d.signed_distance(p))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(f64::INFINITY, f64::min);
    assert!(nearest > 0.01, "a node is {nearest} m from the body");
    let topo = g.cloth.topology();
    let errors = |kind: atelier_grid::EdgeKind| {
        let e: Vec<f64> = topo
            .edges()
            .iter()
            .filter(|e| e.kind == kind)
            .map(|e| {
                ((placed[e.b as usize] - placed[e.a as usize]).norm() / e.rest_length - 1.0).abs()
            })
            .collect();
        (
            e.iter().sum::<f64>() / e.len() as f64,
            e.iter().copied().fold(0.0, f64::max),
        )
    };
    let (u, v) = (
        errors(atelier_grid::EdgeKind::AxialU),
        errors(atelier_grid::EdgeKind::AxialV),
    );
    eprintln!(
        "nearest node {:.1} mm from the body; edge length error mean/max: u {:.2}/{:.2} %, v {:.2}/{:.2} %",
        nearest * 1e3,
        u.0 * 100.0,
        u.1 * 100.0,
        v.0 * 100.0,
        v.1 * 100.0
    );
    assert!(
        u.0 < 0.015 && v.0 < 0.015,
        "mean errors u {}, v {}",
        u.0,
        v.0
    );
    assert!(
        u.1 < 0.1 && v.1 < 0.1,
        "largest errors u {}, v {}",
        u.1,
        v.1
    );
}

#[test]
#[ignore = "issue 7, not working yet: every pair is sewn after 57 steps (the darts close, no node inside the body), but within 10 steps of gravity starting the waist nodes are flung at several m/s and an edge passes strain 1 (step 68). The same happens with friction 0, restitution 0, unstaged contact, without the sewing hold after sewing, and at Δt 0.005; without the body the sewn skirt hangs stably. Suspect: the body's 17 closed part meshes overlap (1 203 of 2 832 triangles have their centroid more than 1 mm inside another part), so contact meets internal faces where the skirt's waist sits on the chest/abdomen joint; but dropping those triangles lets the skirt fall through the hips, so that is not the whole story"]
fn the_skirt_is_sewn_around_the_mannequin_and_hangs_without_entering_it() {
    let (g, mannequin, placed) = placed_skirt();
    let body = mannequin.labelled_mesh();
    let mut state = ClothState::placed(&g.cloth, |p: [f64; 2]| Vector3::new(p[0], p[1], 0.0));
    state.positions.copy_from_slice(&placed);
    let mut sewing = Sewing::new(
        g.pairs.clone(),
        SewingParams {
            threshold: 5e-3,
            ..SewingParams::default()
        },
    );
    let mut contact = BodyContact::new(&g.cloth, ContactParams::default()).expect("contact");
    let dt = 0.01;
    contact
        .set_body(&body.vertices, &body.vertices, &body.triangles, dt)
        .expect("body");
    let inside = part_distances(&mannequin);
    let mut params = StepParams {
        dt,
        gravity: [0.0, 0.0, 0.0],
        diagonal_constraint: atelier_solver::ConstraintKind::Compliant,
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
    // The skirt hangs on the hips: its waist edge stays above the hip line (0.80 m).
    assert!(state.positions.iter().any(|p| p.y > 0.9));
}
