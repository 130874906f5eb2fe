//! `cargo xtask check-layout`: the workspace's structural rules, read from the sources.
//!
//! - **No import cycle between the top-level modules of any crate.** A module is a file
//!   `src/X.rs` or a folder `src/X/` (with everything under it); module X depends on Y when a
//!   line of code in X names `crate::Y` (a `use`, a path, or one of the names of a grouped
//!   `use crate::{…}`). Comments and doc comments are not read: an intra-doc link is not an
//!   import. The graph's strongly connected components (Tarjan) of more than one module are the
//!   cycles reported.
//! - **No source file over [`MAX_LINES`] lines without a stated reason**: a longer file says why
//!   in its module doc, on a line beginning `//! Length:`.
//! - **Every test a table of `docs/validation.md` or `docs/claims.md` names exists** (issue 23:
//!   five rows named tests that had been removed or renamed, so their numbers were asserted by
//!   nothing): each `` `name` `` or `` `module::name` `` in the test cell of a table row (the
//!   last cell in validation.md, the third in claims.md) must be a `fn` somewhere in `crates/`
//!   or `xtask/`. A row that keeps a removed test's numbers as history names it without
//!   backticks.
//!
//! The same checks run as this module's tests, so `cargo test --workspace` (CI) keeps them.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// The longest a source file may be without saying why.
pub const MAX_LINES: usize = 800;

/// The crates' source folders, named by crate folder (`crates/*/src`, `xtask/src`).
fn source_roots(root: &Path) -> Result<Vec<(String, PathBuf)>> {
    let mut roots = Vec::new();
    for entry in std::fs::read_dir(root.join("crates")).context("crates/")? {
        let dir = entry?.path();
        let src = dir.join("src");
        if src.is_dir() {
            let name = dir.file_name().map(|n| n.to_string_lossy().into_owned());
            roots.push((name.unwrap_or_default(), src));
        }
    }
    roots.push(("xtask".into(), root.join("xtask/src")));
    roots.sort();
    Ok(roots)
}

/// Every `.rs` file under `dir`, sorted.
pub(crate) fn rust_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).with_context(|| d.display().to_string())? {
            let p = entry?.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// The top-level module a file of `src` belongs to (`None` for the crate root files).
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let first = rel
        .components()
        .next()?
        .as_os_str()
        .to_string_lossy()
        .into_owned();
    if rel.components().count() == 1 {
        let stem = first.strip_suffix(".rs")?;
        (!matches!(stem, "lib" | "main")).then(|| stem.to_string())
    } else if first == "bin" {
        None
    } else {
        Some(first)
    }
}

/// The top-level modules a piece of code names through `crate::`.
pub fn crate_references(code: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    for line in code.lines() {
        let line = line.trim_start();
        if line.starts_with("//") {
            continue;
        }
        let line = line.split(" //").next().unwrap_or(line);
        let mut rest = line;
        while let Some(i) = rest.find("crate::") {
            // `atelier_crate::x` or `my_crate::x` are not `crate::`.
            let before = rest[..i].chars().next_back();
            rest = &rest[i + "crate::".len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            if let Some(group) = rest.strip_prefix('{') {
                // `crate::{a, b::c, d::{e, f}}`: the first segment of each item at depth 0.
                let mut depth = 0usize;
                let mut item = String::new();
                let mut at_start = true;
                for c in group.chars() {
                    match c {
                        '{' => depth += 1,
                        '}' if depth == 0 => break,
                        '}' => depth -= 1,
                        ',' if depth == 0 => at_start = true,
                        _ => {}
                    }
                    if depth == 0 && at_start {
                        if c.is_alphanumeric() || c == '_' {
                            item.push(c);
                        } else if !item.is_empty() {
                            found.insert(std::mem::take(&mut item));
                            at_start = false;
                        }
                    }
                }
                if !item.is_empty() {
                    found.insert(item);
                }
            } else {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    found.insert(name);
                }
            }
        }
    }
    found
}

/// The import graph of one crate's top-level modules: module → the modules it names.
pub fn module_graph(src: &Path) -> Result<BTreeMap<String, BTreeSet<String>>> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in rust_files(src)? {
        let Some(module) = module_of(src, &file) else {
            continue;
        };
        let code = std::fs::read_to_string(&file).with_context(|| file.display().to_string())?;
        let refs = crate_references(&code);
        let entry = graph.entry(module.clone()).or_default();
        entry.extend(refs.into_iter().filter(|r| *r != module));
    }
    // Names that are not modules (items re-exported at the root, `crate::VERSION`) are dropped.
    let modules: BTreeSet<String> = graph.keys().cloned().collect();
    for deps in graph.values_mut() {
        deps.retain(|d| modules.contains(d));
    }
    Ok(graph)
}

/// The strongly connected components of more than one module (Tarjan), each sorted.
pub fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct Tarjan<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a str) {
            self.index.insert(v, self.next);
            self.low.insert(v, self.next);
            self.next += 1;
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.graph.get(v).into_iter().flatten() {
                let w = w.as_str();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let lw = self.low[w];
                    let lv = self.low.get_mut(v).expect("visited");
                    *lv = (*lv).min(lw);
                } else if self.on_stack.contains(w) {
                    let iw = self.index[w];
                    let lv = self.low.get_mut(v).expect("visited");
                    *lv = (*lv).min(iw);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    component.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.out.push(component);
                }
            }
        }
    }
    let mut t = Tarjan {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !t.index.contains_key(v.as_str()) {
            t.visit(v);
        }
    }
    t.out.sort();
    t.out
}

/// Files over [`MAX_LINES`] lines whose module doc has no `//! Length:` line, with their length.
fn long_files(src: &Path) -> Result<Vec<(PathBuf, usize)>> {
    let mut out = Vec::new();
    for file in rust_files(src)? {
        let code = std::fs::read_to_string(&file).with_context(|| file.display().to_string())?;
        let lines = code.lines().count();
        let stated = code
            .lines()
            .take_while(|l| l.starts_with("//!") || l.trim().is_empty())
            .any(|l| l.starts_with("//! Length:"));
        if lines > MAX_LINES && !stated {
            out.push((file, lines));
        }
    }
    Ok(out)
}

/// The documents whose tables name tests, with the cell that names them (`None`: the last).
const TEST_TABLES: [(&str, Option<usize>); 2] =
    [("docs/validation.md", None), ("docs/claims.md", Some(2))];

/// The tests the tables of [`TEST_TABLES`] name (the test cell's backticked names, the last path
/// segment of each) that are no `fn` of the sources, with the document and the line of the first
/// mention.
fn unknown_tests(root: &Path) -> Result<Vec<(String, String, usize)>> {
    let mut functions = BTreeSet::new();
    for dir in [root.join("crates"), root.join("xtask")] {
        for file in rust_files(&dir)? {
            let code =
                std::fs::read_to_string(&file).with_context(|| file.display().to_string())?;
            for rest in code.split("fn ").skip(1) {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                functions.insert(name);
            }
        }
    }
    let mut out: Vec<(String, String, usize)> = Vec::new();
    for (doc, column) in TEST_TABLES {
        let path = root.join(doc);
        let text = std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
        for (n, line) in text.lines().enumerate() {
            let Some(row) = line.strip_prefix('|') else {
                continue;
            };
            let cells: Vec<&str> = row.trim_end().trim_end_matches('|').split('|').collect();
            let cell = match column {
                None => cells.last(),
                Some(k) => cells.get(k),
            };
            for (k, quoted) in cell.copied().unwrap_or("").split('`').enumerate() {
                let is_path = !quoted.is_empty()
                    && quoted
                        .chars()
                        .all(|c| c.is_alphanumeric() || c == '_' || c == ':');
                if k % 2 == 1 && is_path {
                    let name = quoted.rsplit("::").next().unwrap_or(quoted).to_string();
                    if !functions.contains(&name) && !out.iter().any(|(m, ..)| *m == name) {
                        out.push((name, doc.to_string(), n + 1));
                    }
                }
            }
        }
    }
    Ok(out)
}

/// Every problem found, one line each (empty when the layout keeps its rules).
pub fn problems(root: &Path) -> Result<Vec<String>> {
    let mut out = Vec::new();
    for (name, doc, line) in unknown_tests(root)? {
        out.push(format!(
            "{doc}:{line}: names the test `{name}`, which is no fn of the sources"
        ));
    }
    for (name, src) in source_roots(root)? {
        for cycle in cycles(&module_graph(&src)?) {
            out.push(format!("{name}: import cycle among {}", cycle.join(", ")));
        }
        for (file, lines) in long_files(&src)? {
            let rel = file.strip_prefix(root).unwrap_or(&file);
            out.push(format!(
                "{}: {lines} lines (over {MAX_LINES}) and no `//! Length:` line saying why",
                rel.display()
            ));
        }
    }
    Ok(out)
}

/// `cargo xtask check-layout`: print the problems; fails when there are any.
pub fn main(root: &Path) -> Result<()> {
    let found = problems(root)?;
    for p in &found {
        eprintln!("{p}");
    }
    anyhow::ensure!(found.is_empty(), "{} layout problem(s)", found.len());
    #[allow(clippy::print_stdout)]
    {
        println!("layout: no import cycles, no unexplained file over {MAX_LINES} lines");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn references_are_read_from_code_not_comments() {
        let code = "use crate::run::{RunError, Simulated};\n\
                    use crate::{chart::Chart, export::{Animation, Frame}, report};\n\
                    // crate::commented\n\
                    /// [`crate::doc_link`]\n\
                    let x = crate::picture::CLOTH; // crate::trailing\n\
                    use atelier_crate::not_this;\n";
        let refs: Vec<String> = crate_references(code).into_iter().collect();
        assert_eq!(refs, ["chart", "export", "picture", "report", "run"]);
    }

    #[test]
    fn a_cycle_is_found_and_a_chain_is_not() {
        let graph = |edges: &[(&str, &str)]| {
            let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
            for (a, b) in edges {
                g.entry((*a).into()).or_default().insert((*b).into());
                g.entry((*b).into()).or_default();
            }
            g
        };
        assert!(cycles(&graph(&[("a", "b"), ("b", "c"), ("a", "c")])).is_empty());
        assert_eq!(
            cycles(&graph(&[("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")])),
            vec![vec!["a".to_string(), "b".into(), "c".into()]]
        );
    }

    #[test]
    fn the_workspace_keeps_its_layout_rules() {
        let found = problems(&crate::repository_root()).expect("sources readable");
        assert!(found.is_empty(), "layout problems:\n{}", found.join("\n"));
    }
}
