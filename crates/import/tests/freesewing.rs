//! FreeSewing's SVG output read back (issue 24): the Penelope pencil skirt and the Bella bodice
//! block drafted for the 9AR measurements (`fixtures/patterns/freesewing/`, FreeSewing 4.10.2).
//!
//! Reference: `parts.json`, written by the fixture's `parts.py` (Python's standard library, not
//! atelier): each part's seam line with its area from the exact Bézier integral, its notches,
//! grain line and fold. Tolerance on an area: what flattening the curves to within
//! `svg::FLATNESS` (1 µm) can lose, at most ⅔ × 1 µm per unit of outline length (the area
//! between an arc and its chord is ⅔ × chord × sagitta), plus the reference's rounding to four
//! decimals (5e-5 cm²).

use std::path::{Path, PathBuf};

use atelier_import::{Piece, svg};
use serde_json::Value;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/patterns/freesewing")
}

fn reference() -> Value {
    let text = std::fs::read_to_string(dir().join("parts.json")).expect("parts.json");
    serde_json::from_str(&text).expect("json")
}

fn perimeter_cm(p: &Piece) -> f64 {
    let n = p.outline.len();
    (0..n)
        .map(|k| {
            let (a, b) = (p.outline[k], p.outline[(k + 1) % n]);
            (a[0] - b[0]).hypot(a[1] - b[1])
        })
        .sum()
}

fn check(file: &str) {
    let read = svg::read_with(&dir().join(file), false).unwrap_or_else(|e| panic!("{e}"));
    assert!((read.cm_per_unit - 0.1).abs() < 1e-12, "1 user unit = 1 mm");
    let r = reference();
    let parts = r["files"][file]["parts"].as_array().expect("parts");
    assert_eq!(read.pieces.len(), parts.len(), "{file}");
    for want in parts {
        let name = want["part"].as_str().expect("part");
        let p = read
            .pieces
            .iter()
            .find(|p| p.name == name)
            .unwrap_or_else(|| panic!("{file}: no piece {name}"));
        let folded = !want["cut_on_fold"].is_null();
        let half = want["seam_line"]["area_cm2"].as_f64().expect("area");
        let area = if folded { 2.0 * half } else { half };
        // FLATNESS is in user units (mm): 0.1 cm each.
        let tolerance = 2.0 / 3.0 * svg::FLATNESS * 0.1 * perimeter_cm(p) + 5e-5;
        eprintln!(
            "{file} {name}: area {:.4} cm² against {area:.4} (tolerance {tolerance:.2e}), {} notches on the outline{}",
            p.area_cm2(),
            p.notches.len(),
            if folded { ", unfolded" } else { "" }
        );
        assert!(
            (p.area_cm2() - area).abs() <= tolerance,
            "{file} {name}: area {} against {area} cm²",
            p.area_cm2()
        );
        assert!(p.grain.is_some(), "{file} {name}: a grain line");
        // Notches on the seam line: those of the drawn half and, for a half cut on the fold,
        // their mirror images; a notch inside the piece (Bella's bust point) is not one, nor is
        // one on the fold edge, which lies inside the unfolded piece (its centre line).
        let on: Vec<&Value> = want["notches"]
            .as_array()
            .expect("notches")
            .iter()
            .filter(|n| n["distance_to_seam_line_mm"].as_f64().unwrap_or(0.0) < 0.5)
            .collect();
        let expected = if folded {
            // Both fixtures' folds are vertical lines (x constant).
            let fold = &want["cut_on_fold"];
            let x = fold["from"][0].as_f64().expect("x");
            let on_fold = |n: &Value| (n["at"][0].as_f64().expect("x") - x).abs() < 0.5;
            let at_fold = on.iter().filter(|n| on_fold(n)).count();
            2 * (on.len() - at_fold)
        } else {
            on.len()
        };
        assert_eq!(p.notches.len(), expected, "{file} {name}: notches");
    }
}

#[test]
fn penelope_reads_back_with_its_halves_unfolded() {
    check("penelope.svg");
}

#[test]
fn bella_reads_back_with_its_notches() {
    check("bella.svg");
}

/// The darts drawn as V notches: as many closed as the reference finds tips (vertices turning
/// back by more than 95°: positive turns in `parts.json`'s `corners_over_45deg`, whose y runs
/// down), twice that for a half cut on the fold.
#[test]
fn the_v_darts_are_closed() {
    let r = reference();
    for file in ["penelope.svg", "bella.svg"] {
        let read = svg::read(&dir().join(file)).unwrap_or_else(|e| panic!("{e}"));
        for want in r["files"][file]["parts"].as_array().expect("parts") {
            let name = want["part"].as_str().expect("part");
            let tips = want["seam_line"]["corners_over_45deg"]
                .as_array()
                .map_or(0, |c| {
                    c.iter()
                        .filter(|k| k["turn_deg"].as_f64().is_some_and(|t| t > 95.0))
                        .count()
                });
            let expected = if want["cut_on_fold"].is_null() {
                tips
            } else {
                2 * tips
            };
            let p = read.pieces.iter().find(|p| p.name == name).expect("piece");
            eprintln!(
                "{file} {name}: {} darts closed, {tips} tips drawn",
                p.darts.len()
            );
            assert_eq!(p.darts.len(), expected, "{file} {name}");
        }
    }
}
