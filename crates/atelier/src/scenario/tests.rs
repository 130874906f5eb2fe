//! Tests of [`super`].

use super::*;

/// A range error found after parsing names the field's line and column.
#[test]
fn range_errors_name_the_fields_position() {
    let e = parse(
        "(name: \"g\", reproduces: \"x\",\n kind: Garment(garment: \"a\", fabric: \"b\", placements: [],\n  settings: (dt: 0.01,\n   sewing: (omega: 5.0, threshold: -1.0))))",
    )
    .expect_err("negative threshold");
    assert_eq!(e.field, "kind.settings.sewing.threshold");
    let p = e.position.expect("located");
    assert_eq!((p.line, p.column), (4, 25), "{e}");
    let e = parse(
        "(name: \"d\", reproduces: \"x\", kind: Drape(fabric: \"f\", tester: Jis),\n expectations: [(metric: \"node_count\", min: 1.0),\n  (metric: \"nodes\", min: 2.0, max: 1.0)])",
    )
    .expect_err("min above max");
    assert_eq!(e.field, "expectations[1]");
    assert_eq!(e.position.map(|p| p.line), Some(3), "{e}");
}

fn parse(text: &str) -> Result<Scenario, FileError> {
    Scenario::parse(text, Path::new("test.ron"))
}

#[test]
fn a_drape_scenario_reads_with_its_defaults() {
    let s = parse(
        r#"(name: "d", reproduces: "JIS drape", kind: Drape(fabric: "f.ron", tester: Jis),
            expectations: [(metric: "drape_coefficient_percent", min: 10.0)])"#,
    )
    .expect("parses");
    let ScenarioKind::Drape(d) = &s.kind else {
        panic!("kind")
    };
    assert_eq!(d.tester, Tester::Jis);
    assert!(d.until_rest);
    assert!(s.expectations[0].met_by(Some(12.0)));
    assert!(!s.expectations[0].met_by(Some(9.0)));
    assert!(!s.expectations[0].met_by(None));
    assert!(!s.expectations[0].met_by(Some(f64::NAN)));
}

#[test]
fn errors_name_position_and_field() {
    let e = parse(
        "(name: \"d\", reproduces: \"x\",\n kind: Drape(fabric: \"f.ron\", tester: Jis, wobble: 3))",
    )
    .expect_err("unknown field");
    assert_eq!(e.kind, ErrorKind::UnknownField);
    assert_eq!(e.position.map(|p| p.line), Some(2));
    assert!(e.to_string().contains("test.ron:2:"), "{e}");
    assert!(e.field.contains("wobble"), "{e}");
    let e = parse(r#"(name: "d", kind: Drape(fabric: "f.ron", tester: Jis))"#)
        .expect_err("missing reproduces");
    assert_eq!(e.kind, ErrorKind::MissingField);
    assert!(e.field.contains("reproduces"), "{e}");
    let e = parse(
        r#"(name: "d", reproduces: "x", kind: Drape(fabric: "f.ron", tester: Jis),
            expectations: [(metric: "chord_angle_deg", max: 1.0)])"#,
    )
    .expect_err("metric of another kind");
    assert_eq!(e.field, "expectations[0].metric");
    let e = parse(r#"(name: "a b", reproduces: "x", kind: Drape(fabric: "f", tester: Jis))"#)
        .expect_err("bad name");
    assert_eq!(e.field, "name");
}

/// Too few rings for the tester: the clamped JIS specimen needs a second held ring inside the
/// rim (3 rings), the thesis's hinged hole 2; the error names `kind.n_rings`.
#[test]
fn too_few_rings_for_the_tester_are_refused() {
    let drape = |tester: &str, rings: usize| {
        parse(&format!(
            r#"(name: "d", reproduces: "x", kind: Drape(fabric: "f.ron", tester: {tester}, n_rings: {rings}))"#
        ))
    };
    let e = drape("Jis", 2).expect_err("JIS with 2 rings");
    assert_eq!(e.field, "kind.n_rings", "{e}");
    assert_eq!(e.kind, ErrorKind::OutOfRange, "{e}");
    assert!(drape("Jis", 3).is_ok());
    assert!(drape("Thesis", 2).is_ok());
    assert_eq!(
        drape("Thesis", 1).expect_err("1 ring").field,
        "kind.n_rings"
    );
}

/// An expectation that no run can miss is refused with its field, the metric's physical range
/// and where the expectation is (issue 23: eight drape scenarios once "expected" a drape
/// coefficient in [0, 100] or [−1, 101]); a bound inside the range, or a one-sided bound on a
/// quantity that cannot be negative given from above, is accepted. `unconverged_fraction` may
/// be bounded by 1: that accepts unconverged steps, which a run otherwise fails on.
#[test]
fn an_expectation_that_cannot_fail_is_refused() {
    let with = |bound: &str| {
        parse(&format!(
            "(name: \"d\", reproduces: \"x\", kind: Drape(fabric: \"f.ron\", tester: Jis),\n \
             expectations: [(metric: \"node_count\", max: 9.0),\n  {bound}])"
        ))
    };
    for bound in [
        r#"(metric: "drape_coefficient_percent", min: 0.0, max: 100.0)"#,
        r#"(metric: "drape_coefficient_percent", min: -1.0, max: 101.0)"#,
        r#"(metric: "drape_coefficient_percent", max: 100.0)"#,
        r#"(metric: "shadow_area_m2", min: 0.0)"#,
        r#"(metric: "settled", min: 0.0, max: 1.0)"#,
    ] {
        let e = with(bound).expect_err(bound);
        assert_eq!(e.kind, ErrorKind::Inconsistent, "{bound}: {e}");
        assert_eq!(e.field, "expectations[1]", "{bound}: {e}");
        assert_eq!(e.position.map(|p| p.line), Some(3), "{bound}: {e}");
        assert!(e.to_string().contains("physical range"), "{bound}: {e}");
    }
    for bound in [
        r#"(metric: "drape_coefficient_percent", min: 74.9, max: 90.9)"#,
        r#"(metric: "drape_coefficient_percent", min: 0.5)"#,
        r#"(metric: "shadow_area_m2", max: 0.1)"#,
        r#"(metric: "settled", min: 1.0)"#,
        r#"(metric: "unconverged_fraction", max: 1.0)"#,
    ] {
        with(bound).unwrap_or_else(|e| panic!("{bound}: {e}"));
    }
}
