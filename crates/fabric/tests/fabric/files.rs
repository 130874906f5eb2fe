//! Fabric files: the fixtures load and are plausible; every kind of bad input gives a typed error
//! naming the file, the line and column, and the field; the documented example parses.

use std::path::Path;

use approx::assert_relative_eq;
use atelier_fabric::{ErrorKind, Fabric, FabricClass, FileError, units};

use crate::common::{FIXTURES, fixture, root};

/// A valid file with measured curves and a measured bending loop; tests mutate single lines.
const BASE: &str = r#"Fabric(
    name: "test cloth",
    provenance: (source: "unit test", banded: [Tensile]),
    mass_per_area_mg_cm2: 12.0,
    thickness_mm: 0.4,
    friction: 0.5,
    tensile: (
        warp: Measured(
            loading: [(0.0, 0.0), (100.0, 2.0), (300.0, 3.0), (500.0, 3.5)],
            unloading: [(0.0, 1.5), (100.0, 2.8), (300.0, 3.3), (500.0, 3.5)],
        ),
        weft: Kes(lt: 0.7, emt_percent: 6.0, rt_percent: 50.0),
    ),
    shear: (g_gf_cm_deg: 1.2, two_hg_gf_cm: 2.0),
    bending: (
        warp: Kes(b_gf_cm2_cm: 0.1, two_hb_gf_cm_cm: 0.08),
        weft: Kes(b_gf_cm2_cm: 0.08, two_hb_gf_cm_cm: 0.06),
    ),
)
"#;

fn parse(text: &str) -> Result<Fabric, FileError> {
    Fabric::from_ron_str(text, Path::new("test.ron"))
}

/// Replace the first occurrence of `from` in the base file.
fn mutated(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "base lacks {from}");
    BASE.replacen(from, to, 1)
}

/// Assert an error's kind, field and line; return it for further checks.
fn expect_error(text: &str, kind: ErrorKind, field: &str, line: usize) -> FileError {
    let e = parse(text).expect_err("must fail");
    assert_eq!(e.kind, kind, "{e}");
    assert_eq!(e.field, field, "{e}");
    assert_eq!(e.file, Path::new("test.ron"));
    let pos = e.position.unwrap_or_else(|| panic!("no position: {e}"));
    assert_eq!(pos.line, line, "{e}");
    assert!(pos.column > 0);
    e
}

#[test]
fn the_base_file_parses_into_si() {
    let f = parse(BASE).expect("valid");
    assert_relative_eq!(f.mass_per_area, 0.12, max_relative = 1e-12);
    assert_relative_eq!(f.thickness, 4e-4, max_relative = 1e-12);
    assert_relative_eq!(f.tensile.warp.apex_strain(), 0.035, max_relative = 1e-12);
    assert_relative_eq!(
        f.tensile.warp.max_force(),
        units::force_from_kes(500.0),
        max_relative = 1e-12
    );
    assert_relative_eq!(
        f.bending.weft.rigidity(),
        units::rigidity_from_kes(0.08),
        max_relative = 1e-12
    );
    assert_relative_eq!(
        f.bending.warp.residual_moment(),
        units::moment_from_kes(0.04),
        max_relative = 1e-12
    );
}

#[test]
fn nan_is_rejected_at_its_position() {
    let e = expect_error(
        &mutated("thickness_mm: 0.4", "thickness_mm: NaN"),
        ErrorKind::NotFinite,
        "thickness_mm",
        5,
    );
    assert!(e.to_string().starts_with("test.ron:5:"), "{e}");
}

#[test]
fn negative_mass_is_rejected() {
    expect_error(
        &mutated("mass_per_area_mg_cm2: 12.0", "mass_per_area_mg_cm2: -12.0"),
        ErrorKind::Negative,
        "mass_per_area_mg_cm2",
        4,
    );
}

#[test]
fn non_monotone_curve_is_rejected_with_the_point_index() {
    expect_error(
        &mutated(
            "(300.0, 3.0), (500.0, 3.5)],",
            "(300.0, 3.0), (200.0, 3.5)],",
        ),
        ErrorKind::NonMonotone,
        "tensile.warp.loading[3]",
        9,
    );
    expect_error(
        &mutated(
            "(300.0, 3.0), (500.0, 3.5)],",
            "(300.0, 1.0), (500.0, 3.5)],",
        ),
        ErrorKind::NonMonotone,
        "tensile.warp.loading[2]",
        9,
    );
}

#[test]
fn too_short_curve_is_rejected() {
    expect_error(
        &mutated(
            "loading: [(0.0, 0.0), (100.0, 2.0), (300.0, 3.0), (500.0, 3.5)],",
            "loading: [(0.0, 0.0)],",
        ),
        ErrorKind::TooShort,
        "tensile.warp.loading",
        9,
    );
}

#[test]
fn missing_direction_is_rejected() {
    let text = mutated(
        "        weft: Kes(lt: 0.7, emt_percent: 6.0, rt_percent: 50.0),\n",
        "",
    );
    let e = expect_error(&text, ErrorKind::MissingField, "tensile.weft", 12);
    assert!(e.message.contains("weft"), "{e}");
}

#[test]
fn unknown_field_is_rejected() {
    let e = expect_error(
        &mutated("friction: 0.5,", "friction: 0.5,\n    colour: \"red\","),
        ErrorKind::UnknownField,
        "colour",
        7,
    );
    assert!(e.message.contains("colour"), "{e}");
}

#[test]
fn wrong_type_is_rejected() {
    expect_error(
        &mutated("thickness_mm: 0.4", "thickness_mm: \"thin\""),
        ErrorKind::WrongType,
        "thickness_mm",
        5,
    );
}

#[test]
fn unknown_enum_variant_is_rejected() {
    expect_error(
        &mutated("weft: Kes(", "weft: Kawabata("),
        ErrorKind::UnknownVariant,
        "tensile.weft",
        12,
    );
}

#[test]
fn inconsistent_kes_values_are_rejected() {
    // WT must be 2.5·LT·EMT = 10.5 here.
    expect_error(
        &mutated("rt_percent: 50.0)", "rt_percent: 50.0, wt_gf_cm_cm2: 14.0)"),
        ErrorKind::Inconsistent,
        "tensile.weft.wt_gf_cm_cm2",
        12,
    );
    // Within the 2 % rounding tolerance it is accepted.
    parse(&mutated(
        "rt_percent: 50.0)",
        "rt_percent: 50.0, wt_gf_cm_cm2: 10.6)",
    ))
    .expect("rounded WT accepted");
    // An RT above 100 % is out of range.
    expect_error(
        &mutated("rt_percent: 50.0)", "rt_percent: 120.0)"),
        ErrorKind::OutOfRange,
        "tensile.weft.rt_percent",
        12,
    );
}

#[test]
fn locking_angle_must_lie_below_ninety_degrees() {
    expect_error(
        &mutated(
            "two_hg_gf_cm: 2.0)",
            "two_hg_gf_cm: 2.0, locking_angle_deg: 95.0)",
        ),
        ErrorKind::OutOfRange,
        "shear.locking_angle_deg",
        14,
    );
}

#[test]
fn crossing_branches_are_rejected() {
    expect_error(
        &mutated(
            "unloading: [(0.0, 1.5), (100.0, 2.8)",
            "unloading: [(0.0, 1.5), (100.0, 1.6)",
        ),
        ErrorKind::Inconsistent,
        "tensile.warp.unloading",
        11,
    );
}

#[test]
fn syntax_errors_are_reported() {
    let e = parse(&mutated("friction: 0.5,", "friction: 0.5,,")).expect_err("syntax");
    assert_eq!(e.kind, ErrorKind::Syntax, "{e}");
    assert_eq!(e.position.expect("position").line, 6);
}

#[test]
fn missing_bias_data_is_reported_after_parsing() {
    let e = parse(&mutated(
        "    shear: (g_gf_cm_deg: 1.2, two_hg_gf_cm: 2.0),\n",
        "",
    ))
    .expect_err("no bias");
    assert_eq!(e.kind, ErrorKind::MissingField);
    assert_eq!(e.field, "tensile.bias45");
}

#[test]
fn unreadable_file_is_an_io_error() {
    let e = Fabric::load(Path::new("/nonexistent/fabric.ron")).expect_err("io");
    assert_eq!(e.kind, ErrorKind::Io);
    assert!(e.to_string().contains("/nonexistent/fabric.ron"));
}

/// Every fixture loads, lies inside its class's bands, and keeps the published values it cites.
#[test]
fn fixtures_load_and_are_plausible() {
    for name in FIXTURES {
        let f = fixture(name);
        assert!(
            f.plausibility().is_empty(),
            "{name}: {:?}",
            f.plausibility()
        );
        assert!(!f.provenance.source.is_empty());
    }
    // Matsudaira et al. (2015): B, 2HB, W, T of the cotton broad.
    let c = fixture("cotton_broad");
    assert_relative_eq!(
        units::rigidity_to_kes(c.bending.warp.rigidity()),
        0.118,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        units::moment_to_kes(2.0 * c.bending.warp.residual_moment()),
        0.124,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        units::mass_per_area_to_kes(c.mass_per_area),
        12.38,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        units::thickness_to_kes(c.thickness),
        0.497,
        max_relative = 1e-12
    );
    // Bending lengths c = (B/W)^(1/3) of fabric-data.md §3: 2.120, 1.602, 1.877, 1.221 cm.
    for (name, c_cm) in [
        ("cotton_broad", 2.120),
        ("wool_tropical", 1.602),
        ("polyester_tropical", 1.877),
        ("polyester_faille", 1.221),
    ] {
        let f = fixture(name);
        let c = f
            .bending_length(0.0, atelier_fabric::AnisotropyForm::Thesis)
            .expect("defined");
        assert_relative_eq!(c * 100.0, c_cm, max_relative = 5e-4);
    }
}

/// The plausibility check flags a value outside its class's band (and only that value).
#[test]
fn plausibility_warns_outside_the_band() {
    let text = mutated(
        "mass_per_area_mg_cm2: 12.0,",
        "mass_per_area_mg_cm2: 60.0,\n    class: CottonBroadcloth,",
    );
    let f = parse(&text).expect("valid");
    let w = f.plausibility();
    assert!(
        w.iter().any(|w| w.quantity == "W" && w.band == (9.0, 14.0)),
        "{w:?}"
    );
    assert_eq!(f.class, Some(FabricClass::CottonBroadcloth));
    // Without a class only the envelope of all classes applies: 60 mg/cm² exceeds it too.
    let f = parse(&mutated(
        "mass_per_area_mg_cm2: 12.0,",
        "mass_per_area_mg_cm2: 60.0,",
    ))
    .expect("valid");
    assert_eq!(f.plausibility().len(), 1, "{:?}", f.plausibility());
}

/// The complete example in docs/fabric.md parses and is what the text says it is.
#[test]
fn the_documented_example_parses() {
    let doc = std::fs::read_to_string(root().join("docs/fabric.md")).expect("docs/fabric.md");
    let start = doc.find("```ron\n").expect("a ```ron block") + "```ron\n".len();
    let len = doc[start..].find("```").expect("closed block");
    let f = Fabric::from_ron_str(&doc[start..start + len], Path::new("docs/fabric.md"))
        .expect("example parses");
    assert!(f.plausibility().is_empty(), "{:?}", f.plausibility());
}

/// The base file with a measured shear loop instead of the KES values (lines 14–17).
fn with_measured_shear(upper: &str, lower: &str) -> String {
    mutated(
        "    shear: (g_gf_cm_deg: 1.2, two_hg_gf_cm: 2.0),\n",
        &format!(
            "    shear: (measured: (\n        upper: [{upper}],\n        lower: [{lower}],\n    )),\n"
        ),
    )
}

const UPPER: &str = "(-8.0, -11.4), (-5.0, -4.2), (-0.5, 0.4), (0.5, 1.6), (5.0, 7.8), (8.0, 11.4)";
const LOWER: &str =
    "(-8.0, -11.4), (-5.0, -7.8), (-0.5, -1.6), (0.5, -0.4), (5.0, 4.2), (8.0, 11.4)";

/// A measured shear loop is reduced to G, 2HG, 2HG5 as KES defines them: G = mean slope over
/// 0.5–5° = 1.2 gf/(cm·deg), 2HG = 2.0, 2HG5 = 3.6 gf/cm for these points.
#[test]
fn a_measured_shear_loop_parses_into_the_kes_values() {
    let f = parse(&with_measured_shear(UPPER, LOWER)).expect("valid");
    let s = f.shear.expect("shear");
    assert_relative_eq!(
        units::shear_stiffness_to_kes(s.stiffness),
        1.2,
        max_relative = 1e-12
    );
    assert_relative_eq!(units::force_to_kes(s.hysteresis), 2.0, max_relative = 1e-12);
    assert_relative_eq!(
        units::force_to_kes(s.hysteresis_5deg.expect("2HG5")),
        3.6,
        max_relative = 1e-12
    );
    let (got, want) = (
        f.shear_loop().expect("loop"),
        atelier_fabric::ShearLoop::from_kes_units(1.2, 2.0, Some(3.6)).expect("valid"),
    );
    for x in [0.0, 0.02, 0.06, 0.1] {
        assert_relative_eq!(got.upper(x), want.upper(x), max_relative = 1e-12);
        assert_relative_eq!(got.lower(x), want.lower(x), max_relative = 1e-12);
    }
    assert_relative_eq!(got.join_angle(), want.join_angle(), max_relative = 1e-12);
}

#[test]
fn measured_shear_nan_is_rejected_at_its_point() {
    expect_error(
        &with_measured_shear(&UPPER.replace("(-0.5, 0.4)", "(-0.5, NaN)"), LOWER),
        ErrorKind::NotFinite,
        "shear.measured.upper[2]",
        15,
    );
}

#[test]
fn measured_shear_in_wrong_units_is_rejected() {
    // Angles beyond ±30° (KES measures to ±8°).
    expect_error(
        &with_measured_shear(&UPPER.replace("(8.0, 11.4)", "(45.0, 11.4)"), LOWER),
        ErrorKind::OutOfRange,
        "shear.measured.upper[5]",
        15,
    );
    // Angles in radians: the branch does not reach ±5°.
    let radians = "(-0.14, -11.4), (-0.087, -7.8), (-0.0087, -1.6), (0.0087, -0.4), (0.087, 4.2), (0.14, 11.4)";
    let e = expect_error(
        &with_measured_shear(UPPER, radians),
        ErrorKind::OutOfRange,
        "shear.measured.lower",
        16,
    );
    assert!(e.message.contains("radians"), "{e}");
    // A whole-specimen force in gf rather than gf/cm.
    expect_error(
        &with_measured_shear(UPPER, &LOWER.replace("(8.0, 11.4)", "(8.0, 228.0)")),
        ErrorKind::OutOfRange,
        "shear.measured.lower[5]",
        16,
    );
}

#[test]
fn measured_shear_force_must_not_fall_along_a_branch() {
    expect_error(
        &with_measured_shear(UPPER, &LOWER.replace("(0.5, -0.4)", "(0.5, -2.0)")),
        ErrorKind::NonMonotone,
        "shear.measured.lower[3]",
        16,
    );
}

/// A branch whose angle turns back makes the loop cross itself.
#[test]
fn measured_shear_loop_crossing_itself_is_rejected() {
    let e = expect_error(
        &with_measured_shear(&UPPER.replace("(0.5, 1.6)", "(-1.0, 1.6)"), LOWER),
        ErrorKind::NonMonotone,
        "shear.measured.upper[3]",
        15,
    );
    assert!(e.message.contains("cross itself"), "{e}");
}

/// Branches that cross: swapped (the lower above the upper everywhere inside) or crossing near
/// +5° only (a figure of eight). The error names the first offending point.
#[test]
fn measured_shear_branches_that_cross_are_rejected() {
    expect_error(
        &with_measured_shear(LOWER, UPPER),
        ErrorKind::Inconsistent,
        "shear.measured.lower[1]",
        17,
    );
    expect_error(
        &with_measured_shear(UPPER, &LOWER.replace("(5.0, 4.2)", "(5.0, 8.5)")),
        ErrorKind::Inconsistent,
        "shear.measured.lower[4]",
        17,
    );
}

#[test]
fn measured_shear_with_too_few_points_is_rejected() {
    expect_error(
        &with_measured_shear("(-8.0, -11.4), (0.5, 1.6), (8.0, 11.4)", LOWER),
        ErrorKind::TooShort,
        "shear.measured.upper",
        15,
    );
}

/// A shear section gives the KES values or a measured loop: both is inconsistent, neither is a
/// missing G.
#[test]
fn shear_needs_kes_values_or_a_measured_loop_not_both() {
    let both = with_measured_shear(UPPER, LOWER).replace(
        "    shear: (measured: (",
        "    shear: (g_gf_cm_deg: 1.2, two_hg_gf_cm: 2.0, measured: (",
    );
    expect_error(&both, ErrorKind::Inconsistent, "shear.measured", 17);
    expect_error(
        &mutated(
            "shear: (g_gf_cm_deg: 1.2, two_hg_gf_cm: 2.0)",
            "shear: (two_hg_gf_cm: 2.0)",
        ),
        ErrorKind::MissingField,
        "shear.g_gf_cm_deg",
        14,
    );
    // KES values whose lower branch would fall between 0.5° and 5°.
    expect_error(
        &mutated(
            "two_hg_gf_cm: 2.0)",
            "two_hg_gf_cm: 2.0, two_hg5_gf_cm: 15.0)",
        ),
        ErrorKind::Inconsistent,
        "shear.two_hg5_gf_cm",
        14,
    );
}

/// A fabric description written back as RON (as `atelier fit` writes the fitted fabric, with
/// implicit `Some`) parses to the same description: KES shear values and a measured loop alike.
#[test]
fn fabric_specs_round_trip_through_ron() {
    use atelier_fabric::{FabricSpec, files};
    for text in [
        std::fs::read_to_string(root().join("fixtures/fabrics/cotton_broad.ron")).expect("fixture"),
        with_measured_shear(UPPER, LOWER),
    ] {
        let spec: FabricSpec = files::parse_ron(&text, Path::new("in.ron")).expect("parses");
        let pretty = ron::ser::PrettyConfig::new().depth_limit(4).extensions(
            ron::extensions::Extensions::IMPLICIT_SOME
                | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
        );
        let written = ron::ser::to_string_pretty(&spec, pretty).expect("serialises");
        let back: FabricSpec =
            files::parse_ron(&written, Path::new("out.ron")).expect("reads back");
        assert_eq!(back, spec, "{written}");
    }
}

/// The measured shear loop example of docs/fabric.md §7 parses (put into the complete example
/// in place of its KES shear values) and gives the values the text states.
#[test]
fn the_documented_measured_shear_loop_parses() {
    let doc = std::fs::read_to_string(root().join("docs/fabric.md")).expect("docs/fabric.md");
    let block = |from: usize| {
        let start = from + doc[from..].find("```ron\n").expect("a ```ron block") + "```ron\n".len();
        let len = doc[start..].find("```").expect("closed block");
        (start, &doc[start..start + len])
    };
    let (first_end, example) = block(0);
    let (_, shear) = block(first_end);
    let line = example
        .lines()
        .find(|l| l.trim_start().starts_with("shear:"))
        .expect("the example's shear line");
    let text = example.replacen(line, shear.trim_end(), 1);
    let f = Fabric::from_ron_str(&text, Path::new("docs/fabric.md")).expect("example parses");
    let s = f.shear.expect("shear");
    assert_relative_eq!(
        units::shear_stiffness_to_kes(s.stiffness),
        1.2,
        max_relative = 0.01
    );
    assert_relative_eq!(units::force_to_kes(s.hysteresis), 2.0, max_relative = 0.01);
    assert_relative_eq!(
        units::force_to_kes(s.hysteresis_5deg.expect("2HG5")),
        3.6,
        max_relative = 0.01
    );
}
