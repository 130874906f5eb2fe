//! The string method carried over to cloth, first part (`docs/fit.md`): a fabric's bending
//! rigidity per direction recovered from the cantilever profile the PARTY solver gives for it,
//! the fabric's own value hidden from the fit (only the overhang, the weight per area and the
//! centreline's points are used), and how the recovered value degrades with noise on the points.

use std::path::PathBuf;

use atelier::scenario::Scenario;
use atelier_fabric::AnisotropyForm;
use atelier_fabric::Fabric;
use atelier_fabric::noise::Rng;
use atelier_fit::cloth::{ProfilePoint, fit_cantilever};
use atelier_fit::turned::{TurnedProfile, fit_turned};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepParams};
use nalgebra::Vector3;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("repository root")
}

/// The simulated cantilever of `fabric` along `direction` (40 cells, the default overhang
/// 2.0003·c): its centreline's free points with their arc lengths, and the overhang.
fn profile(fabric: &str, direction: &str) -> (Vec<ProfilePoint>, f64) {
    let text = format!(
        r#"(
    name: "c",
    reproduces: "cantilever for the bending fit (test)",
    kind: Cantilever(fabric: "{}/fixtures/fabrics/{fabric}.ron", direction: {direction}, segments: 40),
)"#,
        root().display()
    );
    let scenario = Scenario::parse(&text, "c.ron".as_ref()).expect("scenario");
    let sim = atelier::run::simulate(&scenario, &root(), &mut |_| {}).expect("runs");
    assert!(
        sim.failure.is_none(),
        "{fabric} {direction}: {:?}",
        sim.failure
    );
    if !sim.warnings.is_empty() {
        eprintln!("{fabric} {direction}: {:?}", sim.warnings);
    }
    let last = sim.cloth.frames.last().expect("a frame");
    let nv = last.len() / 2;
    let length = sim.metrics["overhang_m"].expect("overhang");
    let h = length / ((nv - 2) as f64 + 0.5);
    // Output frame: y up; the strip runs along +x from the platform edge.
    let points = (1..nv)
        .map(|j| {
            let (a, b) = (last[2 * j], last[2 * j + 1]);
            ProfilePoint {
                s: ((j as f64 - 0.5) * h).min(length),
                x: 0.5 * (a[0] + b[0]),
                droop: -0.5 * (a[1] + b[1]),
            }
        })
        .collect();
    (points, length)
}

/// Cotton broad (published, B the same both ways) and silk (banded, weft 25 % softer than
/// warp), warp and weft: the bending rigidity fitted to the simulated profile is within 6 % of
/// the fabric's (the solver's own cantilever error — its strip droops a little more than the
/// elastica at 40 cells — shows up cubed in B = w·c³); with 0.5 mm of noise on every point the
/// mean error over 10 draws stays within 8 %; bias and spread at 0.5, 1 and 2 mm are printed for
/// docs/fit.md.
#[test]
fn bending_rigidity_is_recovered_from_cantilever_profiles() {
    for fabric in ["cotton_broad", "silk"] {
        let f =
            Fabric::load(&root().join(format!("fixtures/fabrics/{fabric}.ron"))).expect("fabric");
        for direction in ["Warp", "Weft"] {
            let hidden = if direction == "Warp" {
                f.bending.warp.rigidity()
            } else {
                f.bending.weft.rigidity()
            };
            let (points, length) = profile(fabric, direction);
            let w = f.weight_per_area();
            let b = |c: f64| w * c.powi(3);
            let fit = fit_cantilever(&points, length).expect("fit");
            let error = b(fit.bending_length) / hidden - 1.0;
            let mut line = format!(
                "{fabric} {direction}: B {:.4e} N·m against {:.4e} ({:+.2} %), RMS {:.3} mm",
                b(fit.bending_length),
                hidden,
                100.0 * error,
                fit.rms * 1e3
            );
            assert!(error.abs() < 0.06, "{line}");
            for (k, sigma) in [0.5e-3, 1e-3, 2e-3].iter().enumerate() {
                // Mean |error| over 10 noise draws.
                let mut errors = Vec::new();
                for seed in 0..10 {
                    let mut noise = Rng::new(100 * k as u64 + seed);
                    let noisy: Vec<ProfilePoint> = points
                        .iter()
                        .map(|p| ProfilePoint {
                            x: p.x + sigma * noise.normal(),
                            droop: p.droop + sigma * noise.normal(),
                            ..*p
                        })
                        .collect();
                    let fit = fit_cantilever(&noisy, length).expect("fit");
                    errors.push(b(fit.bending_length) / hidden - 1.0);
                }
                let mean = errors.iter().sum::<f64>() / 10.0;
                let spread = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / 9.0).sqrt();
                line.push_str(&format!(
                    "; σ {:.1} mm: {:+.2} ± {:.2} %",
                    sigma * 1e3,
                    100.0 * mean,
                    100.0 * spread
                ));
                if k == 0 {
                    assert!(mean.abs() < 0.08, "{line}");
                }
            }
            eprintln!("{line}");
        }
    }
}

/// `atelier fit` (the library call behind it): cotton broad's simulated warp and weft profiles
/// written as a `ClothObservations` file against the fixture as base; the fabric.ron it writes
/// reads back with both B within 6 % of cotton broad's and its 2HB untouched, fit_report.json
/// lists both directions; a second profile of one direction is refused with its position, and
/// nothing is written then.
#[test]
fn atelier_fit_writes_a_fabric_with_the_fitted_rigidity() {
    let dir = std::env::temp_dir().join(format!("atelier-fit-cloth-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let base = root().join("fixtures/fabrics/cotton_broad.ron");
    let cotton = Fabric::load(&base).expect("fabric");
    let mut entries = Vec::new();
    for direction in ["Warp", "Weft"] {
        let (points, length) = profile("cotton_broad", direction);
        let pts: Vec<String> = points
            .iter()
            .map(|p| format!("({}, {}, {})", p.s, p.x, p.droop))
            .collect();
        entries.push(format!(
            "(direction: {direction}, overhang: {length}, points: [{}])",
            pts.join(", ")
        ));
    }
    let observations = |cantilevers: &str| {
        format!(
            r#"ClothObservations(
    name: "cotton strips",
    provenance: "the PARTY solver's cantilevers of cotton broad (test)",
    base: "{}",
    cantilevers: [{cantilevers}],
)"#,
            base.display()
        )
    };
    let file = dir.join("obs.ron");
    std::fs::write(&file, observations(&entries.join(", "))).expect("write");
    let out = dir.join("out");
    let report = atelier::fit::fit_cloth(&file, &out).expect("fits");
    assert_eq!(report.fits.len(), 2);
    let fitted = Fabric::load(&out.join("fabric.ron")).expect("the fitted fabric reads back");
    for (got, want) in [
        (
            fitted.bending.warp.rigidity(),
            cotton.bending.warp.rigidity(),
        ),
        (
            fitted.bending.weft.rigidity(),
            cotton.bending.weft.rigidity(),
        ),
    ] {
        assert!((got / want - 1.0).abs() < 0.06, "{got} vs {want}");
    }
    let m0 = |f: &Fabric| f.bending.warp.residual_moment();
    assert!(
        (m0(&fitted) / m0(&cotton) - 1.0).abs() < 1e-12,
        "2HB changed"
    );
    assert!(out.join("fit_report.json").is_file());
    // Two warp profiles: refused, naming the second, nothing written.
    let bad = dir.join("bad.ron");
    std::fs::write(
        &bad,
        observations(&format!("{}, {}", entries[0], entries[0])),
    )
    .expect("write");
    let e = atelier::fit::fit_cloth(&bad, &dir.join("bad_out")).expect_err("refused");
    let msg = e.to_string();
    assert!(
        msg.contains("cantilevers[1].direction") && msg.contains("bad.ron:"),
        "{msg}"
    );
    assert!(!dir.join("bad_out").exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// The turned cantilever in the PARTY solver, hysteresis on: the strip of the Cantilever
/// scenario (`segments` cells, overhang 2.0003·c, 1 cm wide, clamped by its first two rows)
/// laid out straight, gravity applied over 1 s, then the clamp turned downwards about the
/// platform edge at 45°/s, holding at each of `angles` until every node is slower than 1 mm/s;
/// the centreline's free points in the fixed frame at each hold. The shape tolerance is
/// 1e-8 m (the default 1e-6 m, at this Δt = 0.25·h, leaves the nodes jittering at cm/s).
fn turned(
    fabric: &Fabric,
    weft: bool,
    segments: usize,
    angles: &[f64],
) -> (Vec<TurnedProfile>, f64) {
    let b = if weft {
        fabric.bending.weft.rigidity()
    } else {
        fabric.bending.warp.rigidity()
    };
    let length = 2.0003 * (b / fabric.weight_per_area()).cbrt();
    let h = length / (segments as f64 + 0.5);
    let nv = segments + 2;
    let mut grid = StructuredGrid::sheet(2, nv, 0.01, (nv - 1) as f64 * h);
    if weft {
        grid.grain_angle = 0.0;
    }
    let topo = ClothTopology::from_structured(&grid).expect("grid");
    let mut cloth = Cloth::new(topo, fabric, AnisotropyForm::Thesis).expect("cloth");
    let place = |[x, y]: [f64; 2]| Vector3::new(y - 0.5 * h, x, 0.0);
    let rest = cloth.topology().rest_positions().to_vec();
    let clamp = |cloth: &mut Cloth, beta: f64| {
        for (node, &r) in rest.iter().enumerate().take(4) {
            let p = place(r);
            let q = Vector3::new(p.x * beta.cos(), p.y, -p.x * beta.sin());
            cloth.pin(node as u32, q, PinMotion::Fixed).expect("pin");
        }
    };
    clamp(&mut cloth, 0.0);
    let mut state = ClothState::placed(&cloth, place);
    let mut params = StepParams {
        dt: 0.25 * h,
        damping: 5.0,
        shape_tolerance: 1e-8,
        implicit_stick_slope: true,
        ..StepParams::default()
    };
    let g = params.gravity;
    let mut solver = Solver::new();
    let rate = 45f64.to_radians();
    let mut beta = 0.0f64;
    let mut profiles = Vec::new();
    for &target in angles {
        let target = target.to_radians();
        let start = state.time;
        loop {
            let f = state.time.min(1.0);
            params.gravity = g.map(|c| c * f);
            if beta < target {
                beta = (beta + rate * params.dt).min(target);
                clamp(&mut cloth, beta);
            }
            solver.step(&cloth, &mut state, &params).expect("step");
            let fastest = state
                .velocities
                .iter()
                .map(|v| v.norm())
                .fold(0.0, f64::max);
            if f >= 1.0 && beta >= target && state.time - start > 0.5 && fastest < 1e-3 {
                break;
            }
            assert!(state.time - start < 20.0, "not at rest: {fastest} m/s");
        }
        let points = (1..nv)
            .map(|j| {
                let p = (state.positions[2 * j] + state.positions[2 * j + 1]) * 0.5;
                ProfilePoint {
                    s: ((j as f64 - 0.5) * h).min(length),
                    x: p.x,
                    droop: -p.z,
                }
            })
            .collect();
        profiles.push(TurnedProfile {
            clamp_deg: beta.to_degrees(),
            points,
        });
    }
    (profiles, length)
}

/// Bending rigidity and hysteresis together from the turned cantilever simulated by the
/// solver (hysteresis on; B and 2HB hidden: only the overhang, the weight per area and the
/// profiles at 0°, 45° and 90° are used), fitted with the quasi-static spindle strip
/// (`atelier_fit::turned`). Measured (docs/fit.md): the hysteresis explains the turned
/// profiles (RMS 3–6 times below the best elastic strip's), but the solver's discrete strip
/// at 10–16 cells is not the continuum strip — B comes out high and M₀ low, by an amount that
/// falls with refinement for wool (B +12 → +7 %, M₀ −37 → −22 % from 10 to 16 cells) and
/// hardly for cotton broad, whose loop is the widest (B about +100 %). Asserted: for wool
/// tropical at 16 cells B within 12 %, M₀ within 30 %, the hysteretic RMS a third of the
/// elastic one or less; for every case M₀ > 0 found; with 0.2 mm of noise on every point the
/// mean of five draws stays within the same bounds.
#[test]
fn bending_hysteresis_is_recovered_from_a_turned_cantilever() {
    let angles = [0.0, 45.0, 90.0];
    for (name, weft) in [
        ("wool_tropical", false),
        ("silk", false),
        ("silk", true),
        ("cotton_broad", false),
    ] {
        let f = Fabric::load(&root().join(format!("fixtures/fabrics/{name}.ron"))).expect("fabric");
        let hidden = if weft { f.bending.weft } else { f.bending.warp };
        let w = f.weight_per_area();
        let errors = |fit: &atelier_fit::turned::HysteresisFit| {
            (
                fit.rigidity / hidden.rigidity() - 1.0,
                fit.residual_moment / hidden.residual_moment() - 1.0,
            )
        };
        for segments in [10, 16] {
            let (profiles, length) = turned(&f, weft, segments, &angles);
            let fit = fit_turned(&profiles, length, w).expect("fit");
            let (eb, em) = errors(&fit);
            let mut line = format!(
                "{name} {} {segments} cells: B {:+.1} %, M0 {:+.1} %, RMS {:.3} mm (elastic {:.3} mm), set at 90° {:.2} mm, {} evaluations",
                if weft { "weft" } else { "warp" },
                100.0 * eb,
                100.0 * em,
                fit.rms * 1e3,
                fit.elastic_rms * 1e3,
                profiles[2].points.last().expect("points").x * 1e3,
                fit.evaluations,
            );
            assert!(
                fit.residual_moment > 0.05 * hidden.residual_moment(),
                "{line}"
            );
            let wool = name == "wool_tropical" && segments == 16;
            if wool {
                assert!(eb.abs() < 0.12 && em.abs() < 0.30, "{line}");
                assert!(fit.rms < fit.elastic_rms / 3.0, "{line}");
                for sigma in [0.2e-3, 0.5e-3] {
                    let mut draws = Vec::new();
                    for seed in 0..5 {
                        let mut noise = Rng::new(500 + seed);
                        let noisy: Vec<TurnedProfile> = profiles
                            .iter()
                            .map(|p| TurnedProfile {
                                points: p
                                    .points
                                    .iter()
                                    .map(|q| ProfilePoint {
                                        x: q.x + sigma * noise.normal(),
                                        droop: q.droop + sigma * noise.normal(),
                                        ..*q
                                    })
                                    .collect(),
                                ..p.clone()
                            })
                            .collect();
                        draws.push(errors(&fit_turned(&noisy, length, w).expect("fit")));
                    }
                    let n = draws.len() as f64;
                    let mean = |k: usize| {
                        draws
                            .iter()
                            .map(|d| if k == 0 { d.0 } else { d.1 })
                            .sum::<f64>()
                            / n
                    };
                    let spread = |k: usize| {
                        let m = mean(k);
                        (draws
                            .iter()
                            .map(|d| (if k == 0 { d.0 } else { d.1 } - m).powi(2))
                            .sum::<f64>()
                            / (n - 1.0))
                            .sqrt()
                    };
                    line.push_str(&format!(
                        "; σ {:.1} mm: B {:+.1} ± {:.1} %, M0 {:+.1} ± {:.1} %",
                        sigma * 1e3,
                        100.0 * mean(0),
                        100.0 * spread(0),
                        100.0 * mean(1),
                        100.0 * spread(1)
                    ));
                    if sigma < 0.3e-3 {
                        assert!(mean(0).abs() < 0.12 && mean(1).abs() < 0.30, "{line}");
                    }
                }
            }
            eprintln!("{line}");
        }
    }
}

/// `atelier fit` with a turned strip: the warp's B and 2HB replaced by the fitted values (the
/// wool strip at 16 cells: within the bias measured above), the weft's kept; a turned strip
/// observed at one angle only is refused as not identifiable, with its place, nothing written.
#[test]
fn atelier_fit_writes_the_fitted_hysteresis_of_a_turned_strip() {
    let dir = std::env::temp_dir().join(format!("atelier-fit-turned-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let base = root().join("fixtures/fabrics/wool_tropical.ron");
    let wool = Fabric::load(&base).expect("fabric");
    let (profiles, length) = turned(&wool, false, 16, &[0.0, 45.0, 90.0]);
    let text = |profiles: &[TurnedProfile]| {
        let entries: Vec<String> = profiles
            .iter()
            .map(|p| {
                let pts: Vec<String> = p
                    .points
                    .iter()
                    .map(|q| format!("({}, {}, {})", q.s, q.x, q.droop))
                    .collect();
                format!("({}, [{}])", p.clamp_deg, pts.join(", "))
            })
            .collect();
        format!(
            r#"ClothObservations(
    name: "wool turned strip",
    provenance: "the PARTY solver's turned cantilever of wool tropical (test)",
    base: "{}",
    turned: [(direction: Warp, overhang: {length}, profiles: [{}])],
)"#,
            base.display(),
            entries.join(", ")
        )
    };
    let file = dir.join("obs.ron");
    std::fs::write(&file, text(&profiles)).expect("write");
    let out = dir.join("out");
    let report = atelier::fit::fit_cloth(&file, &out).expect("fits");
    assert_eq!(report.fits[0].observation, "turned");
    let fitted = Fabric::load(&out.join("fabric.ron")).expect("the fitted fabric reads back");
    let (got, want) = (fitted.bending.warp, wool.bending.warp);
    assert!(
        (got.rigidity() / want.rigidity() - 1.0).abs() < 0.12
            && (got.residual_moment() / want.residual_moment() - 1.0).abs() < 0.30,
        "B {} against {}, M0 {} against {}",
        got.rigidity(),
        want.rigidity(),
        got.residual_moment(),
        want.residual_moment()
    );
    assert_eq!(fitted.bending.weft, wool.bending.weft);
    let bad = dir.join("bad.ron");
    let one_angle: Vec<TurnedProfile> = profiles
        .iter()
        .take(2)
        .map(|p| TurnedProfile {
            clamp_deg: 0.0,
            ..p.clone()
        })
        .collect();
    std::fs::write(&bad, text(&one_angle)).expect("write");
    let e = atelier::fit::fit_cloth(&bad, &dir.join("bad_out")).expect_err("refused");
    let msg = e.to_string();
    assert!(
        msg.contains("turned[0]") && msg.contains("not identifiable") && msg.contains("bad.ron:"),
        "{msg}"
    );
    assert!(!dir.join("bad_out").exists());
    std::fs::remove_dir_all(&dir).ok();
}
