//! The time-against-error study's table and figure.

use std::fmt::Write as _;
use std::time::Duration;

use anyhow::Result;
use atelier_solver::Cloth;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::figures::plot::PALETTE;

use super::{Family, GOAL_MS, MAX_REPEATS, REFERENCE_DT, Row, Run};

/// Δt in the table: plain above 1 ms, else in scientific notation.
fn seconds(dt: f64) -> String {
    if dt >= 1e-3 {
        format!("{dt}")
    } else {
        format!("{dt:.3e}")
    }
}

/// A finite number in the given format, "–" otherwise.
fn finite(x: f64, text: impl Fn(f64) -> String) -> String {
    if x.is_finite() {
        text(x)
    } else {
        "–".to_owned()
    }
}

fn mm(x: Option<f64>) -> String {
    x.map_or("–".to_owned(), |e| format!("{:.1}", e * 1e3))
}

pub(super) fn table(
    cloth: &Cloth,
    rows: &[Row],
    reference: &Run,
    check: &Run,
    uncertainty: f64,
    total: Duration,
) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# Time against error: Ø 63.5 cm drape, 60 × 5 annulus, cotton, 2 s (`cargo xtask figures solver`)\n"
    );
    let _ = writeln!(
        t,
        "Reference: PARTY, Gauss–Newton shape projection (20 per pass), ε^c 1e-9, Δt {REFERENCE_DT} s: \
         {:.1} s wall, max strain error {:.1e}, lowest node at z = {:.0} mm. The same at Δt {} s \
         lies {:.1} mm RMS from it \
         (the reference's uncertainty; smaller errors are not resolved). Error: RMS distance of \
         the free nodes to the reference at t = 2 s. Own ref.: the baseline against a tight run \
         of itself (mass-spring at 0.01 × its stability estimate, XPBD 200 substeps × 10 \
         sweeps). Wall: the stepping loop, fastest of up to {MAX_REPEATS} repeats, one thread. \
         Iterations per step: PARTY's shape iterations over both collision passes and internal \
         iterations over both phases. Max strain (error): PARTY's largest |ε − ε̄| of any step, \
         the baselines' largest |ε|. DC: the drape coefficient at 2 s (the reference's: {:.1} %). \
         The check run took {:.1} s, the whole study {:.0} s.\n",
        reference.wall.as_secs_f64(),
        reference.max_strain,
        reference.lowest() * 1e3,
        2.0 * REFERENCE_DT,
        uncertainty * 1e3,
        reference.drape_coefficient(cloth),
        check.wall.as_secs_f64(),
        total.as_secs_f64(),
    );
    let default_walls: Vec<f64> = rows
        .iter()
        .filter(|r| r.is_default)
        .map(Row::wall_ms)
        .collect();
    if default_walls.len() > 1 {
        let lo = default_walls.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = default_walls.iter().copied().fold(0.0, f64::max);
        let _ = writeln!(
            t,
            "The defaults appear in {} sweeps (same configuration, same answer): their wall times \
             {lo:.0}–{hi:.0} ms show this machine's noise.\n",
            default_walls.len()
        );
    }
    t.push_str(
        "| solver | sweep | setting | Δt s | steps | wall ms | error mm | own ref. mm | lowest z mm | DC % | iterations/step | max strain (error) | Pareto | status |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            t,
            "| {} | {} | {}{} | {} | {} | {:.1} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.family.name(),
            r.sweep,
            r.setting,
            if r.is_default { " (defaults)" } else { "" },
            seconds(r.dt),
            r.run.steps,
            r.wall_ms(),
            mm(r.error),
            if r.family == Family::Party {
                "=".to_owned()
            } else {
                mm(r.own_error)
            },
            finite(r.run.lowest() * 1e3, |z| format!("{z:.0}")),
            finite(r.run.drape_coefficient(cloth), |d| format!("{d:.1}")),
            r.run.iterations,
            if r.run.outcome.is_ok() {
                format!("{:.1e}", r.run.max_strain)
            } else {
                "–".to_owned()
            },
            if r.pareto { "★" } else { "" },
            r.status,
        );
    }
    t
}

/// A marker shape per sweep (`k`: the sweep's index within its family), in pixel offsets.
fn marker<DB: DrawingBackend>(k: usize, style: ShapeStyle) -> DynElement<'static, DB, (i32, i32)> {
    match k % 9 {
        0 => Circle::new((0, 0), 5, style).into_dyn(),
        7 => Rectangle::new([(-3, -3), (3, 3)], style.filled()).into_dyn(),
        8 => TriangleMarker::new((0, 0), 5, style.filled()).into_dyn(),
        1 => TriangleMarker::new((0, 0), 6, style).into_dyn(),
        2 => Rectangle::new([(-4, -4), (4, 4)], style).into_dyn(),
        3 => Cross::new((0, 0), 5, style).into_dyn(),
        4 => Polygon::new(vec![(0, -6), (6, 0), (0, 6), (-6, 0)], style).into_dyn(),
        5 => Circle::new((0, 0), 3, style.filled()).into_dyn(),
        _ => PathElement::new(vec![(-6, 4), (0, -6), (6, 4), (-6, 4)], style).into_dyn(),
    }
}

/// The sweeps of the rows, in order of first appearance.
fn sweeps(rows: &[Row]) -> Vec<(Family, &'static str)> {
    let mut s: Vec<(Family, &'static str)> = Vec::new();
    for r in rows {
        if !s.contains(&(r.family, r.sweep)) {
            s.push((r.family, r.sweep));
        }
    }
    s
}

pub(super) fn draw(
    root: &DrawingArea<BitMapBackend, Shift>,
    rows: &[Row],
    uncertainty: f64,
) -> Result<()> {
    let (title, body) = root.split_vertically(50);
    title.draw(&Text::new(
        "Time against error: Ø 63.5 cm drape (60 × 5 annulus, cotton), 2 s simulated, one thread",
        (20, 14),
        ("sans-serif", 24).into_font(),
    ))?;
    let panels = body.split_evenly((1, 2));
    panel(
        &panels[0],
        rows,
        |r| r.error,
        "(a) RMS distance to the PARTY reference at t = 2 s",
        Some(uncertainty),
        true,
    )?;
    panel(
        &panels[1],
        rows,
        |r| r.own_error,
        "(b) each solver against a tight run of itself (PARTY: as in (a))",
        None,
        false,
    )?;
    Ok(())
}

fn panel(
    area: &DrawingArea<BitMapBackend, Shift>,
    rows: &[Row],
    error: impl Fn(&Row) -> Option<f64>,
    caption: &str,
    uncertainty: Option<f64>,
    front: bool,
) -> Result<()> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| error(r).map(|e| (r.wall_ms(), e * 1e3)))
        .collect();
    let (x_min, x_max) = pts
        .iter()
        .fold((GOAL_MS, GOAL_MS), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y_min, y_max) = pts.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| {
        (a.min(p.1), b.max(p.1))
    });
    let y_min = uncertainty.map_or(y_min, |u| y_min.min(u * 1e3));
    let x_range = (x_min / 1.6)..(x_max * 1.6);
    let y_range = (y_min.max(1e-3) / 2.0)..(y_max * 2.0);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 19))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(x_range.clone().log_scale(), y_range.clone().log_scale())?;
    chart
        .configure_mesh()
        .x_desc("wall time for 2 s simulated (ms)")
        .y_desc("RMS node error (mm)")
        .light_line_style(TRANSPARENT)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| {
            if *v >= 1.0 {
                format!("{v:.0}")
            } else {
                format!("{v:.1}")
            }
        })
        .axis_desc_style(("sans-serif", 17))
        .label_style(("sans-serif", 14))
        .draw()?;
    let grey = RGBColor(120, 120, 120);
    // The goal: 2 s in 50 ms.
    chart
        .draw_series(DashedLineSeries::new(
            vec![(GOAL_MS, y_range.start), (GOAL_MS, y_range.end)],
            6,
            4,
            PALETTE[4].stroke_width(2),
        ))?
        .label("goal: 2 s at Δt 0.01 in 50 ms")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], PALETTE[4].stroke_width(2)));
    if let Some(u) = uncertainty {
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x_range.start, u * 1e3), (x_range.end, u * 1e3)],
                3,
                4,
                grey.stroke_width(2),
            ))?
            .label("reference uncertainty (ref. at 2Δt)")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(2))
            });
    }
    let mut k_in_family = [0usize; 3];
    for (family, sweep) in sweeps(rows) {
        let fi = family as usize;
        let k = k_in_family[fi];
        k_in_family[fi] += 1;
        // Joined in the order of the knob's values (not of wall time), so a line follows the knob.
        let line: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.family == family && r.sweep == sweep)
            .filter_map(|r| error(r).map(|e| (r.wall_ms(), e * 1e3)))
            .collect();
        if line.is_empty() {
            continue;
        }
        let colour = family.colour();
        let style = colour.stroke_width(2);
        let dashed = k % 2 == 1;
        if dashed {
            chart.draw_series(DashedLineSeries::new(line.clone(), 7, 4, style))?;
        } else {
            chart.draw_series(LineSeries::new(line.clone(), style))?;
        }
        chart
            .draw_series(
                line.iter()
                    .map(|&p| EmptyElement::at(p) + marker(k, colour.stroke_width(2))),
            )?
            .label(format!("{}: {sweep}", family.name()))
            .legend(move |(x, y)| {
                EmptyElement::at((x + 12, y))
                    + PathElement::new(vec![(-12, 0), (12, 0)], style)
                    + marker(k, style)
            });
    }
    // The defaults.
    // The defaults appear in several sweeps; mark their fastest run.
    if let Some(d) = rows
        .iter()
        .filter(|r| r.is_default)
        .min_by_key(|r| r.run.wall)
        && let Some(e) = error(d)
    {
        let p = (d.wall_ms(), e * 1e3);
        chart.draw_series(std::iter::once(
            EmptyElement::at(p)
                + Circle::new((0, 0), 11, BLACK.stroke_width(2))
                + Text::new("PARTY defaults", (12, -22), ("sans-serif", 15).into_font()),
        ))?;
    }
    if front {
        let mut f: Vec<&Row> = rows.iter().filter(|r| r.pareto).collect();
        f.sort_by_key(|r| r.run.wall);
        let mut stairs = Vec::new();
        for (i, r) in f.iter().enumerate() {
            let e = r.error.unwrap_or(f64::NAN) * 1e3;
            if i > 0 {
                stairs.push((r.wall_ms(), stairs.last().map_or(e, |p: &(f64, f64)| p.1)));
            }
            stairs.push((r.wall_ms(), e));
        }
        if let Some(&(_, y)) = stairs.last() {
            stairs.push((x_range.end, y));
        }
        chart
            .draw_series(LineSeries::new(stairs, BLACK.stroke_width(1)))?
            .label("Pareto front (filled: on it)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(1)));
        chart.draw_series(f.iter().map(|r| {
            let p = (r.wall_ms(), r.error.unwrap_or(f64::NAN) * 1e3);
            EmptyElement::at(p) + Circle::new((0, 0), 5, r.family.colour().filled())
        }))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .label_font(("sans-serif", 13))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}
