//! Dressing by sewing: the two panels of the flared skirt, laid face to face 10 cm apart with
//! gravity off, are drawn together along both side seams until every pair is sewn; then gravity
//! starts and the sewn pairs stay together.

use std::path::PathBuf;

use atelier::{GarmentCloth, Sewing, SewingParams};
use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_grid::ImproveParams;
use atelier_grid::pattern::load_garment;
use atelier_solver::{ClothState, Solver, StepInput, StepParams};
use nalgebra::Vector3;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn the_flared_skirt_sews_itself_shut_and_stays_sewn() {
    let garment = load_garment(
        &root().join("fixtures/patterns/flared_skirt.ron"),
        ImproveParams::default(),
    )
    .expect("garment");
    let fabric = Fabric::load(&root().join("fixtures/fabrics/cotton_broad.ron")).expect("fabric");
    let g = GarmentCloth::new(&garment, &fabric, AnisotropyForm::PlateTheory).expect("cloth");
    assert_eq!(g.pairs.len(), 42, "two side seams of 21 pairs");
    // Front at z = +5 cm as drawn; back mirrored in x at z = −5 cm (its outside facing −z), so
    // the front's "side +x" meets the back's "side −x" on the same side.
    let back_start = g.offsets[1] as usize;
    let rest: Vec<[f64; 2]> = g.cloth.topology().rest_positions().to_vec();
    let mut state = ClothState::placed(&g.cloth, |p: [f64; 2]| Vector3::new(p[0], p[1], 0.0));
    for (i, (x, q)) in state.positions.iter_mut().zip(&rest).enumerate() {
        *x = if i < back_start {
            Vector3::new(q[0], q[1], 0.05)
        } else {
            Vector3::new(-q[0], q[1], -0.05)
        };
    }
    let mut sewing = Sewing::new(g.pairs.clone(), SewingParams::default());
    let params = StepParams::default();
    let mut input = StepInput::weightless(0.01);
    let mut solver = Solver::new();
    let mut sewn_at = None;
    for step in 0..400 {
        solver
            .step_with(&g.cloth, &mut state, &params, input, &mut sewing)
            .unwrap_or_else(|e| panic!("step {step}: {e}"));
        if sewn_at.is_none() && sewing.done() {
            sewn_at = Some(step);
            input.gravity = [0.0, -atelier_fabric::STANDARD_GRAVITY, 0.0];
        }
        if let Some(s) = sewn_at
            && step > s + 100
        {
            break;
        }
    }
    let sewn_at = sewn_at.unwrap_or_else(|| panic!("sewn {:?} of the pairs", sewing.progress()));
    eprintln!(
        "sewn after {sewn_at} steps; largest gap after gravity {:.2e} m",
        sewing.largest_gap(&state.positions)
    );
    assert!(sewn_at < 200, "sewing took {sewn_at} steps");
    // A hundred steps of gravity later the seams are still closed and nothing is non-finite.
    let gap = sewing.largest_gap(&state.positions);
    assert!(gap < 1e-6, "a sewn pair opened to {gap} m");
    assert!(
        state
            .positions
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite()))
    );
    // The picture of the final state: the skirt shows in both views.
    let points: Vec<[f64; 3]> = state.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    let (w, h) = (300, 400);
    let pixels =
        atelier::picture::garment_views((&points, g.cloth.topology().triangles()), None, w, h);
    let out = std::env::temp_dir().join("atelier-sewn-skirt.png");
    atelier::picture::write_png(&out, &pixels, 2 * w, h, [1.0; 3]).expect("png");
    eprintln!("picture: {}", out.display());
    // Two flat panels sewn at their edges hang as a flattened bag: wide from the front, thin
    // from the side.
    for (half, least) in [(0, 5_000), (1, 500)] {
        let cloth = (0..h)
            .flat_map(|y| (0..w).map(move |x| y * 2 * w + half * w + x))
            .filter(|&k| pixels[k].is_some())
            .count();
        assert!(cloth > least, "view {half}: {cloth} cloth pixels");
    }
    // The skirt now hangs: its lowest point fell below where it started.
    let lowest = state
        .positions
        .iter()
        .map(|p| p.y)
        .fold(f64::INFINITY, f64::min);
    let start_lowest = rest.iter().map(|q| q[1]).fold(f64::INFINITY, f64::min);
    assert!(
        lowest < start_lowest - 0.01,
        "{lowest} against {start_lowest}"
    );
}
