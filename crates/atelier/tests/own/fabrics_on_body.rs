//! Issue 21, item 7: fabrics tell apart on the body. The same garment sewn in silk, cotton broad
//! and denim must hang as the fabrics differ: its hem's width in the front view
//! (`metrics::hem_extent`, the report's `hem_width_m`) orders with the fabrics' bending length
//! c = (B/W)^⅓ (warp), which the test reads from the fabric files, not from a list.
//!
//! - The dress's skirt alone, at the defaults: ordered (the assertion).
//! - The whole dress with bending hysteresis off: ordered (the assertion).
//! - The whole dress at the defaults is the goal and is **missed**: cotton broad's hem
//!   ends wider than denim's (50.0 against 49.2 cm, silk 46.2). Measured: with bending hysteresis
//!   off denim's hem is 1.3 cm wider (50.5) and cotton's hardly moves (49.9). Likely (not
//!   isolated by a run of its own): the spindle holds the curvature the sewing left wherever
//!   gravity's moment stays inside it (denim's half-width HB, 0.3 gf·cm/cm = 2.9 mN·m/m, is 3.5
//!   times the moment of its lowest 5 cm hanging 10° off the vertical, W·L²/2·sin 10° = 0.85
//!   mN·m/m). And even without it cotton and denim differ by 0.6 cm: the dress's slight A-line (4
//!   cm of flare per side seam) leaves the fabric little to decide. Kept as an ignored test
//!   stating the goal; `docs/validation.md`, "Item 7".

use std::path::{Path, PathBuf};

use atelier::pipeline::run_garment;
use atelier::scenario::{Scenario, ScenarioKind};
use atelier_fabric::{AnisotropyForm, Fabric};
use atelier_solver::metrics::{HEM_BAND, hem_extent};

fn scenarios() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios")
}

/// The three fabrics of the issue, by fixture file.
const FABRICS: [&str; 3] = ["silk", "cotton_broad", "denim"];

/// Fastest a garment at rest may still move, m/s (root mean square over its nodes between the
/// last two recorded frames).
const AT_REST: f64 = 0.01;

/// Time under gravity after sewing, s: the scenarios' 1 s leaves the hems swinging at 3–14 mm/s.
const SETTLE: f64 = 3.0;

/// Largest share of steps above the tolerance (issue 21, item 1).
const UNCONVERGED: f64 = 0.01;

struct Hung {
    fabric: &'static str,
    bending_length: f64,
    hem_width: f64,
    hem_depth: f64,
}

/// `scenario` with its fabric replaced by `fabric` and bending hysteresis `hysteresis`, run
/// sewn and settled for [`SETTLE`]: the hem's extents, checked converged and at rest.
fn hang(scenario: &str, fabric: &'static str, hysteresis: bool) -> Hung {
    let s = Scenario::load(&scenarios().join(format!("{scenario}.ron"))).expect("scenario");
    let ScenarioKind::Garment(mut spec) = s.kind else {
        panic!("{scenario} is a garment scenario")
    };
    spec.fabric = Path::new("../fabrics").join(format!("{fabric}.ron"));
    spec.settings.step.hysteresis = hysteresis;
    spec.settings.settle = SETTLE;
    let run = run_garment(&spec, &scenarios(), &mut |_| {}).expect("runs");
    assert_eq!(
        run.failure, None,
        "{scenario} in {fabric}: {:?}",
        run.warnings
    );
    assert_eq!(
        run.pairs.0, run.pairs.1,
        "{scenario} in {fabric}: every pair sewn"
    );
    let c = &run.convergence;
    let unconverged = c.unconverged_steps.expect("reported") as f64 / c.steps as f64;
    assert!(
        unconverged <= UNCONVERGED,
        "{scenario} in {fabric}: {:.1} % of {} steps above the tolerance",
        100.0 * unconverged,
        c.steps
    );
    let speed = run.final_rms_speed().expect("two frames recorded");
    let last = run.frames.last().expect("frames recorded");
    assert!(
        speed < AT_REST,
        "{scenario} in {fabric} still moves at {:.1} mm/s (rms) at the end",
        speed * 1e3
    );
    let hem = hem_extent(&last.cloth, HEM_BAND).expect("finite");
    let loaded = Fabric::load(&scenarios().join(&spec.fabric)).expect("fabric");
    let hung = Hung {
        fabric,
        bending_length: loaded
            .bending_length(0.0, AnisotropyForm::default())
            .expect("bending length"),
        hem_width: hem.width,
        hem_depth: hem.depth,
    };
    eprintln!(
        "{scenario:10} {fabric:13} c {:.2} cm  hem width {:.1} cm  depth {:.1} cm  rms speed {:.2} mm/s  {} of {} steps unconverged",
        hung.bending_length * 100.0,
        hung.hem_width * 100.0,
        hung.hem_depth * 100.0,
        speed * 1e3,
        c.unconverged_steps.unwrap_or(0),
        c.steps
    );
    hung
}

/// The hems sorted by the fabrics' bending length must be sorted by width, strictly.
fn assert_orders(what: &str, mut hung: Vec<Hung>) {
    hung.sort_by(|a, b| a.bending_length.total_cmp(&b.bending_length));
    let table: Vec<String> = hung
        .iter()
        .map(|h| {
            format!(
                "{} (c {:.2} cm): {:.1} cm",
                h.fabric,
                h.bending_length * 100.0,
                h.hem_width * 100.0
            )
        })
        .collect();
    assert!(
        hung.windows(2).all(|w| w[0].hem_width < w[1].hem_width),
        "{what}: the hem's width does not order with the bending length: {}",
        table.join(", ")
    );
}

fn all(scenario: &str, hysteresis: bool) -> Vec<Hung> {
    FABRICS
        .iter()
        .map(|f| hang(scenario, f, hysteresis))
        .collect()
}

/// The dress's three-panel skirt hanging from the hips, at the defaults: silk's hem falls
/// narrowest, denim's stands widest (measured 41.5 / 43.8 / 46.1 cm; after 1 s on a grid of
/// half the spacing silk 42.0, denim 47.6, against 42.1 and 46.8 on the fixture's grid).
#[test]
fn the_skirt_hem_widens_with_the_fabrics_bending_length() {
    assert_orders("skirt", all("skirt_sewn", true));
}

/// The eight-panel dress with bending hysteresis off (elastic bending B only): ordered
/// (measured 47.0 / 49.9 / 50.5 cm).
#[test]
#[ignore = "long: three dresses sewn and settled 3 s each (11.5 minutes on 2 cores, session 19); the skirt's ordering above is in CI"]
fn the_dress_hem_widens_with_bending_length_without_bending_hysteresis() {
    assert_orders("dress, hysteresis off", all("dress_sewn", false));
}

/// The goal (issue 21, item 7) at the defaults: missed (silk 46.2, cotton broad 50.0, denim
/// 49.2 cm; the module documentation says why).
#[test]
#[ignore = "issue 21 item 7, missed: bending hysteresis keeps the sewn shape (docs/validation.md)"]
fn the_dress_hem_widens_with_the_fabrics_bending_length() {
    assert_orders("dress", all("dress_sewn", true));
}
