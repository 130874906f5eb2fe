//! Figures of the gridding (issue 4): the front bodice before and after improvement (thesis
//! Figs. 30 and 33), the energy against iteration (Fig. 31), the quality histograms (Fig. 32),
//! the eight dress panels with their seams, a depth-controlled grid (Fig. 25), and the body from
//! range images coloured by part with its error image (Figs. 35–37).

use std::path::{Path, PathBuf};

use anyhow::Result;
use atelier_grid::pattern::{Garment, Panel, grid_pattern, load_garment, load_pattern};
use atelier_grid::{ImproveParams, Patch};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::figures::plot::{PALETTE, png};

/// Draw every grid figure into `out`; returns the files written.
pub fn draw_all(root: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let patterns = root.join("fixtures/patterns");
    let bodice = grid_pattern(
        &load_pattern(&patterns.join("dress/front_bodice.ron"))?,
        ImproveParams::default(),
    )?;
    let dress = load_garment(&patterns.join("dress/dress.ron"), ImproveParams::default())?;
    let hill = grid_pattern(
        &load_pattern(&patterns.join("depth_square.ron"))?,
        ImproveParams::default(),
    )?;
    let mut written = vec![
        before_after(&bodice, &out.join("grid_front_bodice.png"))?,
        energy(&bodice, &out.join("grid_energy.png"))?,
        histograms(&bodice, &out.join("grid_histograms.png"))?,
        dress_panels(&dress, &out.join("grid_dress_panels.png"))?,
        before_after(&hill, &out.join("grid_depth.png"))?,
    ];
    written.extend(crate::figures::grid_body::draw_all(out)?);
    Ok(written)
}

/// Bounding box of a patch's nodes (m).
fn bounds(p: &Patch) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for s in 0..p.node_of.len() {
        if let Some(n) = p.node((s % p.nu) as isize, (s / p.nu) as isize) {
            let q = p.positions[n as usize];
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
    }
    (lo, hi)
}

/// A chart in cm with equal scales on both axes over the box `lo..hi` (m) plus a margin.
fn equal_chart<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    caption: &str,
    lo: [f64; 2],
    hi: [f64; 2],
) -> Result<Chart<'a, 'b>> {
    let (w, h) = area.dim_in_pixel();
    let (pw, ph) = (f64::from(w) - 80.0, f64::from(h) - 90.0);
    let (mut x0, mut x1) = (lo[0] * 100.0 - 2.0, hi[0] * 100.0 + 2.0);
    let (mut y0, mut y1) = (lo[1] * 100.0 - 2.0, hi[1] * 100.0 + 2.0);
    // Equal scales: widen the shorter extent.
    let scale = ((x1 - x0) / pw).max((y1 - y0) / ph);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    (x0, x1) = (cx - 0.5 * scale * pw, cx + 0.5 * scale * pw);
    (y0, y1) = (cy - 0.5 * scale * ph, cy + 0.5 * scale * ph);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x (cm)")
        .y_desc("y (cm)")
        .label_style(("sans-serif", 13))
        .draw()?;
    Ok(chart)
}

type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Draw a patch's grid lines (offset by `shift`, cm); fixed interior nodes as dots.
fn draw_patch(
    chart: &mut Chart<'_, '_>,
    p: &Patch,
    shift: [f64; 2],
    colour: RGBColor,
) -> Result<()> {
    let at = |n: u32| {
        let q = p.positions[n as usize];
        (q[0] * 100.0 + shift[0], q[1] * 100.0 + shift[1])
    };
    for (_, line) in p.lines() {
        let pts: Vec<(f64, f64)> = line.iter().map(|&n| at(n)).collect();
        chart.draw_series(LineSeries::new(pts, colour.stroke_width(1)))?;
    }
    Ok(())
}

fn draw_darts(chart: &mut Chart<'_, '_>, panel: &Panel, shift: [f64; 2]) -> Result<()> {
    let rest = panel.topology.rest_positions();
    let red = RGBColor(213, 94, 0);
    for d in &panel.darts {
        for &(a, b) in &d.pairs {
            for n in [a, b] {
                let q = rest[n as usize];
                chart.draw_series(std::iter::once(Circle::new(
                    (q[0] * 100.0 + shift[0], q[1] * 100.0 + shift[1]),
                    3,
                    red.filled(),
                )))?;
            }
        }
    }
    Ok(())
}

fn before_after(panel: &Panel, path: &Path) -> Result<PathBuf> {
    let (lo, hi) = bounds(&panel.initial);
    png(path, (1500, 760), |root| {
        let halves = root.split_evenly((1, 2));
        let (b, a) = (&panel.quality_before, &panel.quality_after);
        let captions = [
            format!(
                "{} (a) initial grid: shear {:.2} ± {:.2}°",
                panel.name, b.shear_deg.mean, b.shear_deg.sd
            ),
            format!(
                "(b) improved ({} steps): shear {:.2} ± {:.2}°",
                panel.improvement.energy.len() - 1,
                a.shear_deg.mean,
                a.shear_deg.sd
            ),
        ];
        for ((area, patch), caption) in halves
            .iter()
            .zip([&panel.initial, &panel.grid])
            .zip(captions)
        {
            let mut chart = equal_chart(area, &caption, lo, hi)?;
            draw_patch(&mut chart, patch, [0.0, 0.0], RGBColor(0, 80, 160))?;
            draw_darts(&mut chart, panel, [0.0, 0.0])?;
            for (c, h, r) in &panel.depth {
                let ring: Vec<(f64, f64)> = (0..=72)
                    .map(|k| {
                        let t = k as f64 * std::f64::consts::TAU / 72.0;
                        (100.0 * (c[0] + r * t.cos()), 100.0 * (c[1] + r * t.sin()))
                    })
                    .collect();
                chart
                    .draw_series(LineSeries::new(ring, PALETTE[1].stroke_width(2)))?
                    .label(format!(
                        "hill: height {:.0} cm, radius {:.0} cm",
                        h * 100.0,
                        r * 100.0
                    ))
                    .legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], PALETTE[1].stroke_width(2))
                    });
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .background_style(WHITE.mix(0.9))
                    .label_font(("sans-serif", 13))
                    .draw()?;
            }
        }
        Ok(())
    })
}

fn energy(panel: &Panel, path: &Path) -> Result<PathBuf> {
    let e = &panel.improvement.energy;
    let (lo, hi) = (
        e.iter().copied().fold(f64::INFINITY, f64::min),
        e.iter().copied().fold(0.0, f64::max),
    );
    png(path, (1000, 650), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!(
                    "Improvement energy E = c₁E₁ + c₂E₂ + c₃E₃ + E_fold, {} (monotone)",
                    panel.name
                ),
                ("sans-serif", 20),
            )
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..(e.len() - 1).max(1) as f64, (0.9 * lo)..(1.05 * hi))?;
        chart
            .configure_mesh()
            .x_desc("accepted gradient step")
            .y_desc("E (dimensionless)")
            .axis_desc_style(("sans-serif", 16))
            .label_style(("sans-serif", 14))
            .draw()?;
        chart.draw_series(LineSeries::new(
            e.iter().enumerate().map(|(k, &v)| (k as f64, v)),
            PALETTE[0].stroke_width(3),
        ))?;
        Ok(())
    })
}

fn histograms(panel: &Panel, path: &Path) -> Result<PathBuf> {
    let (b, a) = (&panel.quality_before, &panel.quality_after);
    let names = [
        ("u edge length (cm)", 100.0),
        ("v edge length (cm)", 100.0),
        ("shear angle (°)", 1.0),
        ("cell area (cm²)", 1e4),
    ];
    png(path, (1400, 900), |root| {
        let areas = root.split_evenly((2, 2));
        for (k, (area, (name, scale))) in areas.iter().zip(names).enumerate() {
            let before: Vec<f64> = b.samples[k].iter().map(|v| v * scale).collect();
            let after: Vec<f64> = a.samples[k].iter().map(|v| v * scale).collect();
            let all: Vec<f64> = before.iter().chain(&after).copied().collect();
            let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let bins = 30;
            let width = (hi - lo) / bins as f64;
            let hist = |v: &[f64]| -> Vec<(f64, f64)> {
                let mut counts = vec![0usize; bins];
                for x in v {
                    counts[(((x - lo) / width) as usize).min(bins - 1)] += 1;
                }
                counts
                    .iter()
                    .enumerate()
                    .map(|(i, &c)| (lo + (i as f64 + 0.5) * width, c as f64 / v.len() as f64))
                    .collect()
            };
            let (hb, ha) = (hist(&before), hist(&after));
            let ymax = hb.iter().chain(&ha).map(|p| p.1).fold(0.0, f64::max) * 1.1;
            let (sb, sa) = (stats(&before), stats(&after));
            let mut chart = ChartBuilder::on(area)
                .caption(name, ("sans-serif", 18))
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(50)
                .build_cartesian_2d(lo..hi, 0.0..ymax)?;
            chart
                .configure_mesh()
                .y_desc("fraction")
                .label_style(("sans-serif", 13))
                .draw()?;
            for (h, colour, label) in [
                (
                    &hb,
                    PALETTE[6],
                    format!("initial {:.2} ± {:.2}", sb.0, sb.1),
                ),
                (
                    &ha,
                    PALETTE[0],
                    format!("improved {:.2} ± {:.2}", sa.0, sa.1),
                ),
            ] {
                chart
                    .draw_series(h.iter().map(|&(x, y)| {
                        Rectangle::new(
                            [(x - 0.45 * width, 0.0), (x + 0.45 * width, y)],
                            colour.mix(0.45).filled(),
                        )
                    }))?
                    .label(label)
                    .legend(move |(x, y)| {
                        Rectangle::new([(x, y - 5), (x + 14, y + 5)], colour.mix(0.45).filled())
                    });
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.9))
                .border_style(BLACK)
                .label_font(("sans-serif", 13))
                .draw()?;
        }
        Ok(())
    })
}

fn stats(v: &[f64]) -> (f64, f64) {
    let s = atelier_grid::Stats::of(v);
    (s.mean, s.sd)
}

fn dress_panels(g: &Garment, path: &Path) -> Result<PathBuf> {
    // Lay the panels out in two rows: bodice and sleeves on top, skirts below.
    let mut shifts = Vec::with_capacity(g.panels.len());
    let (mut x, mut lo, mut hi) = ([0.0; 2], [f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &g.panels {
        let (a, b) = bounds(&p.grid);
        let row = usize::from(p.name.contains("skirt"));
        let shift = [x[row] - a[0] * 100.0, -(row as f64) * 28.0];
        x[row] += (b[0] - a[0]) * 100.0 + 6.0;
        for k in 0..2 {
            lo[k] = lo[k].min(a[k] * 100.0 + shift[k]);
            hi[k] = hi[k].max(b[k] * 100.0 + shift[k]);
        }
        shifts.push(shift);
    }
    png(path, (1700, 1150), |root| {
        let mut chart = equal_chart(
            root,
            &format!(
                "{}: {} panels, {} seams (matching colours are sewn together), darts in red",
                g.name,
                g.panels.len(),
                g.seams.len()
            ),
            [lo[0] / 100.0, lo[1] / 100.0],
            [hi[0] / 100.0, hi[1] / 100.0],
        )?;
        for (p, shift) in g.panels.iter().zip(&shifts) {
            draw_patch(&mut chart, &p.grid, *shift, RGBColor(150, 150, 150))?;
            draw_darts(&mut chart, p, *shift)?;
            let (a, b) = bounds(&p.grid);
            chart.draw_series(std::iter::once(Text::new(
                p.name.clone(),
                (
                    50.0 * (a[0] + b[0]) + shift[0] - 8.0,
                    b[1] * 100.0 + shift[1] + 2.5,
                ),
                ("sans-serif", 15).into_font(),
            )))?;
        }
        for (k, seam) in g.seams.iter().enumerate() {
            let colour = PALETTE[k % 6];
            for (panel, side) in [(seam.panel_a, 0), (seam.panel_b, 1)] {
                let rest = g.panels[panel].topology.rest_positions();
                let s = shifts[panel];
                let pts: Vec<(f64, f64)> = seam
                    .pairs
                    .iter()
                    .map(|p| {
                        let n = if side == 0 { p.0 } else { p.1 };
                        let q = rest[n as usize];
                        (q[0] * 100.0 + s[0], q[1] * 100.0 + s[1])
                    })
                    .collect();
                chart.draw_series(LineSeries::new(pts.clone(), colour.stroke_width(4)))?;
                let mid = pts[pts.len() / 2];
                chart.draw_series(std::iter::once(Text::new(
                    format!("{}", k + 1),
                    (mid.0 + 0.8, mid.1),
                    ("sans-serif", 14).into_font().color(&BLACK),
                )))?;
            }
        }
        Ok(())
    })
}
