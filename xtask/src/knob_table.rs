//! `cargo xtask knob-table [--check]`: the table of the step's knobs in `docs/solver.md`,
//! generated so that the docs cannot disagree with the code.
//!
//! The defaults come from `atelier_solver::StepParams::default()`, serialized field by field
//! (serde_json, rendered in Rust/RON notation: `Direct { refactor_after: 4 }`). The words come
//! from the source: `crates/solver/src/params.rs` is read for the `pub field: Type,` lines of
//! `StepParams` and their `///` doc comments (a field whose type is another struct there, a
//! stage's group, expands to its fields as `group.field`), and for the enums a field's type names (also in a
//! module that params.rs `use`s from the crate, e.g. `shear_angle::ShearMeasure`): their variants,
//! the variants' fields and their doc comments. The unit is what a doc comment's first clause
//! names after its last comma (`Time step Δt, s.`), or a doc comment that is only a unit
//! (`m/s.`); the range is the text after `Range ` up to the next `;`, and where a doc comment
//! states none (the fields of variants, `gravity`) the range string of the field's
//! `check("name", …, "range")` in `validate()`.
//!
//! Generation fails when a field's doc comment states a default (`default 0.01`, `Default
//! true`, ``Default `Direct { refactor_after: 4 }` ``) other than `StepParams::default()`'s, or
//! a variant documented as "The default." is not the default.
//!
//! The table is written between `<!-- knob-table:begin -->` and `<!-- knob-table:end -->`
//! (atomically). `--check` writes nothing and fails when the file differs from what would be
//! written; the unit test `docs_solver_md_is_in_sync` does the same under `cargo test
//! --workspace`.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result, bail};
use atelier_solver::StepParams;
use serde_json::Value;

/// The marker opening the generated table.
pub const BEGIN: &str = "<!-- knob-table:begin -->";
/// The marker closing the generated table.
pub const END: &str = "<!-- knob-table:end -->";

/// The file holding the table, relative to the repository.
const DOC: &str = "docs/solver.md";
/// The parameters' source, relative to the repository.
const PARAMS: &str = "crates/solver/src/params.rs";

/// A field of a struct or of an enum variant, with its doc comment (lines joined by spaces).
#[derive(Clone, Debug)]
struct Field {
    name: String,
    ty: String,
    doc: String,
}

/// An enum variant.
#[derive(Clone, Debug)]
struct Variant {
    name: String,
    doc: String,
    fields: Vec<Field>,
}

/// A struct (fields) or an enum (variants) of the source.
#[derive(Clone, Debug)]
enum Item {
    Struct(Vec<Field>),
    Enum(Vec<Variant>),
}

/// The items of one source file by name, and the `use crate::module::Name;` imports.
#[derive(Default, Debug)]
struct Source {
    items: Vec<(String, String, Item)>,
    imports: Vec<(String, String)>,
}

impl Source {
    fn item(&self, name: &str) -> Option<&Item> {
        self.items
            .iter()
            .find(|(n, _, _)| n == name)
            .map(|(_, _, item)| item)
    }
}

/// Net brace depth change of a line of code (string literals in the scanned files hold no
/// braces where it matters: only struct and enum bodies are read).
fn brace_delta(line: &str) -> i32 {
    line.chars().fold(0, |d, c| match c {
        '{' => d + 1,
        '}' => d - 1,
        _ => d,
    })
}

/// Read the `pub struct` and `pub enum` items at the top level of a Rust file with their doc
/// comments, and its `use crate::…::Name;` imports.
fn parse_source(text: &str) -> Source {
    let mut source = Source::default();
    let mut doc: Vec<String> = Vec::new();
    let mut depth = 0i32;
    // The item being read: name, doc, body, and for an enum the variant being read.
    let mut current: Option<(String, String, Item)> = None;
    for raw in text.lines() {
        let line = raw.trim();
        if let Some(d) = line.strip_prefix("///") {
            doc.push(d.trim().to_string());
            continue;
        }
        if line.starts_with("#[") || line.starts_with("//") || line.is_empty() {
            continue;
        }
        let joined = doc.join(" ");
        doc.clear();
        if depth == 0 {
            if let Some(rest) = line.strip_prefix("use crate::") {
                let path = rest.trim_end_matches(';');
                if let Some((module, name)) = path.rsplit_once("::")
                    && !name.contains('{')
                {
                    source
                        .imports
                        .push((module.replace("::", "/"), name.to_string()));
                }
            }
            let kind = if let Some(rest) = line.strip_prefix("pub struct ") {
                Some((rest, Item::Struct(Vec::new())))
            } else {
                line.strip_prefix("pub enum ")
                    .map(|rest| (rest, Item::Enum(Vec::new())))
            };
            if let Some((rest, item)) = kind {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if line.ends_with('{') {
                    current = Some((name, joined, item));
                }
            }
        } else if let Some((_, _, item)) = current.as_mut() {
            match item {
                Item::Struct(fields) if depth == 1 => {
                    if let Some(rest) = line.strip_prefix("pub ")
                        && let Some((name, ty)) = rest.split_once(':')
                    {
                        fields.push(Field {
                            name: name.trim().to_string(),
                            ty: ty.trim().trim_end_matches(',').trim().to_string(),
                            doc: joined,
                        });
                    }
                }
                Item::Enum(variants) if depth == 1 => {
                    let name: String = line
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    if !name.is_empty() {
                        variants.push(Variant {
                            name,
                            doc: joined,
                            fields: Vec::new(),
                        });
                    }
                }
                Item::Enum(variants) if depth == 2 => {
                    if let (Some(variant), Some((name, ty))) =
                        (variants.last_mut(), line.split_once(':'))
                    {
                        variant.fields.push(Field {
                            name: name.trim().to_string(),
                            ty: ty.trim().trim_end_matches(',').trim().to_string(),
                            doc: joined,
                        });
                    }
                }
                _ => {}
            }
        }
        depth += brace_delta(line);
        if depth == 0
            && let Some(done) = current.take()
        {
            source.items.push(done);
        }
    }
    source
}

/// A JSON value in Rust/RON notation: `Direct { refactor_after: 4 }`, `[0.0, 0.0, -9.80665]`.
fn render(value: &Value) -> String {
    match value {
        Value::Null => "None".to_string(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        Value::String(s) => s.clone(),
        Value::Array(items) => {
            let items: Vec<String> = items.iter().map(render).collect();
            format!("[{}]", items.join(", "))
        }
        Value::Object(map) => {
            let fields = |m: &serde_json::Map<String, Value>| -> String {
                m.iter()
                    .map(|(k, v)| format!("{k}: {}", render(v)))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            match map.iter().next() {
                // An enum variant with fields, as serde's externally tagged form.
                Some((variant, Value::Object(inner))) if map.len() == 1 => {
                    format!("{variant} {{ {} }}", fields(inner))
                }
                _ => format!("{{ {} }}", fields(map)),
            }
        }
    }
}

/// The variant a default value is (unit variant as a string, otherwise the single key).
fn variant_of(value: &Value) -> Option<&str> {
    match value {
        Value::String(s) => Some(s),
        Value::Object(map) if map.len() == 1 => map.keys().next().map(String::as_str),
        _ => None,
    }
}

/// A doc comment as table text: rustdoc links unwrapped, pipes escaped.
fn cell(doc: &str) -> String {
    doc.replace("[`", "`")
        .replace("`]", "`")
        .replace('|', "\\|")
}

/// The unit a doc comment names: the text after the last comma of its first clause
/// (`Time step Δt, s.`), or a leading lower-case word followed by a comma or full stop (`m/s.`).
fn unit(doc: &str) -> String {
    let end = [doc.find(". "), doc.find(": ")]
        .into_iter()
        .flatten()
        .min()
        .unwrap_or(doc.len());
    let clause = doc[..end].trim_end_matches('.');
    let looks_like_unit =
        |u: &str| !u.is_empty() && !u.contains(' ') && !u.contains('`') && u.chars().count() <= 12;
    if let Some((_, candidate)) = clause.rsplit_once(", ")
        && looks_like_unit(candidate)
    {
        return candidate.to_string();
    }
    let lead: String = doc
        .chars()
        .take_while(|c| !c.is_whitespace() && *c != ',')
        .collect();
    let lead = lead.trim_end_matches('.');
    let followed = doc[lead.len()..].starts_with(',') || doc[lead.len()..].starts_with('.');
    if followed && lead.chars().next().is_some_and(char::is_lowercase) && looks_like_unit(lead) {
        return lead.to_string();
    }
    String::new()
}

/// The range a doc comment states: the text after `Range ` up to the next `;`.
fn doc_range(doc: &str) -> String {
    doc.find("Range ")
        .map(|at| {
            let rest = &doc[at + "Range ".len()..];
            rest.split(';').next().unwrap_or("").trim().to_string()
        })
        .unwrap_or_default()
}

/// The range string of `check("name", …, "range")` in the source, if any: the string literal
/// after the name in a call of `check` whose first argument is the name.
fn checked_range(source: &str, name: &str) -> Option<String> {
    let quoted = format!("\"{name}\"");
    let at = source
        .match_indices(&quoted)
        .map(|(at, _)| at)
        .find(|&at| source[..at].trim_end().ends_with("check("))?;
    let rest = &source[at + quoted.len()..];
    let open = rest.find('"')?;
    let rest = &rest[open + 1..];
    let close = rest.find('"')?;
    Some(rest[..close].to_string())
}

/// Check the defaults a field's doc comment states against the serialized default.
fn check_stated_default(field: &str, doc: &str, value: &Value) -> Result<()> {
    let lower = doc.to_lowercase();
    let mut from = 0;
    while let Some(at) = lower[from..].find("default ") {
        let start = from + at + "default ".len();
        from = start;
        let stated = &doc[start..];
        let mismatch = if let Some(code) = stated.strip_prefix('`') {
            // ``Default `Direct { refactor_after: 4 }` ``: the whole value in Rust notation.
            let code = code.split('`').next().unwrap_or("");
            (code != render(value)).then(|| code.to_string())
        } else if let Some(tuple) = stated.strip_prefix('(') {
            // `Default (0, 0, −9.80665)`: an array, element by element.
            let tuple = tuple.split(')').next().unwrap_or("");
            let numbers: Vec<Option<f64>> = tuple
                .split(',')
                .map(|x| x.trim().replace('−', "-").parse::<f64>().ok())
                .collect();
            match value {
                Value::Array(items) if numbers.iter().all(Option::is_some) => {
                    let same = items.len() == numbers.len()
                        && items
                            .iter()
                            .zip(&numbers)
                            .all(|(v, n)| same_number(v, n.unwrap_or(f64::NAN)));
                    (!same).then(|| format!("({tuple})"))
                }
                _ => None,
            }
        } else {
            let word: String = stated
                .chars()
                .take_while(|c| !c.is_whitespace() && !matches!(c, ';' | ',' | ')' | '('))
                .collect();
            let word = word.trim_end_matches('.');
            match (word, value) {
                ("true" | "false", Value::Bool(b)) => (word != b.to_string()).then(|| word.into()),
                (_, Value::Number(_)) => word
                    .replace('−', "-")
                    .parse::<f64>()
                    .ok()
                    .filter(|n| !same_number(value, *n))
                    .map(|_| word.to_string()),
                _ => None,
            }
        };
        if let Some(stated) = mismatch {
            bail!(
                "{PARAMS}: the doc comment of `{field}` says the default is {stated}, \
                 StepParams::default() has {}",
                render(value)
            );
        }
    }
    Ok(())
}

fn same_number(value: &Value, n: f64) -> bool {
    value
        .as_f64()
        .is_some_and(|v| (v - n).abs() <= 1e-12 * v.abs().max(n.abs()))
}

/// The generated Markdown between the markers (without them).
pub fn generate(root: &Path) -> Result<String> {
    let params_text =
        std::fs::read_to_string(root.join(PARAMS)).with_context(|| format!("reading {PARAMS}"))?;
    let params = parse_source(&params_text);
    let Some(Item::Struct(fields)) = params.item("StepParams") else {
        bail!("{PARAMS}: no `pub struct StepParams {{` found");
    };
    // The enums a field may name: those of params.rs and of the modules it imports them from.
    let mut items = params.items.clone();
    for (module, name) in &params.imports {
        let path = format!("crates/solver/src/{module}.rs");
        let text =
            std::fs::read_to_string(root.join(&path)).with_context(|| format!("reading {path}"))?;
        items.extend(
            parse_source(&text)
                .items
                .into_iter()
                .filter(|(n, _, _)| n == name),
        );
    }
    let find_enum = |ty: &str| {
        items.iter().find_map(|(n, _, item)| match item {
            Item::Enum(variants) if n == ty => Some(variants.clone()),
            _ => None,
        })
    };

    let defaults = serde_json::to_value(StepParams::default())?;
    let Value::Object(defaults) = defaults else {
        bail!("StepParams did not serialize to a map");
    };

    let mut out = String::new();
    writeln!(
        out,
        "<!-- generated by `cargo xtask knob-table` from `StepParams::default()` and the doc \
         comments of `{PARAMS}`; edit those, then run it (`--check` tests it) -->"
    )?;
    writeln!(out)?;
    writeln!(out, "| knob | default | unit | range | what |")?;
    writeln!(out, "|---|---|---|---|---|")?;
    // A field whose type is a struct of params.rs (a stage's group: `ShapeParams`, …) stands
    // for its fields, named `group.field` as in a scenario file's `step: (shape: (…))`.
    let mut knobs: Vec<(Field, Value)> = Vec::new();
    for field in fields {
        let value = defaults
            .get(&field.name)
            .with_context(|| format!("`{}` is not a serialized field of StepParams", field.name))?;
        match params.item(&field.ty) {
            Some(Item::Struct(inner)) => {
                for f in inner {
                    let v = value.get(&f.name).with_context(|| {
                        format!("`{}.{}` is not a serialized field", field.name, f.name)
                    })?;
                    knobs.push((
                        Field {
                            name: format!("{}.{}", field.name, f.name),
                            ty: f.ty.clone(),
                            doc: f.doc.clone(),
                        },
                        v.clone(),
                    ));
                }
            }
            _ => knobs.push((field.clone(), value.clone())),
        }
    }
    let mut enums = Vec::new();
    for (field, value) in &knobs {
        check_stated_default(&field.name, &field.doc, value)?;
        let mut range = doc_range(&field.doc);
        if range.is_empty() {
            range = checked_range(&params_text, &field.name).unwrap_or_default();
        }
        if field.ty == "bool" && range.is_empty() {
            range = "true, false".to_string();
        }
        if let Some(variants) = find_enum(&field.ty) {
            if range.is_empty() {
                range = variants
                    .iter()
                    .map(|v| format!("`{}`", v.name))
                    .collect::<Vec<_>>()
                    .join(", ");
            }
            enums.push((field, variants, value));
        }
        writeln!(
            out,
            "| `{}` | `{}` | {} | {} | {} |",
            field.name,
            render(value),
            cell(&unit(&field.doc)),
            cell(&range),
            cell(&field.doc)
        )?;
    }
    if !enums.is_empty() {
        writeln!(out)?;
        writeln!(
            out,
            "The variants of the knobs that choose (★ the default):"
        )?;
        writeln!(out)?;
        writeln!(out, "| knob | variant | what |")?;
        writeln!(out, "|---|---|---|")?;
        let mut variant_fields = Vec::new();
        for (field, variants, value) in &enums {
            let default = variant_of(value);
            if let Some(stated) = variants.iter().find(|v| v.doc.contains("The default."))
                && Some(stated.name.as_str()) != default
            {
                bail!(
                    "the doc comment of `{}::{}` says it is the default, \
                     StepParams::default() has `{}: {}`",
                    field.ty,
                    stated.name,
                    field.name,
                    render(value)
                );
            }
            for (i, variant) in variants.iter().enumerate() {
                let names: Vec<&str> = variant.fields.iter().map(|f| f.name.as_str()).collect();
                let shape = if names.is_empty() {
                    variant.name.clone()
                } else {
                    format!("{} {{ {} }}", variant.name, names.join(", "))
                };
                let star = if default == Some(variant.name.as_str()) {
                    " ★"
                } else {
                    ""
                };
                let knob = if i == 0 {
                    format!("`{}`", field.name)
                } else {
                    String::new()
                };
                writeln!(out, "| {knob} | `{shape}`{star} | {} |", cell(&variant.doc))?;
                for f in &variant.fields {
                    let inner = match value {
                        Value::Object(map) => map
                            .get(&variant.name)
                            .and_then(|v| v.get(&f.name))
                            .map(|v| format!("`{}`", render(v))),
                        _ => None,
                    };
                    let range = checked_range(&params_text, &format!("{}.{}", field.name, f.name))
                        .unwrap_or_else(|| doc_range(&f.doc));
                    variant_fields.push((
                        format!("{}.{}.{}", field.name, variant.name, f.name),
                        inner.unwrap_or_else(|| "—".to_string()),
                        unit(&f.doc),
                        range,
                        f.doc.clone(),
                    ));
                }
            }
        }
        if !variant_fields.is_empty() {
            writeln!(out)?;
            writeln!(
                out,
                "Their fields (the default only where the variant is the default; the range as \
                 `validate()` checks it):"
            )?;
            writeln!(out)?;
            writeln!(out, "| field | default | unit | range | what |")?;
            writeln!(out, "|---|---|---|---|---|")?;
            for (name, default, unit, range, doc) in variant_fields {
                writeln!(
                    out,
                    "| `{name}` | {default} | {} | {} | {} |",
                    cell(&unit),
                    cell(&range),
                    cell(&doc)
                )?;
            }
        }
    }
    Ok(out)
}

/// `document` with the text between the markers replaced by `table`.
fn splice(document: &str, table: &str) -> Result<String> {
    let (Some(begin), Some(end)) = (document.find(BEGIN), document.find(END)) else {
        bail!("{DOC} has no `{BEGIN}` … `{END}` markers");
    };
    if end < begin {
        bail!("{DOC}: `{END}` before `{BEGIN}`");
    }
    Ok(format!(
        "{}{BEGIN}\n{table}{}",
        &document[..begin],
        &document[end..]
    ))
}

/// What `docs/solver.md` should be, and what it is.
fn expected_and_actual(root: &Path) -> Result<(String, String)> {
    let actual =
        std::fs::read_to_string(root.join(DOC)).with_context(|| format!("reading {DOC}"))?;
    let expected = splice(&actual, &generate(root)?)?;
    Ok((expected, actual))
}

/// Regenerate the table in `docs/solver.md` (atomically), or with `check` only compare:
/// `Ok(false)` when the file is out of date.
pub fn run(root: &Path, check: bool) -> Result<bool> {
    let (expected, actual) = expected_and_actual(root)?;
    if check {
        return Ok(expected == actual);
    }
    if expected != actual {
        atelier_files::files::write_atomic(&root.join(DOC), expected.as_bytes())?;
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn docs_solver_md_is_in_sync() {
        let root = crate::repository_root();
        let (expected, actual) = expected_and_actual(&root).expect("knob table generated");
        assert!(
            expected == actual,
            "docs/solver.md's knob table is out of date: run `cargo xtask knob-table`"
        );
    }

    #[test]
    fn units_ranges_and_stated_defaults_are_read() {
        assert_eq!(unit("Time step Δt, s. Range (0, 0.1]; default 0.01."), "s");
        assert_eq!(
            unit("Linear damping per area c/S (air drag), kg/(m²·s). Range"),
            "kg/(m²·s)"
        );
        assert_eq!(
            unit("Reversal dead band of the shear loop, rad: an angle"),
            "rad"
        );
        assert_eq!(unit("m/s, below `fast_speed`."), "m/s");
        assert_eq!(
            unit("Where the edges' axial forces come from. Default `Constraint`."),
            ""
        );
        assert_eq!(
            doc_range("Time step Δt, s. Range (0, 0.1]; default 0.01."),
            "(0, 0.1]"
        );
        let v = serde_json::json!(0.01);
        assert!(check_stated_default("dt", "Range (0, 0.1]; default 0.01 (x).", &v).is_ok());
        assert!(check_stated_default("dt", "Range (0, 0.1]; default 0.02.", &v).is_err());
        let v = serde_json::json!({"Direct": {"refactor_after": 4}});
        assert!(check_stated_default("m", "Default `Direct { refactor_after: 4 }`.", &v).is_ok());
        assert!(check_stated_default("m", "Default `Direct { refactor_after: 5 }`.", &v).is_err());
        let v = serde_json::json!([0.0, 0.0, -9.80665]);
        assert!(check_stated_default("g", "Gravity, m/s². Default (0, 0, −9.80665).", &v).is_ok());
        assert!(check_stated_default("g", "Gravity, m/s². Default (0, 0, −9.81).", &v).is_err());
    }
}
