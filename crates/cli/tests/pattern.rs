//! `atelier pattern FILE --out DIR` and `atelier validate` on DXF-AAMA pattern files (issue 24):
//! the dress written by ezdxf (`fixtures/patterns/dxf/`) read into seven pieces, one line each,
//! their patterns, grids and picture written; a bad file is one line naming the piece and the
//! entity, and exit 1.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn atelier(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_atelier"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("atelier-pattern-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn the_dress_pattern_is_read_printed_and_written() {
    let out = temp_dir("dress");
    let (code, stdout, stderr) = atelier(&[
        "pattern",
        "fixtures/patterns/dxf/dress_aama_r12.dxf",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 7, "{stdout}");
    // The front skirt: 56 × 60 cm, its drafted area 2997.90 cm², warp along +y, four notches,
    // two darts (the manifest of the file's writer).
    let skirt = lines
        .iter()
        .find(|l| l.starts_with("front skirt:"))
        .expect("front skirt");
    for part in [
        "56.0 × 60.0 cm",
        "2997.9 cm²",
        "grain 90.0°",
        "4 notches",
        "2 darts",
    ] {
        assert!(skirt.contains(part), "{part}: {skirt}");
    }
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("sleeve:") && l.contains("quantity 2"))
    );
    for name in [
        "front_skirt.ron",
        "front_skirt.obj",
        "sleeve.ron",
        "pieces.png",
    ] {
        assert!(out.join(name).is_file(), "{name} in {stderr}");
    }
    // The pattern written is an atelier pattern file: it loads and grids as any other.
    let spec = atelier_grid::pattern::load_pattern(&out.join("front_skirt.ron")).expect("loads");
    atelier_grid::pattern::grid_pattern(&spec, atelier_grid::ImproveParams::default())
        .expect("grids");
    let (code, stdout, _) = atelier(&[
        "validate",
        out.join("front_skirt.ron").to_str().expect("utf-8"),
    ]);
    assert_eq!(code, Some(0), "{stdout}");
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn validate_reads_dxf_patterns_and_names_the_piece_and_entity_of_a_bad_one() {
    let (code, stdout, _) = atelier(&[
        "validate",
        "fixtures/patterns/dxf/dress_aama_r2000.dxf",
        "fixtures/patterns/dxf/bad/open_outline.dxf",
    ]);
    assert_eq!(code, Some(1));
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(
        lines[0].starts_with("ok") && lines[0].contains("pattern file"),
        "{stdout}"
    );
    assert!(lines[1].starts_with("error"), "{stdout}");
    for part in [
        "open_outline.dxf",
        "piece \"open outline\"",
        "on layer 14",
        "does not close",
    ] {
        assert!(lines[1].contains(part), "{part}: {}", lines[1]);
    }
}

#[test]
fn a_bad_pattern_file_fails_with_one_line_and_writes_nothing() {
    let out = temp_dir("bad");
    let (code, stdout, stderr) = atelier(&[
        "pattern",
        "fixtures/patterns/dxf/bad/no_units.dxf",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(code, Some(1));
    assert!(stdout.is_empty(), "{stdout}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("no_units.dxf") && stderr.contains("no units"),
        "{stderr}"
    );
    assert!(!out.exists());
    let missing = Path::new("fixtures/patterns/dxf/none.dxf");
    let (code, _, stderr) = atelier(&["pattern", missing.to_str().expect("utf-8"), "--out", "x"]);
    assert_eq!(code, Some(1));
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// FreeSewing's Penelope pencil skirt (SVG): three pieces, the front and the waistband unfolded
/// from their halves, the waist darts closed, each gridded and written.
#[test]
fn the_freesewing_skirt_is_read_and_gridded() {
    let out = temp_dir("penelope");
    let (code, stdout, stderr) = atelier(&[
        "pattern",
        "fixtures/patterns/freesewing/penelope.svg",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 3, "{stdout}");
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("penelope.front:") && l.contains("4 darts")),
        "{stdout}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("penelope.back:") && l.contains("2 darts")),
        "{stdout}"
    );
    assert!(out.join("penelope_front.ron").is_file() && out.join("pieces.png").is_file());
    std::fs::remove_dir_all(&out).ok();
}
