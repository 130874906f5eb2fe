//! The string-identification experiments of Sudoh et al. (issue 9; `docs/fit.md`) on the four
//! synthetic objects (`atelier_fit::synthetic`: fine elastic rods, 20 manipulated-end
//! positions, 9 markers, σ = 0.5 px, 1 px = 2 mm):
//!
//! 1. Table 1: J = 4 observed shapes fitted, each reproduced; error per shape and object.
//! 2. Fig. 11: the first J = 1…10 of shapes 0–9 fitted; the mean error of the 10 unobserved
//!    shapes 10–19 reproduced with the parameters found.
//! 3. Table 3: the same error with the initial values (Table 2's s and b, l and φ from shape 0).
//!
//! Output: `fit.md` (the tables, also on stderr), `fit_unobserved.png` (Fig. 11),
//! `fit_shapes.png` (observed markers and reproduced shapes, J = 4, as Figs. 5–8).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use atelier_fit::experiment::{
    Reproduced, fit, mean_error, mean_error_from_truth, paper_initial, reproduce,
};
use atelier_fit::synthetic::{Object, SyntheticOptions, observe};
use atelier_fit::{FitOptions, StringModel};
use plotters::prelude::*;

use crate::figures::plot::{PALETTE, png};

/// Observed markers and a reproduced shape, image pixels.
type ShapePair = (Vec<[f64; 2]>, Vec<[f64; 2]>);

/// What one object's experiments give.
struct Results {
    object: Object,
    /// J = 4: per observed shape, its error, px; the fit's iterations, cost and termination.
    table1: Vec<Option<f64>>,
    fit4: (usize, f64, String),
    /// J = 1…10: the unobserved shapes' mean error, px (None: a shape without equilibrium),
    /// from the markers and from the noise-free markers.
    fig11: Vec<Option<f64>>,
    fig11_truth: Vec<Option<f64>>,
    /// The initial values' error on the unobserved shapes, px.
    table3: Option<f64>,
    /// J = 4: observed markers (px) and reproduced shapes (px), for the picture.
    shapes: Vec<ShapePair>,
    /// Wall time of the J = 10 fit, s.
    wall10: f64,
}

fn run_object(object: Object) -> Result<Results> {
    let (obs, truth) = observe(object, &SyntheticOptions::default()).context("observe")?;
    let (s, b) = object.table2();
    let initial = paper_initial(&obs, 0, s, b).context("initial values")?;
    let options = FitOptions::default();
    let unobserved: Vec<usize> = (10..20).collect();
    let four = [0, 1, 2, 3];
    let f4 = fit(&obs, &four, &initial, &options).context("fit J = 4")?;
    let r4 = reproduce(&f4.model, &obs, &f4.positions, &four);
    let shapes = r4
        .iter()
        .map(|r: &Reproduced| {
            let markers = obs.shapes[r.shape].markers.clone();
            let model = r.positions.iter().map(|x| obs.to_pixels(x)).collect();
            (markers, model)
        })
        .collect();
    let mut fig11 = Vec::new();
    let mut fig11_truth = Vec::new();
    let mut wall10 = 0.0;
    for j in 1..=10 {
        let which: Vec<usize> = (0..j).collect();
        let t0 = std::time::Instant::now();
        let f = fit(&obs, &which, &initial, &options).context("fit")?;
        if j == 10 {
            wall10 = t0.elapsed().as_secs_f64();
        }
        let r = reproduce(&f.model, &obs, &f.positions, &unobserved);
        fig11.push(mean_error(&r));
        fig11_truth.push(mean_error_from_truth(&r, &truth, obs.pixel_size));
    }
    let table3 = mean_error(&reproduce(
        &StringModel::new(initial),
        &obs,
        &[obs.shape(0)],
        &unobserved,
    ));
    Ok(Results {
        object,
        table1: r4.iter().map(|r| r.error_px).collect(),
        fit4: (f4.iterations, f4.cost, f4.termination),
        fig11,
        fig11_truth,
        table3,
        shapes,
        wall10,
    })
}

fn px(v: Option<f64>) -> String {
    v.map_or("no equilibrium".into(), |e| format!("{e:.2}"))
}

/// Draw everything into `out`.
pub fn draw_all(_root: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let results: Vec<Results> = Object::ALL
        .iter()
        .map(|&o| run_object(o))
        .collect::<Result<_>>()?;
    let mut md = String::new();
    writeln!(
        md,
        "# String identification: the paper's experiments on synthetic objects\n"
    )?;
    writeln!(
        md,
        "Objects: `atelier_fit::synthetic` (fine elastic rods, 120 segments), 20 manipulated-end positions, 9 markers, σ = 0.5 px, 1 px = 2 mm, seed 1. Fit: `FitOptions::default()` (c_s = 100 m⁻², c_f = 10 gf⁻², at most 200 iterations). Errors: mean distance of the 7 inner particles from their markers, px.\n"
    )?;
    writeln!(
        md,
        "## Table 1: J = 4 observed shapes, each reproduced (the paper: 0.20–1.68 px)\n"
    )?;
    writeln!(
        md,
        "| shape | rubber string | chain | UTP cable | grass leaf |"
    )?;
    writeln!(md, "|---|---|---|---|---|")?;
    for k in 0..4 {
        let cells: Vec<String> = results.iter().map(|r| px(r.table1[k])).collect();
        writeln!(md, "| C{} | {} |", k + 1, cells.join(" | "))?;
    }
    let cells: Vec<String> = results
        .iter()
        .map(|r| format!("{} it, E {:.2e}, {}", r.fit4.0, r.fit4.1, r.fit4.2))
        .collect();
    writeln!(md, "| fit | {} |", cells.join(" | "))?;
    writeln!(
        md,
        "\n## Fig. 11: mean error on the 10 unobserved shapes against J (the paper: ~1 px from J = 3–4 for uniform objects, ~10 for the others)\n"
    )?;
    writeln!(
        md,
        "Each cell: from the markers / from the noise-free markers (the noise alone puts a marker 0.63 px from the truth on average).\n"
    )?;
    writeln!(md, "| J | rubber string | chain | UTP cable | grass leaf |")?;
    writeln!(md, "|---|---|---|---|---|")?;
    for j in 0..10 {
        let cells: Vec<String> = results
            .iter()
            .map(|r| format!("{} / {}", px(r.fig11[j]), px(r.fig11_truth[j])))
            .collect();
        writeln!(md, "| {} | {} |", j + 1, cells.join(" | "))?;
    }
    writeln!(
        md,
        "\n## Table 3: error on the unobserved shapes with the initial values (the paper: 6.34, 34.54, 25.46, 115.34 px)\n"
    )?;
    writeln!(md, "| rubber string | chain | UTP cable | grass leaf |")?;
    writeln!(md, "|---|---|---|---|")?;
    let cells: Vec<String> = results.iter().map(|r| px(r.table3)).collect();
    writeln!(md, "| {} |", cells.join(" | "))?;
    let walls: Vec<String> = results
        .iter()
        .map(|r| format!("{} {:.2} s", r.object.name(), r.wall10))
        .collect();
    writeln!(
        md,
        "\nWall time of the J = 10 fit (one thread): {}.",
        walls.join(", ")
    )?;
    eprint!("{md}");
    let md_path = out.join("fit.md");
    atelier_files::files::write_atomic(&md_path, md.as_bytes())
        .with_context(|| format!("writing {}", md_path.display()))?;
    let a = unobserved_chart(&out.join("fit_unobserved.png"), &results)?;
    let b = shapes_chart(&out.join("fit_shapes.png"), &results)?;
    Ok(vec![md_path, a, b])
}

/// Fig. 11: unobserved error against J, one line per object (log scale).
fn unobserved_chart(path: &Path, results: &[Results]) -> Result<PathBuf> {
    png(path, (900, 600), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                "error on 10 unobserved shapes against observed shapes J",
                ("sans-serif", 22),
            )
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(0.5f64..10.5f64, (0.05f64..200f64).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("observed shapes J")
            .y_desc("mean error, px")
            .x_labels(10)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y}"))
            .label_style(("sans-serif", 15))
            .draw()?;
        for (k, r) in results.iter().enumerate() {
            let c = PALETTE[k];
            let pts: Vec<(f64, f64)> = r
                .fig11
                .iter()
                .enumerate()
                .filter_map(|(j, e)| e.map(|e| ((j + 1) as f64, e.max(0.05))))
                .collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?
                .label(r.object.name())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
            chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 4, c.filled())))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        Ok(())
    })
}

/// Figs. 5–8: for each object the four observed shapes (markers, dots) and their reproduction
/// (lines), in image pixels (v down).
fn shapes_chart(path: &Path, results: &[Results]) -> Result<PathBuf> {
    png(path, (1200, 900), |root| {
        let panels = root.split_evenly((2, 2));
        for (panel, r) in panels.iter().zip(results) {
            let mut chart = ChartBuilder::on(panel)
                .caption(
                    format!("{}: J = 4, markers and model", r.object.name()),
                    ("sans-serif", 18),
                )
                .margin(10)
                .x_label_area_size(30)
                .y_label_area_size(45)
                .build_cartesian_2d(100f64..500f64, 400f64..60f64)?;
            chart
                .configure_mesh()
                .label_style(("sans-serif", 12))
                .draw()?;
            for (k, (markers, model)) in r.shapes.iter().enumerate() {
                let c = PALETTE[k];
                chart.draw_series(LineSeries::new(
                    model.iter().map(|p| (p[0], p[1])),
                    c.stroke_width(2),
                ))?;
                chart.draw_series(
                    markers
                        .iter()
                        .map(|p| Circle::new((p[0], p[1]), 4, BLACK.stroke_width(1))),
                )?;
            }
        }
        Ok(())
    })
}
