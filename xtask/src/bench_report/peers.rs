//! The peers' rows of the report: the other solvers' results on the peers' scene, read from
//! `benches/peers/`, their table and figure, and the goal row.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use plotters::prelude::*;
use serde::Deserialize;

use crate::figures::plot;

use super::Sources;

/// One peer's results (`benches/peers/README.md` has the schema).
#[derive(Deserialize)]
struct PeerFile {
    peer: String,
    threads: usize,
    rows: Vec<PeerRow>,
    #[serde(default)]
    differences: Vec<String>,
}

#[derive(Deserialize, Clone)]
struct PeerRow {
    scene: String,
    /// Nodes per side of the sheet (none for the drape).
    side: Option<usize>,
    setting: String,
    ms_per_step: Option<f64>,
    stretch_end: Option<f64>,
    stretch_max: Option<f64>,
    diverged_at_s: Option<f64>,
    drape_coefficient: Option<f64>,
    note: Option<String>,
}

fn peer_files(src: &Sources) -> Result<Vec<PeerFile>> {
    let mut files = Vec::new();
    for path in [
        src.bench.join("peers_party.json"),
        src.out.join("peers/peers_rapier.json"),
        src.out.join("peers/peers_pypbd.json"),
    ] {
        let text = std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
        files.push(
            serde_json::from_str(&text).with_context(|| format!("reading {}", path.display()))?,
        );
    }
    Ok(files)
}

fn percent(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{:.2} %", 100.0 * v))
}

/// The peers' table for one sheet size (and the drape rows with `drape`), with the figure of
/// time per step against stretch drawn beside it.
pub(super) fn peers_table(
    arg: &str,
    src: &Sources,
    figures: &mut Vec<(PathBuf, PathBuf)>,
) -> Result<String> {
    let files = peer_files(src)?;
    if arg == "drape" {
        let mut t = String::from(
            "| solver | setting | ms/step | drape coefficient | note |\n|---|---|---|---|---|\n",
        );
        // PARTY: the JIS drape scenario of the benchmark scenarios.
        let path = src.out.join("scenarios/drape_jis_cotton_broad/report.json");
        let text = std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
        let r: serde_json::Value = serde_json::from_str(&text)?;
        let steps = r["steps"].as_f64().unwrap_or(f64::NAN);
        let _ = writeln!(
            t,
            "| atelier PARTY | `drape_jis_cotton_broad`: {} nodes, Δt 1 ms, {:.1} s: the annulus outside the support, its rim ring and one ring inside it pinned (clamped, as the tester holds it; hinged until session 21) | {:.2} | {:.1} % | published for this fabric: 82.9 % (Matsudaira et al. 2015) |",
            r["nodes"].as_u64().unwrap_or(0),
            r["simulated_s"].as_f64().unwrap_or(f64::NAN),
            r["stage_s"]["total"].as_f64().unwrap_or(f64::NAN) / steps * 1e3,
            r["metrics"]["drape_coefficient_percent"]
                .as_f64()
                .unwrap_or(f64::NAN),
        );
        for f in &files {
            for r in f.rows.iter().filter(|r| r.scene == "drape") {
                let _ = writeln!(
                    t,
                    "| {} | {} | {} | {} | {} |",
                    f.peer,
                    r.setting,
                    r.ms_per_step.map_or("—".into(), |v| format!("{v:.2}")),
                    percent(r.drape_coefficient),
                    r.note.clone().unwrap_or_default()
                );
            }
        }
        return Ok(t.trim_end().to_string());
    }
    if arg == "differences" {
        let mut t = String::new();
        for f in files.iter().filter(|f| !f.differences.is_empty()) {
            let _ = writeln!(
                t,
                "{} ({} thread{}):\n",
                f.peer,
                f.threads,
                if f.threads == 1 { "" } else { "s" }
            );
            for d in &f.differences {
                let _ = writeln!(t, "- {d}");
            }
            t.push('\n');
        }
        return Ok(t.trim_end().to_string());
    }
    let side: usize = arg.parse().context("@@peers SIDE | drape | differences")?;
    let mut t = String::from(
        "| solver | setting | threads | ms/step | largest stretch at 2 s | over the run | diverged at |\n|---|---|---|---|---|---|---|\n",
    );
    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for f in &files {
        let mut points = Vec::new();
        for r in f
            .rows
            .iter()
            .filter(|r| r.scene == "sheet" && r.side == Some(side))
        {
            let _ = writeln!(
                t,
                "| {} | {} | {} | {} | {} | {} | {} |",
                f.peer,
                r.setting,
                f.threads,
                r.ms_per_step.map_or("—".into(), |v| format!("{v:.2}")),
                percent(r.stretch_end),
                percent(r.stretch_max),
                r.diverged_at_s.map_or("—".into(), |s| format!("{s:.2} s")),
            );
            if let (Some(ms), Some(s)) = (r.ms_per_step, r.stretch_end)
                && r.diverged_at_s.is_none()
            {
                points.push((ms, s.max(1e-4)));
            }
        }
        series.push((f.peer.clone(), points));
    }
    let name = format!("peers_{side}.png");
    let dir = src.out.join("figures/peers");
    std::fs::create_dir_all(&dir)?;
    figures.push((dir.join(&name), src.root.join("docs/img/peers").join(&name)));
    plot::register_font()?;
    plot::png(&dir.join(&name), (900, 600), |area| {
        let all: Vec<(f64, f64)> = series.iter().flat_map(|s| s.1.clone()).collect();
        if all.is_empty() {
            bail!("no finished run for the {side} × {side} sheet");
        }
        let (x0, x1) = all
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
        let (y0, y1) = all
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!(
                    "{side} × {side} sheet pinned at two corners, 2 s at Δt 10 ms (diverged runs not drawn)"
                ),
                ("sans-serif", 22),
            )
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(
                ((x0 * 0.7).min(1.5)..x1 * 1.4).log_scale(),
                (y0.min(0.01) * 0.7..y1 * 1.4).log_scale(),
            )?;
        chart
            .configure_mesh()
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&|v| format!("{v:.0}"))
            .x_desc("wall time per step, ms")
            .y_desc("largest edge stretch at 2 s")
            .y_label_formatter(&|v| format!("{:.2} %", 100.0 * v))
            .draw()?;
        // The goal: 1 % stretch (and, at 50 × 50, 2 ms per step).
        chart
            .draw_series(LineSeries::new(
                [((x0 * 0.7).min(1.5), 0.01), (x1 * 1.4, 0.01)],
                BLACK.mix(0.4).stroke_width(1),
            ))?
            .label("1 % stretch (the issue's goal)")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.mix(0.4)));
        // The time goal: 2 ms per step at 50 × 50, 10 ms at 100 × 100.
        let goal_ms = if side <= 50 { 2.0 } else { 10.0 };
        let (ylo, yhi) = (y0.min(0.01) * 0.7, y1 * 1.4);
        chart
            .draw_series(LineSeries::new(
                [(goal_ms, ylo), (goal_ms, yhi)],
                RED.mix(0.5).stroke_width(1),
            ))?
            .label(format!("{goal_ms} ms per step (the issue's goal)"))
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.mix(0.5)));
        for (k, (peer, points)) in series.iter().enumerate() {
            let colour = plot::PALETTE[k % plot::PALETTE.len()];
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 6, colour.filled())))?
                .label(peer.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), 6, colour.filled()));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerLeft)
            .draw()?;
        Ok(())
    })?;
    let _ = writeln!(
        t,
        "\n![time per step against stretch, {side} × {side}](img/peers/{name})"
    );
    Ok(t.trim_end().to_string())
}

/// Whether the goal is met by some PARTY setting.
pub(super) fn peers_goal(src: &Sources) -> Result<String> {
    let files = peer_files(src)?;
    let party = &files[0];
    let best = |side: usize, pred: &dyn Fn(&PeerRow) -> bool| {
        party
            .rows
            .iter()
            .filter(|r| r.scene == "sheet" && r.side == Some(side) && r.diverged_at_s.is_none())
            .filter(|r| pred(r))
            .filter_map(|r| Some((r.ms_per_step?, r.setting.clone(), r.stretch_end?)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    };
    let mut t = String::new();
    match best(50, &|r| r.stretch_end.is_some_and(|s| s <= 0.01)) {
        Some((ms, setting, s)) => {
            let verdict = if ms <= 2.0 { "met" } else { "not met" };
            let _ = writeln!(
                t,
                "- 50 × 50, ≤ 2 ms/step with ≤ 1 % stretch: **{verdict}** — the fastest PARTY setting within 1 % is `{setting}`: {ms:.2} ms/step, {:.2} %.",
                100.0 * s
            );
        }
        None => {
            let _ = writeln!(
                t,
                "- 50 × 50, ≤ 2 ms/step with ≤ 1 % stretch: **not met** — no PARTY setting run reaches 1 %."
            );
        }
    }
    match best(100, &|_| true) {
        Some((ms, setting, s)) => {
            let verdict = if ms <= 10.0 { "met" } else { "not met" };
            let _ = writeln!(
                t,
                "- 100 × 100, ≤ 10 ms/step, stable: **{verdict}** — the fastest stable PARTY setting is `{setting}`: {ms:.2} ms/step ({:.2} % stretch).",
                100.0 * s
            );
        }
        None => {
            let _ = writeln!(
                t,
                "- 100 × 100, stable: **not met** — every PARTY run diverged."
            );
        }
    }
    Ok(t.trim_end().to_string())
}
