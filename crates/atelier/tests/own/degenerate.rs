//! Degenerate geometry (issue 10): each case gives a clear error naming the file, place and
//! field, or a documented behaviour (`docs/hostile.md`).

use std::path::{Path, PathBuf};

use atelier_fabric::ErrorKind;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("repository root")
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("atelier-degenerate-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch");
    dir
}

/// A quad pattern with the given four side ends (cm) and cells per side.
fn quad(name: &str, corners: [(f64, f64); 3], cells: usize) -> String {
    let [b, r, t] = corners;
    format!(
        r#"(
    name: "{name}",
    provenance: "degenerate-geometry test",
    grain: ((25.0, 0.0), (25.0, 50.0)),
    outline: Quad(
        start: (0.0, 0.0),
        bottom: [(name: "bottom", cells: {cells}, path: [Line({}, {})])],
        right: [(name: "right", cells: {cells}, path: [Line({}, {})])],
        top: [(name: "top", cells: {cells}, path: [Line({}, {})])],
        left: [(name: "left", cells: {cells}, path: [Line(0.0, 0.0)])],
    ),
)"#,
        b.0, b.1, r.0, r.1, t.0, t.1
    )
}

fn load_pattern(dir: &Path, text: &str) -> Result<atelier_grid::pattern::Panel, String> {
    let path = dir.join("p.ron");
    std::fs::write(&path, text).expect("write");
    let spec = atelier_grid::pattern::load_pattern(&path).map_err(|e| e.to_string())?;
    atelier_grid::pattern::grid_pattern(&spec, atelier_grid::ImproveParams::default())
        .map_err(|e| e.to_string())
}

/// A pattern whose corners all lie on one line (the boundary runs out and back) crosses itself
/// nowhere but encloses nothing: refused as such, naming the outline — not as a grid that
/// "cannot be cooked".
#[test]
fn a_collinear_outline_is_refused() {
    let dir = scratch("collinear");
    let e = load_pattern(
        &dir,
        &quad("line", [(50.0, 0.0), (100.0, 0.0), (50.0, 0.0)], 10),
    )
    .expect_err("refused");
    assert!(
        e.contains("p.ron:") && e.contains("`outline`") && e.contains("encloses no area"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Two coincident corners make a side of zero length: refused, naming the team's path.
#[test]
fn coincident_corners_are_refused() {
    let dir = scratch("coincident");
    let e = load_pattern(
        &dir,
        &quad("pinch", [(50.0, 0.0), (50.0, 0.0), (0.0, 50.0)], 10),
    )
    .expect_err("refused");
    assert!(
        e.contains("outline.right[0].path") && e.contains("zero length"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A panel of 10¹⁰ nodes (100 000 cells a side: a typo) is refused from its numbers before
/// anything is allocated (it used to abort the process asking for 160 GB).
#[test]
fn a_panel_too_large_is_refused_before_it_is_gridded() {
    let dir = scratch("huge");
    let e = load_pattern(
        &dir,
        &quad("huge", [(50.0, 0.0), (50.0, 50.0), (0.0, 50.0)], 100_000),
    )
    .expect_err("refused");
    assert!(
        e.contains("`outline`") && e.contains("at most 1000000"),
        "{e}"
    );
    let ok = load_pattern(
        &dir,
        &quad("fine", [(50.0, 0.0), (50.0, 50.0), (0.0, 50.0)], 99),
    )
    .expect("a 100 × 100 grid");
    assert_eq!(ok.topology.node_count(), 100 * 100);
    std::fs::remove_dir_all(&dir).ok();
}

/// A seam that joins a team to itself is refused with the seam's place; a seam joining two
/// teams of one panel (a tube) is allowed.
#[test]
fn a_seam_joining_a_team_to_itself_is_refused() {
    let dir = scratch("seam");
    std::fs::copy(
        root().join("fixtures/patterns/dress/front_skirt.ron"),
        dir.join("front_skirt.ron"),
    )
    .expect("copy");
    let garment = |a: &str, b: &str| {
        format!(
            r#"(name: "g", provenance: "degenerate-geometry test", panels: [(name: "front skirt", pattern: "front_skirt.ron")],
    seams: [(name: "s", a: ("front skirt", "{a}"), b: ("front skirt", "{b}"), reversed: false)])"#
        )
    };
    let path = dir.join("g.ron");
    std::fs::write(&path, garment("side +x", "side +x")).expect("write");
    let e = atelier_grid::pattern::load_garment(&path, atelier_grid::ImproveParams::default())
        .expect_err("refused");
    assert_eq!(e.kind, ErrorKind::Inconsistent, "{e}");
    assert_eq!(e.field, "seams[0]");
    assert_eq!(e.position.map(|p| p.line), Some(2), "{e}");
    assert!(e.message.contains("to itself"), "{e}");
    std::fs::write(&path, garment("side +x", "side -x")).expect("write");
    let tube = atelier_grid::pattern::load_garment(&path, atelier_grid::ImproveParams::default())
        .expect("a panel sewn to itself along two teams");
    assert_eq!(tube.seams[0].panel_a, tube.seams[0].panel_b);
    std::fs::remove_dir_all(&dir).ok();
}

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";

fn obj(
    text: &str,
    closed: bool,
) -> Result<atelier_body::io::ExternalBody, atelier_fabric::FileError> {
    let opts = atelier_body::io::LoadOptions {
        require_closed: closed,
        scale: 1.0,
    };
    atelier_body::io::parse_obj(text, Path::new("b.obj"), &opts)
}

/// A body mesh with a hole: refused when a closed mesh is required (the open edge and its
/// face's line named), read with `closed: false` otherwise.
#[test]
fn a_body_mesh_with_a_hole_is_refused_or_marked_open() {
    let holed = TETRA.replace("f 3 1 4\n", "");
    assert!(obj(TETRA, true).expect("closed").closed);
    let e = obj(&holed, true).expect_err("refused");
    assert_eq!(e.kind, ErrorKind::Inconsistent, "{e}");
    assert!(
        e.position.is_some() && e.message.contains("not closed"),
        "{e}"
    );
    assert!(!obj(&holed, false).expect("read").closed);
}

/// A face without area (three corners on a line, or a corner repeated) is refused with its
/// line, closed mesh required or not: it has no normal, so no side.
#[test]
fn a_zero_area_face_is_refused_with_its_line() {
    for (bad, line) in [
        (TETRA.replace("f 3 1 4\n", "f 3 1 4\nf 1 2 2\n"), 9),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 2 0 0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\nf 1 2 5\n"
                .to_string(),
            10,
        ),
    ] {
        for closed in [false, true] {
            let e = obj(&bad, closed).expect_err("refused");
            assert_eq!(e.kind, ErrorKind::Inconsistent, "{e}");
            assert_eq!(e.position.map(|p| p.line), Some(line), "{e}");
            assert!(e.message.contains("zero area"), "{e}");
        }
    }
}

/// A sheet of zero width has no cell with a positive area: the topology refuses it.
#[test]
fn a_sheet_without_area_is_refused() {
    let grid = atelier_grid::StructuredGrid::sheet(3, 3, 0.0, 1.0);
    let e = atelier_grid::ClothTopology::from_structured(&grid).expect_err("refused");
    assert!(e.to_string().contains("positive area"), "{e}");
}

/// Sizes that would exhaust memory before anything failed are refused when the scenario is
/// read: a drape of 10⁸ nodes, a cantilever of 10⁶ cells, 10¹¹ frames.
#[test]
fn a_scene_too_large_is_refused_when_read() {
    let drape = |extra: &str| {
        format!(
            r#"(name: "d", reproduces: "degenerate-geometry test", kind: Drape(fabric: "../fabrics/silk.ron", tester: Jis{extra}))"#
        )
    };
    for (text, field) in [
        (drape(", n_around: 10000, n_rings: 10000"), "kind.n_around"),
        (drape(", max_time: 1000.0, frame_interval: 1e-8"), "kind.frame_interval"),
        (
            r#"(name: "c", reproduces: "degenerate-geometry test", kind: Cantilever(fabric: "../fabrics/silk.ron", segments: 1000000))"#
                .to_string(),
            "kind.segments",
        ),
    ] {
        let e = atelier::scenario::Scenario::parse(&text, Path::new("s.ron")).expect_err(field);
        assert_eq!(e.field, field, "{e}");
        assert_eq!(e.kind, ErrorKind::OutOfRange, "{e}");
    }
}

/// A garment larger than the scene: a single 3 m × 1 m panel wrapped around the trunk. The
/// placement widens its wrap so that the panel does not overlap itself (a tube about a metre
/// across), nothing holds it, and it falls off the body — there is no floor. The run completes,
/// and the report says what happened (a warning and `nodes_below_body`) instead of drawing it
/// silently; the sewn dress, which the body holds, has neither.
#[test]
fn a_garment_larger_than_the_body_falls_off_and_says_so() {
    let dir = scratch("larger");
    std::fs::write(
        dir.join("wide.ron"),
        r#"(
    name: "wide",
    provenance: "degenerate-geometry test: 3 m wide, 1 m long",
    grain: ((0.0, -100.0), (0.0, 0.0)),
    outline: Quad(
        start: (-150.0, -100.0),
        bottom: [(name: "bottom", cells: 60, path: [Line(150.0, -100.0)])],
        right: [(name: "right", cells: 20, path: [Line(150.0, 0.0)])],
        top: [(name: "top", cells: 60, path: [Line(-150.0, 0.0)])],
        left: [(name: "left", cells: 20, path: [Line(-150.0, -100.0)])],
    ),
)"#,
    )
    .expect("write");
    std::fs::write(
        dir.join("g.ron"),
        r#"(name: "wide", provenance: "test", panels: [(name: "wide", pattern: "wide.ron")], seams: [])"#,
    )
    .expect("write");
    let fabric = root().join("fixtures/fabrics/cotton_broad.ron");
    let scenario = format!(
        r#"(name: "wide", reproduces: "degenerate-geometry test", kind: Garment(garment: "g.ron", fabric: "{}", placements: [Trunk(facing_deg: 0.0, y0: 0.98)], settings: (dt: 0.01, friction: 0.3, restitution: 0.1, settle: 0.6)))"#,
        fabric.display()
    );
    let path = dir.join("s.ron");
    std::fs::write(&path, &scenario).expect("write");
    let s = atelier::scenario::Scenario::load(&path).expect("scenario");
    let report = atelier::run::run(
        &s,
        Some(&path),
        &dir,
        &dir.join("out"),
        &atelier::run::RunOptions::default(),
        &mut |_| {},
    )
    .expect("the run completes");
    let fallen = report.metrics["nodes_below_body"].expect("metric");
    assert!(fallen > 0.0, "{:?}", report.metrics);
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("does not hold the garment")),
        "{:?}",
        report.warnings
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A setting a scene kind checks only when it runs is refused as a typed error naming the
/// scene and the field: a wet scene's `fold_radius` beyond the sheet, a string fit observing
/// more shapes than there are.
#[test]
fn a_scene_setting_out_of_range_names_the_scene_and_the_field() {
    use atelier::outcome::{RunError, SetupError};
    use atelier::scenario::{Scenario, ScenarioKind};
    let load = |name: &str| {
        Scenario::load(&root().join(format!("fixtures/scenarios/{name}.ron"))).expect("scenario")
    };
    let ScenarioKind::Wet(mut spec) = load("wet_pinch1_dry").kind else {
        panic!("a wet scenario")
    };
    spec.fold_radius = 2.0 * spec.scene.size;
    let fabric =
        atelier_fabric::Fabric::load(&root().join("fixtures/scenarios").join(&spec.fabric))
            .expect("fabric");
    let e = atelier::wet::simulate(&spec, &fabric).expect_err("refused");
    let RunError::Setup {
        scene: "wet scene",
        source,
    } = &e
    else {
        panic!("not a wet scene's setup: {e:?}")
    };
    let SetupError::Invalid(v) = source.as_ref() else {
        panic!("not a wet scene's invalid value: {e:?}")
    };
    assert_eq!(v.field, "fold_radius", "{e}");
    assert_eq!(v.kind, ErrorKind::OutOfRange, "{e}");
    assert!(e.to_string().starts_with("wet scene: "), "{e}");
    let ScenarioKind::StringFit(mut spec) = load("fit_cable_j4").kind else {
        panic!("a string-fit scenario")
    };
    spec.observed = 1000;
    let e = atelier::fit::simulate(&spec, &root().join("fixtures/scenarios")).expect_err("refused");
    let RunError::Setup {
        scene: "string fit",
        source,
    } = &e
    else {
        panic!("not a string fit's setup: {e:?}")
    };
    let SetupError::Invalid(v) = source.as_ref() else {
        panic!("not a string fit's invalid value: {e:?}")
    };
    assert_eq!(v.field, "observed", "{e}");
}

/// The step parameters in a scenario file are grouped by stage (issue 22): the nested form
/// parses to the values given, every other field at its default, and the flat names of before
/// are refused as unknown fields naming the place (not silently ignored).
#[test]
fn step_parameters_are_grouped_by_stage_and_flat_names_are_refused() {
    use atelier::scenario::{Scenario, ScenarioKind};
    let drape = |step: &str| {
        format!(
            r#"(name: "d", reproduces: "step-parameter test", kind: Drape(fabric: "../fabrics/silk.ron", tester: Jis, step: ({step})))"#
        )
    };
    let s = Scenario::parse(
        &drape("damping: 0.5, shape: (tolerance: 1e-6, max_iterations: 7), bending: (off: true)"),
        Path::new("s.ron"),
    )
    .expect("nested step parameters parse");
    let ScenarioKind::Drape(d) = s.kind else {
        panic!("a drape")
    };
    let defaults = atelier_solver::StepParams::default();
    assert_eq!(d.step.damping, 0.5);
    assert_eq!(d.step.shape.tolerance, 1e-6);
    assert_eq!(d.step.shape.max_iterations, 7);
    assert!(d.step.bending.off);
    assert_eq!(
        d.step.shape.collision_passes,
        defaults.shape.collision_passes
    );
    assert_eq!(d.step.internal, defaults.internal);
    assert_eq!(d.step.shear, defaults.shear);
    let e = Scenario::parse(&drape("shape_tolerance: 1e-6"), Path::new("s.ron"))
        .expect_err("a flat name is refused");
    assert_eq!(e.kind, ErrorKind::UnknownField, "{e}");
    assert!(e.to_string().contains("shape_tolerance"), "{e}");
    assert!(e.field.contains("step"), "{e}");
}
