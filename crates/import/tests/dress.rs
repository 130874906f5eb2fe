//! The project's own dress, written as DXF-AAMA by an independent writer (the Python package
//! `ezdxf`, `fixtures/patterns/dxf/make.py`) and read back (issue 24).
//!
//! References, none produced by atelier: the manifest `dress_aama.json` the script wrote beside
//! the files (each piece's quantity, corners, teams with their cells, notches, darts, and the
//! exact area of its drafted outline, Bézier curves integrated in closed form), and the
//! hand-written pattern files of `fixtures/patterns/dress/` the script read. The goal (issue 24):
//! every piece, read back and gridded with the pattern file's corners and cell counts, gives the
//! same grid as the pattern file within 0.1 mm, from the R12 file (POLYLINE), the R2000 file
//! (LWPOLYLINE) and the millimetre file alike.

use std::path::{Path, PathBuf};

use atelier_grid::ImproveParams;
use atelier_grid::pattern::{grid_pattern, load_pattern};
use atelier_import::{PanelOptions, Piece, dxf, plan, plan_and_grid};
use serde_json::Value;

/// The goal: grid nodes within 0.1 mm (m).
const SAME_GRID_M: f64 = 1e-4;

/// The sew line's area against the drafted outline's: the script's sampling keeps it within
/// 1e-3 cm² (its README).
const AREA_CM2: f64 = 1e-3;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/patterns/dxf")
}

fn manifest() -> Value {
    let text = std::fs::read_to_string(dir().join("dress_aama.json")).expect("manifest");
    serde_json::from_str(&text).expect("json")
}

fn point(v: &Value) -> [f64; 2] {
    [v[0].as_f64().expect("x"), v[1].as_f64().expect("y")]
}

fn find<'a>(pieces: &'a [Piece], name: &str) -> &'a Piece {
    pieces
        .iter()
        .find(|p| p.name == name)
        .unwrap_or_else(|| panic!("no piece {name:?}"))
}

/// Read a file; every piece of the manifest is there with its quantity, sew line, area,
/// notches and darts; no warning but the style text's.
fn read_and_check(file: &str) -> Vec<Piece> {
    let read = dxf::read(&dir().join(file)).unwrap_or_else(|e| panic!("{e}"));
    let m = manifest();
    let pieces = m["pieces"].as_array().expect("pieces");
    assert_eq!(read.pieces.len(), pieces.len(), "{file}");
    assert!(read.warnings.is_empty(), "{file}: {:#?}", read.warnings);
    assert_eq!(read.style.as_deref(), Some("atelier dress 9AR"));
    for want in pieces {
        let name = want["name"].as_str().expect("name");
        let p = find(&read.pieces, name);
        assert_eq!(
            u64::from(p.quantity),
            want["quantity"].as_u64().expect("q"),
            "{name}"
        );
        assert_eq!(p.outline_source, "sew line (layer 14)");
        let area = want["area_exact_cm2"].as_f64().expect("area");
        assert!(
            (p.area_cm2() - area).abs() <= AREA_CM2,
            "{file} {name}: area {} against {area} cm²",
            p.area_cm2()
        );
        assert_eq!(
            p.notches.len(),
            want["notches"].as_array().expect("n").len(),
            "{name}"
        );
        assert_eq!(
            p.darts.len(),
            want["darts"].as_array().expect("d").len(),
            "{name}"
        );
        let grain = want["grain"].as_array().expect("grain");
        assert_eq!(
            p.grain,
            Some((point(&grain[0]), point(&grain[1]))),
            "{name}"
        );
    }
    read.pieces
}

/// Grid every piece as its pattern file says (corners, cells) and compare with the pattern
/// file's own grid; returns the largest distance, m.
fn same_grids(pieces: &[Piece], file: &str, params: ImproveParams) -> f64 {
    let m = manifest();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut worst: f64 = 0.0;
    for want in m["pieces"].as_array().expect("pieces") {
        let name = want["name"].as_str().expect("name");
        let corners: Vec<[f64; 2]> = want["corners"]
            .as_array()
            .expect("corners")
            .iter()
            .map(point)
            .collect();
        let cells: Vec<usize> = want["teams"]
            .as_array()
            .expect("teams")
            .iter()
            .map(|t| t["cells"].as_u64().expect("cells") as usize)
            .collect();
        let dart_cells: Vec<usize> = want["darts"]
            .as_array()
            .expect("darts")
            .iter()
            .map(|d| d["cells"].as_u64().expect("cells") as usize)
            .collect();
        let options = PanelOptions {
            corners: Some([corners[0], corners[1], corners[2], corners[3]]),
            cells: Some(cells),
            dart_cells: Some(dart_cells),
            ..PanelOptions::default()
        };
        let planned =
            plan(find(pieces, name), &options, "test").unwrap_or_else(|e| panic!("{name}: {e}"));
        let imported =
            grid_pattern(&planned.spec, params).unwrap_or_else(|e| panic!("{file} {name}: {e}"));
        let ron = load_pattern(&root.join(want["ron_file"].as_str().expect("file")))
            .expect("pattern file");
        let drafted = grid_pattern(&ron, params).expect("grids");
        let (a, b) = (
            imported.topology.rest_positions(),
            drafted.topology.rest_positions(),
        );
        assert_eq!(a.len(), b.len(), "{file} {name}: node counts");
        let d = a
            .iter()
            .zip(b)
            .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
            .fold(0.0, f64::max);
        let far = |x: &[[f64; 2]], y: &[[f64; 2]], only: &dyn Fn(usize) -> bool| {
            x.iter()
                .zip(y)
                .enumerate()
                .filter(|(k, _)| only(*k))
                .map(|(_, (p, q))| (p[0] - q[0]).hypot(p[1] - q[1]))
                .fold(0.0, f64::max)
        };
        let fixed = &drafted.initial.fixed;
        eprintln!(
            "{file} {name}: {} nodes, largest distance {:.2e} m; before improvement {:.2e} m (fixed nodes {:.2e} m); improvement steps {} / {}, converged {} / {}",
            a.len(),
            d,
            far(
                &imported.initial.positions,
                &drafted.initial.positions,
                &|_| true
            ),
            far(
                &imported.initial.positions,
                &drafted.initial.positions,
                &|k| fixed[k]
            ),
            imported.improvement.energy.len(),
            drafted.improvement.energy.len(),
            imported.improvement.converged,
            drafted.improvement.converged,
        );
        worst = worst.max(d);
    }
    worst
}

/// The improvement run to convergence (a relative energy change of 1e-13): the grid is then
/// the energy's minimum, not where a looser stopping rule happened to stop.
fn converged() -> ImproveParams {
    ImproveParams {
        relative_tolerance: 1e-13,
        max_iterations: 200_000,
        ..ImproveParams::default()
    }
}

#[test]
fn the_dress_written_by_ezdxf_reads_back_r2000() {
    let pieces = read_and_check("dress_aama_r2000.dxf");
    let d = same_grids(&pieces, "r2000", converged());
    assert!(d <= SAME_GRID_M, "largest distance {d:.2e} m");
}

#[test]
fn the_dress_written_by_ezdxf_reads_back_r12() {
    let pieces = read_and_check("dress_aama_r12.dxf");
    let d = same_grids(&pieces, "r12", converged());
    assert!(d <= SAME_GRID_M, "largest distance {d:.2e} m");
}

/// At the gridder's default stopping rule (relative energy change 1e-6) the improvement stops
/// early, after a number of steps that micrometre differences of the outline change (the front
/// skirt: 344 steps read back, 483 drafted), and the two grids end up to 0.78 mm apart, though
/// they start within 0.013 mm (docs/patterns-import.md).
#[test]
#[ignore = "misses its goal at the gridder's default stopping rule: 0.78 mm (front skirt) > 0.1 mm; within 0.013 mm converged"]
fn the_dress_reads_back_at_the_default_improvement() {
    let pieces = read_and_check("dress_aama_r2000.dxf");
    let d = same_grids(&pieces, "default", ImproveParams::default());
    assert!(d <= SAME_GRID_M, "largest distance {d:.2e} m");
}

#[test]
fn the_dress_in_millimetres_is_the_same_dress() {
    let cm = read_and_check("dress_aama_r2000.dxf");
    let mm = read_and_check("dress_aama_mm.dxf");
    for (a, b) in cm.iter().zip(&mm) {
        assert_eq!(a.outline.len(), b.outline.len(), "{}", a.name);
        for (p, q) in a.outline.iter().zip(&b.outline) {
            assert!(
                (p[0] - q[0]).hypot(p[1] - q[1]) < 1e-6,
                "{}: {p:?} {q:?}",
                a.name
            );
        }
    }
}

/// Without corners given, the search (every four of the six vertices that turn most, the grid
/// with the least shear kept) finds the four corners the dress's drafter chose for each piece
/// (the manifest's, read from the hand-drafted pattern files).
#[test]
fn the_corner_search_finds_the_drafters_corners() {
    let pieces = read_and_check("dress_aama_r2000.dxf");
    for want in manifest()["pieces"].as_array().expect("pieces") {
        let name = want["name"].as_str().expect("name");
        let (planned, _) = plan_and_grid(
            find(&pieces, name),
            &PanelOptions::default(),
            "test",
            ImproveParams::default(),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let found: Vec<[f64; 2]> = planned
            .corners
            .iter()
            .map(|&k| planned.breakpoints[k])
            .collect();
        for (k, c) in want["corners"]
            .as_array()
            .expect("corners")
            .iter()
            .enumerate()
        {
            let c = point(c);
            assert!(
                (found[k][0] - c[0]).hypot(found[k][1] - c[1]) < 1e-6,
                "{name}: corner {k} at {:?}, the drafter's at {c:?}",
                found[k]
            );
        }
    }
}
