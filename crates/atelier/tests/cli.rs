//! `atelier validate`: success, a bad file, a missing file — exit codes and one line per file.

use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn atelier(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_atelier"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn every_fixture_validates_and_is_recognised() {
    let (ok, out, err) = atelier(&[
        "validate",
        "fixtures/fabrics/cotton_broad.ron",
        "fixtures/patterns/dress/front_bodice.ron",
        "fixtures/patterns/dress/dress.ron",
        "fixtures/bodies/jis_9ar.ron",
        "fixtures/motions/walk.ron",
    ]);
    assert!(ok, "{out}{err}");
    for kind in [
        "(fabric)",
        "(pattern)",
        "(garment)",
        "(body description)",
        "(motion)",
    ] {
        assert!(out.contains(kind), "{kind} missing in\n{out}");
    }
    assert_eq!(out.lines().count(), 5);
}

#[test]
fn a_bad_file_is_reported_with_its_position_and_field_and_fails() {
    let dir = std::env::temp_dir().join(format!("atelier-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let bad = dir.join("bad_pattern.ron");
    std::fs::write(
        &bad,
        r#"(name: "x", provenance: "x", grain: ((0.0, 0.0), (0.0, 1.0)),
  outline: Quad(start: (0.0, 0.0),
    bottom: [(name: "b", cells: 4, path: [Line(NaN, 0.0)])],
    right: [(name: "r", cells: 4, path: [Line(10.0, 10.0)])],
    top: [(name: "t", cells: 4, path: [Line(0.0, 10.0)])],
    left: [(name: "l", cells: 4, path: [Line(0.0, 0.0)])]))"#,
    )
    .expect("write");
    let missing = dir.join("missing.ron");
    let (ok, out, err) = atelier(&[
        "validate",
        bad.to_str().expect("utf-8"),
        missing.to_str().expect("utf-8"),
        "fixtures/motions/walk.ron",
    ]);
    assert!(!ok, "must fail:\n{out}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "{out}");
    assert!(
        lines[0].starts_with("error")
            && lines[0].contains("bad_pattern.ron:6:")
            && lines[0].contains("outline.bottom[0].path[0]")
            && lines[0].contains("read as a pattern"),
        "{}",
        lines[0]
    );
    assert!(
        lines[1].contains("missing.ron") && lines[1].contains("cannot read"),
        "{}",
        lines[1]
    );
    assert!(lines[2].starts_with("ok"), "{}", lines[2]);
    assert!(err.contains("2 of 3 files"), "{err}");
    assert!(
        !err.contains("panicked") && !err.contains("backtrace"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
