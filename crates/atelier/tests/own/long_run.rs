//! Long runs (issue 10): the walking dress for 60 s does not drift — no growth of the cloth's
//! motion relative to the body, no creeping down the body, no penetration beyond the 6 s
//! scenario's bound. 1.5–3 minutes on the unconverged step; on the converged step (6 000
//! steps solved to the tolerance) more than 16 minutes, over CI's budget: ignored, run by hand
//! with `cargo test --release -p atelier --test own long_run:: -- --ignored` (docs/performance.md).

use std::path::PathBuf;

use atelier::scenario::Scenario;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("repository root")
}

fn centroid(points: &[[f64; 3]]) -> [f64; 3] {
    let n = points.len() as f64;
    let s = points
        .iter()
        .fold([0.0; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]]);
    [s[0] / n, s[1] / n, s[2] / n]
}

/// The dress of `dress_walk` (cotton broad, sewn, 1 s settle) walking for 60 s (the same gait,
/// `fixtures/motions/walk_60s.ron`: 1.1 s cycles after a 1.1 s ramp). Per 1.1 s cycle, from the
/// recorded frames (every 0.04 s): the mean square speed of the cloth's nodes relative to the
/// body's centroid, and the height of the cloth's centroid above the body's. Asserted: the
/// last five cycles' mean square speed at most 1.5 times that of cycles 2–6 (no energy
/// growth), their height within 5 mm of those cycles' (no creeping), every seam still closed,
/// and the largest penetration over the whole run within the 6 s scenario's 2 mm.
#[test]
#[ignore = "over CI's budget on the converged step (6 000 steps; unfinished after 16 min, session 8): run with -- --ignored, docs/performance.md"]
fn a_sixty_second_walk_does_not_drift() {
    let text = std::fs::read_to_string(root().join("fixtures/scenarios/dress_walk.ron"))
        .expect("scenario")
        .replace("name: \"dress_walk\"", "name: \"dress_walk_60s\"")
        .replace("../motions/walk.ron", "../motions/walk_60s.ron")
        .replace("motion_time: 6.0", "motion_time: 60.0");
    assert!(text.contains("walk_60s.ron") && text.contains("motion_time: 60.0"));
    let base = root().join("fixtures/scenarios");
    let scenario = Scenario::parse(&text, &base.join("dress_walk_60s.ron")).expect("scenario");
    let t = std::time::Instant::now();
    let sim = atelier::run::simulate(&scenario, &base, &mut |_| {}).expect("runs");
    let wall = t.elapsed().as_secs_f64();
    assert!(sim.failure.is_none(), "{:?}", sim.failure);
    let body = &sim.solid.as_ref().expect("the body").motion;
    let cloth = &sim.cloth;
    assert_eq!(
        body.times.len(),
        cloth.times.len(),
        "body and cloth frames differ"
    );
    // The walk starts after sewing and the 1 s settle: find its start as the last frame
    // before the body first moves.
    let c0 = centroid(&body.frames[0]);
    let start = body
        .frames
        .iter()
        .position(|f| {
            let c = centroid(f);
            (c[2] - c0[2]).abs() + (c[0] - c0[0]).abs() > 1e-4
        })
        .expect("the body walks");
    let t0 = body.times[start];
    let cycle = 1.1;
    let mut cycles: Vec<(f64, f64, usize)> = Vec::new(); // (Σ speed², Σ height, frames)
    for i in start..cloth.times.len() - 1 {
        let dt = cloth.times[i + 1] - cloth.times[i];
        let (b0, b1) = (centroid(&body.frames[i]), centroid(&body.frames[i + 1]));
        let vb = [0, 1, 2].map(|k| (b1[k] - b0[k]) / dt);
        let (f0, f1) = (&cloth.frames[i], &cloth.frames[i + 1]);
        let speed2 = f0
            .iter()
            .zip(f1)
            .map(|(p, q)| {
                (0..3)
                    .map(|k| ((q[k] - p[k]) / dt - vb[k]).powi(2))
                    .sum::<f64>()
            })
            .sum::<f64>()
            / f0.len() as f64;
        let height = centroid(f0)[1] - b0[1];
        let k = ((cloth.times[i] - t0) / cycle) as usize;
        if cycles.len() <= k {
            cycles.resize(k + 1, (0.0, 0.0, 0));
        }
        cycles[k].0 += speed2;
        cycles[k].1 += height;
        cycles[k].2 += 1;
    }
    let full: Vec<(f64, f64)> = cycles
        .iter()
        .filter(|c| c.2 >= 20)
        .map(|c| (c.0 / c.2 as f64, c.1 / c.2 as f64))
        .collect();
    assert!(full.len() >= 50, "{} full cycles", full.len());
    let mean = |s: &[(f64, f64)]| {
        let n = s.len() as f64;
        s.iter()
            .fold((0.0, 0.0), |a, c| (a.0 + c.0 / n, a.1 + c.1 / n))
    };
    let early = mean(&full[1..6]);
    let late = mean(&full[full.len() - 5..]);
    let line = format!(
        "60 s walk ({wall:.0} s wall, {} cycles): mean square relative speed {:.4} → {:.4} m²/s² (×{:.2}), cloth centroid {:.1} → {:.1} mm above the body's; max penetration {:.2} mm, unsewn pairs {}",
        full.len(),
        early.0,
        late.0,
        late.0 / early.0,
        early.1 * 1e3,
        late.1 * 1e3,
        sim.metrics["max_penetration_m"].unwrap_or(f64::NAN) * 1e3,
        sim.metrics["unsewn_pairs"].unwrap_or(f64::NAN)
    );
    eprintln!("{line}");
    for (k, c) in full.iter().enumerate().step_by(5) {
        eprintln!("  cycle {k}: {:.4} m²/s², {:.1} mm", c.0, c.1 * 1e3);
    }
    assert!(late.0 <= 1.5 * early.0, "energy grows: {line}");
    assert!((late.1 - early.1).abs() < 5e-3, "the dress creeps: {line}");
    assert_eq!(sim.metrics["unsewn_pairs"], Some(0.0), "{line}");
    assert!(
        sim.metrics["max_penetration_m"].expect("penetration") <= 2e-3,
        "{line}"
    );
}
