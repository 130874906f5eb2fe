//! Bad pattern files (`fixtures/patterns/dxf/bad/`, written by ezdxf, valid DXF and bad
//! patterns): each is a typed error naming the file, the piece and the entity, or, for entities
//! the reader does not use, a warning naming each one — never a panic, never silence.

use std::path::{Path, PathBuf};

use atelier_import::{ImportError, PieceProblem, dxf};

fn bad(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/patterns/dxf/bad")
        .join(name)
}

fn error(name: &str) -> ImportError {
    match dxf::read(&bad(name)) {
        Ok(read) => panic!("{name}: read {} pieces", read.pieces.len()),
        Err(e) => {
            let text = e.to_string();
            assert!(
                text.contains(name),
                "{name}: the message names the file: {text}"
            );
            e
        }
    }
}

#[test]
fn an_open_outline_is_refused_with_its_piece_and_entity() {
    let e = error("open_outline.dxf");
    let ImportError::Piece {
        piece,
        entity,
        problem,
        ..
    } = &e
    else {
        panic!("{e}")
    };
    assert_eq!(piece, "open outline");
    assert!(entity.contains("on layer 14"), "{entity}");
    assert!(
        matches!(problem, PieceProblem::NotClosed { gap_cm } if *gap_cm > 1.0),
        "{e}"
    );
}

#[test]
fn a_self_intersecting_outline_is_refused_where_it_crosses() {
    let e = error("self_intersecting.dxf");
    let ImportError::Piece { problem, .. } = &e else {
        panic!("{e}")
    };
    let PieceProblem::SelfIntersecting { .. } = problem else {
        panic!("{e}")
    };
}

#[test]
fn a_zero_area_outline_is_refused() {
    let e = error("zero_area.dxf");
    assert!(
        matches!(
            &e,
            ImportError::Piece {
                problem: PieceProblem::ZeroArea { .. } | PieceProblem::TooFewPoints(_),
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn a_file_without_units_is_refused_not_guessed() {
    let e = error("no_units.dxf");
    assert!(matches!(e, ImportError::NoUnits { .. }), "{e}");
}

#[test]
fn a_file_without_pieces_is_refused_listing_what_it_skipped() {
    let e = error("no_pieces.dxf");
    let ImportError::NoPieces { skipped, .. } = &e else {
        panic!("{e}")
    };
    assert!(skipped.iter().any(|s| s.contains("LINE")), "{skipped:?}");
}

#[test]
fn two_pieces_with_one_name_are_refused_naming_both_blocks() {
    let e = error("two_pieces_same_name.dxf");
    let ImportError::DuplicateName {
        name,
        first,
        second,
        ..
    } = &e
    else {
        panic!("{e}")
    };
    assert_eq!(name, "square");
    assert_eq!((first.as_str(), second.as_str()), ("square A", "square B"));
}

#[test]
fn entities_the_reader_does_not_use_are_listed() {
    let read = dxf::read(&bad("unknown_entities.dxf")).expect("reads");
    assert_eq!(read.pieces.len(), 1);
    assert!((read.pieces[0].area_cm2() - 400.0).abs() < 1e-9);
    eprintln!("{:#?}", read.warnings);
    assert!(
        read.warnings
            .iter()
            .any(|w| w.contains("1 HATCH entity not read")),
        "{:#?}",
        read.warnings
    );
    for (what, layer) in [("CIRCLE", "1"), ("SPLINE", "8"), ("LINE", "99")] {
        assert!(
            read.warnings
                .iter()
                .any(|w| w.contains(what) && w.contains(&format!("on layer {layer} "))),
            "{what} on layer {layer}: {:#?}",
            read.warnings
        );
    }
}

#[test]
fn a_missing_or_non_dxf_file_is_an_error_not_a_panic() {
    let e = dxf::read(Path::new("/nonexistent/pattern.dxf")).expect_err("no file");
    assert!(e.to_string().contains("pattern.dxf"), "{e}");
    let text = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
    assert!(dxf::read(&text).is_err());
}

/// A header date far out of range made the `dxf` crate panic (`DateTime + TimeDelta
/// overflowed`, found by the hostile-input tests): the reader reports the file as unreadable.
#[test]
fn a_date_out_of_range_is_an_error_not_a_panic() {
    let text = std::fs::read_to_string(bad("unknown_entities.dxf")).expect("fixture");
    let hostile = text.replacen("$TDCREATE\n 40\n2451545.0", "$TDCREATE\n 40\n1e308", 1);
    assert_ne!(hostile, text, "the fixture holds $TDCREATE");
    let dir = std::env::temp_dir().join(format!("atelier-import-date-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("date.dxf");
    std::fs::write(&path, hostile).expect("write");
    let e = dxf::read(&path).expect_err("refused");
    assert!(
        matches!(&e, ImportError::Read { message, .. } if message.contains("failed on this file")),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
