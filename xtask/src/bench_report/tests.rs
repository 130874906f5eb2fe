//! Tests of [`super`].

use super::*;

#[test]
fn durations_get_a_unit_and_three_digits() {
    assert_eq!(duration(1.5e-8), "15.0 ns");
    assert_eq!(duration(2.345e-4), "234 µs");
    assert_eq!(duration(0.0123), "12.3 ms");
    assert_eq!(duration(3.0), "3.00 s");
}

#[test]
fn the_scaling_slope_of_a_linear_table_is_one() {
    let dir = std::env::temp_dir().join(format!("atelier-slope-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("scaling.md");
    std::fs::write(
        &path,
        "| nodes | edges | 1 | 2 |\n|---|---|---|---|\n| 1 000 | 0 | 1 | 1 |\n| 10 000 | 0 | 5 | 10 |\n| 40 000 | 0 | 20 | 40 |\n",
    )
    .unwrap();
    assert!((scaling_slope(&path).unwrap() - 1.0).abs() < 1e-12);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_missing_input_names_the_template_line_and_writes_nothing() {
    let src = Sources {
        root: PathBuf::from("/nonexistent"),
        bench: PathBuf::from("/nonexistent/bench"),
        criterion: BTreeMap::new(),
        out: PathBuf::from("/nonexistent/out"),
    };
    let err = render("# title\n@@include bench/x.md\nok {{bench:a/b}}\n", &src)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(err.contains("performance.md.in:2"), "{err}");
    assert!(err.contains("performance.md.in:3"), "{err}");
}

#[test]
fn the_templates_scenarios_are_the_ones_the_report_runs() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("performance.md.in");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut named = Vec::new();
    for line in text.lines().filter_map(|l| l.strip_prefix("@@scenarios ")) {
        for item in line.split_whitespace() {
            named.push(item.split('=').next().unwrap().to_string());
        }
    }
    let mut run: Vec<String> = SCENARIOS.iter().map(|s| s.to_string()).collect();
    named.sort();
    run.sort();
    assert_eq!(
        named, run,
        "the template's @@scenarios and SCENARIOS differ"
    );
}
