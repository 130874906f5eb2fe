//! `cargo xtask long-tests [--list]`: the tests kept out of `cargo test` for CI's time budget.
//!
//! CI (`.ci/run`, the README's test command) must finish in under 30 minutes on two cores. A
//! test whose simulations cost more than CI can pay is marked
//! `#[ignore = "long: <what it runs and how long>"]`: `cargo test` skips it, and this command
//! runs every such test, found in the sources (not kept in a list that could drift), with
//! `cargo test --workspace --release --lib --bins --test '*' -- --ignored NAME…` — the bench
//! targets left out, since criterion takes one filter only (several names are a usage error)
//! and would still build its scenes with `--ignored`. The other `#[ignore]`d tests — goals
//! that are missed, measurements that print tables — are not run by it.
//!
//! libtest selects the tests whose path contains one of the names, so a long test's name must
//! not be part of another ignored test's name; [`select`] refuses the run when it is.
//! `docs/validation.md` ("What CI runs") lists the long tests and their last measured times.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::layout::rust_files;

/// How a long test's `#[ignore]` reason begins.
pub const MARK: &str = "long:";

/// An `#[ignore]`d test of the sources.
#[derive(Debug, Clone, PartialEq)]
pub struct Ignored {
    /// The file, relative to the repository root.
    pub file: PathBuf,
    /// The line of its `#[ignore` attribute (1-based).
    pub line: usize,
    /// The function's name.
    pub name: String,
    /// The reason given (empty when none).
    pub reason: String,
}

impl Ignored {
    /// Whether it is one of the long tests.
    pub fn is_long(&self) -> bool {
        self.reason.starts_with(MARK)
    }
}

/// The `#[ignore]`d functions of one file's text: each `#[ignore…]` attribute and the first
/// `fn NAME` after it.
pub fn scan(file: &Path, text: &str) -> Vec<Ignored> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let t = line.trim_start();
        if t.starts_with("//") || !t.starts_with("#[ignore") {
            continue;
        }
        // The reason may continue over several lines until `"]`.
        let mut attribute = String::new();
        let mut k = i;
        while k < lines.len() {
            attribute.push_str(lines[k].trim());
            if lines[k].trim_end().ends_with(']') {
                break;
            }
            attribute.push(' ');
            k += 1;
        }
        let reason = attribute
            .split_once('"')
            .and_then(|(_, r)| r.rsplit_once('"'))
            .map_or(String::new(), |(r, _)| r.to_string());
        let name = lines[k.min(lines.len())..]
            .iter()
            .find_map(|l| {
                let l = l.trim_start();
                let rest = l
                    .strip_prefix("fn ")
                    .or_else(|| l.strip_prefix("async fn "))?;
                Some(
                    rest.chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect::<String>(),
                )
            })
            .unwrap_or_default();
        if !name.is_empty() {
            out.push(Ignored {
                file: file.to_path_buf(),
                line: i + 1,
                name,
                reason,
            });
        }
    }
    out
}

/// Every `#[ignore]`d test of `crates/` and `xtask/`.
pub fn ignored(root: &Path) -> Result<Vec<Ignored>> {
    let mut out = Vec::new();
    for dir in [root.join("crates"), root.join("xtask")] {
        for file in rust_files(&dir)? {
            let text =
                std::fs::read_to_string(&file).with_context(|| file.display().to_string())?;
            let rel = file.strip_prefix(root).unwrap_or(&file);
            out.extend(scan(rel, &text));
        }
    }
    Ok(out)
}

/// The long tests' names, checked to select no other ignored test.
pub fn select(all: &[Ignored]) -> Result<Vec<String>> {
    let long: Vec<&Ignored> = all.iter().filter(|t| t.is_long()).collect();
    for t in &long {
        if let Some(other) = all
            .iter()
            .find(|o| !o.is_long() && o.name.contains(&t.name))
        {
            bail!(
                "{}:{}: the long test `{}` would also select the ignored `{}` ({}:{}); rename one",
                t.file.display(),
                t.line,
                t.name,
                other.name,
                other.file.display(),
                other.line
            );
        }
    }
    let mut names: Vec<String> = long.iter().map(|t| t.name.clone()).collect();
    names.sort();
    names.dedup();
    Ok(names)
}

/// Lists the long tests, or runs them; `Ok(false)` when one failed.
pub fn run(root: &Path, list: bool) -> Result<bool> {
    let all = ignored(root)?;
    let names = select(&all)?;
    for t in all.iter().filter(|t| t.is_long()) {
        eprintln!("{}:{}: {} — {}", t.file.display(), t.line, t.name, t.reason);
    }
    if list || names.is_empty() {
        return Ok(true);
    }
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .current_dir(root)
        .args([
            "test",
            "--workspace",
            "--release",
            "--lib",
            "--bins",
            "--test",
            "*",
        ])
        .args(["--", "--ignored"])
        .args(&names)
        .status()
        .context("cargo test")?;
    Ok(status.success())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file's text, each line behind a `|` (so that this file's own scan finds none).
    const TEXT: &str = r#"
|#[test]
|fn quick() {}
|
|/// Doc.
|#[test]
|#[ignore = "long: three dresses, 3 s each (~10 min)"]
|fn three_dresses() {}
|
|#[test]
|#[ignore = "misses its goal: 0.78 mm"]
|fn a_goal() {}
|
|// #[ignore = "long: commented out"]
|#[test]
|#[ignore = "long: a reason written
| over two lines"]
|fn two_lines() {}
|"#;

    fn text() -> String {
        TEXT.lines()
            .map(|l| l.strip_prefix('|').unwrap_or(l))
            .collect::<Vec<_>>()
            .join("\n")
    }

    #[test]
    fn ignored_tests_are_read_with_their_reasons() {
        let found = scan(Path::new("t.rs"), &text());
        let names: Vec<(&str, bool)> = found
            .iter()
            .map(|t| (t.name.as_str(), t.is_long()))
            .collect();
        assert_eq!(
            names,
            [
                ("three_dresses", true),
                ("a_goal", false),
                ("two_lines", true)
            ]
        );
        assert_eq!(found[0].line, 7);
        assert_eq!(found[0].reason, "long: three dresses, 3 s each (~10 min)");
        assert_eq!(found[2].reason, "long: a reason written over two lines");
    }

    #[test]
    fn a_long_name_inside_another_ignored_name_is_refused() {
        let mut found = scan(Path::new("t.rs"), &text());
        assert_eq!(
            select(&found).expect("distinct"),
            ["three_dresses", "two_lines"]
        );
        found[1].name = "three_dresses_again".into();
        let e = select(&found).expect_err("ambiguous").to_string();
        assert!(
            e.contains("three_dresses_again") && e.contains("t.rs:7"),
            "{e}"
        );
    }

    /// The workspace's long tests can be selected, and every one says why it is long.
    #[test]
    fn the_workspaces_long_tests_are_selectable() {
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
        let all = ignored(&root).expect("read");
        let names = select(&all).expect("selectable");
        assert!(!names.is_empty());
        for t in all.iter().filter(|t| t.is_long()) {
            assert!(t.reason.len() > MARK.len() + 10, "{}: {}", t.name, t.reason);
        }
    }
}
