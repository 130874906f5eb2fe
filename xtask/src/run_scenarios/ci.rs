//! Which scenarios `cargo test` runs in full: the two lists of `fixtures/scenarios/CI.md` (each
//! `- name` line under its heading), read by the test below — which runs the first list as
//! `cargo xtask run-scenarios` runs a scenario and asserts every expectation of each (issue 23:
//! scenario expectations had never run in CI) — and by `run-scenarios` for the column "in CI" of
//! `docs/results.md`. Every scenario file must be in exactly one list, so none is left out
//! silently; the long ones (drapes, dresses, wet scenes: 7–190 s each, about 20 minutes
//! together) run in full only in `run-scenarios`.
//!
//! A scenario's expectations are checked for binding when the file is read (an interval covering
//! the metric's whole physical range is refused, `atelier::scenario::bounds`), so a scenario that
//! passes here could have failed.

use std::path::Path;

use anyhow::{Context, Result, bail};

/// The file holding the lists, relative to the repository.
pub const FILE: &str = "fixtures/scenarios/CI.md";

/// The scenarios run in full by `cargo test`, and those run only by `run-scenarios`.
pub struct Lists {
    /// Run in full by `cargo test`.
    pub full: Vec<String>,
    /// Run only by `cargo xtask run-scenarios`.
    pub long: Vec<String>,
}

/// Read the two lists.
pub fn lists(root: &Path) -> Result<Lists> {
    let path = root.join(FILE);
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let mut lists = Lists {
        full: Vec::new(),
        long: Vec::new(),
    };
    let mut section = 0;
    for (n, line) in text.lines().enumerate() {
        if line.starts_with("## ") {
            section += 1;
        } else if let Some(item) = line.strip_prefix("- ") {
            let name = item
                .split_whitespace()
                .next()
                .unwrap_or_default()
                .to_owned();
            match section {
                1 => lists.full.push(name),
                2 => lists.long.push(name),
                _ => bail!("{FILE}:{}: a list item outside the two sections", n + 1),
            }
        }
    }
    Ok(lists)
}

#[cfg(test)]
mod tests {
    use super::super::{run_one, scenario_files, stem};
    use super::*;

    fn root() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
    }

    /// Every scenario file is in exactly one list, and every listed name is a file.
    #[test]
    fn every_scenario_file_is_in_one_list() {
        let root = root();
        let names: Vec<String> = scenario_files(&root)
            .expect("scenarios")
            .iter()
            .map(|f| stem(f))
            .collect();
        let l = lists(&root).expect("CI.md");
        assert!(l.full.len() >= 10, "{:?}", l.full);
        for name in &names {
            let (q, g) = (l.full.contains(name), l.long.contains(name));
            assert!(
                q != g,
                "{name}: in the full list {q}, in the long list {g} ({FILE})"
            );
        }
        for listed in l.full.iter().chain(&l.long) {
            assert!(
                names.contains(listed),
                "{FILE} names {listed}: no such scenario file"
            );
        }
    }

    /// The scenarios of the first list run in full, as `run-scenarios` runs them, and meet
    /// every expectation their files state; each states at least one.
    #[test]
    fn the_scenarios_run_in_ci_meet_their_expectations() {
        let root = root();
        let out = std::env::temp_dir().join(format!("atelier-ci-scenarios-{}", std::process::id()));
        let files = scenario_files(&root).expect("scenarios");
        let mut failures = Vec::new();
        for name in lists(&root).expect("CI.md").full {
            let file = files.iter().find(|f| stem(f) == name).expect("listed file");
            let row = run_one(&root, file, &out);
            eprintln!("{name}: {:.1} s", row.wall_s);
            let report = row.report.as_ref();
            assert!(
                report.is_none_or(|r| !r.expectations.is_empty()),
                "{name}: no expectation"
            );
            if !row.passed() {
                failures.push(format!("{name}: {:?} {:?}", row.unmet, row.failure));
            }
        }
        std::fs::remove_dir_all(&out).ok();
        assert!(failures.is_empty(), "not met:\n{}", failures.join("\n"));
    }
}
