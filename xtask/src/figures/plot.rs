//! Plotting helpers shared by the figure sets: the bundled font, atomic PNG output, colours,
//! and polar axes on a square Cartesian chart (plotters has no polar coordinate type).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// Register DejaVu Sans (shipped in `assets/fonts`, see its licence there) as "sans-serif".
pub fn register_font() -> Result<()> {
    static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| anyhow!("the bundled font could not be loaded"))
}

/// Draw a rendered picture (`w` pixels a row, row 0 at the top; `None` pixels left as they are)
/// into `area` with its top left corner at `at`.
pub fn blit(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    pixels: &[Option<[f64; 3]>],
    w: usize,
    at: (usize, usize),
) -> Result<()> {
    for (k, p) in pixels.iter().enumerate() {
        if let Some(rgb) = p {
            let (x, y) = (at.0 + k % w, at.1 + k / w);
            area.draw_pixel((x as i32, y as i32), &to_rgb(*rgb))?;
        }
    }
    Ok(())
}

/// Draw into a PNG at `path`: the drawing goes to a temporary file beside it, renamed over
/// `path` only when complete, so a failure leaves an earlier figure intact.
pub fn png(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend, plotters::coord::Shift>) -> Result<()>,
) -> Result<PathBuf> {
    let tmp = atelier_files::files::temporary_sibling(path);
    let result = (|| {
        let root = BitMapBackend::new(&tmp, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
        Ok::<_, anyhow::Error>(())
    })();
    match result {
        Ok(()) => {
            std::fs::rename(&tmp, path).with_context(|| format!("renaming {}", tmp.display()))?;
            Ok(path.to_path_buf())
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e.context(format!("drawing {}", path.display())))
        }
    }
}

/// Which of the `(wall time, error)` points lie on the Pareto front: no other point has both a
/// smaller wall time and a smaller error (points without an error are never on it).
pub fn pareto_front(points: &[(f64, Option<f64>)]) -> Vec<bool> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].1.is_some())
        .collect();
    order.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0));
    let mut on = vec![false; points.len()];
    let mut best = f64::INFINITY;
    for i in order {
        let e = points[i].1.unwrap_or(f64::INFINITY);
        if e < best {
            best = e;
            on[i] = true;
        }
    }
    on
}

/// A qualitative palette (Okabe–Ito, colour-blind safe).
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(120, 120, 120),
];

/// A chart with square axes `[-r, r]²` for polar data.
pub type PolarChart<'a> =
    ChartContext<'a, BitMapBackend<'a>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draw polar axes of radius `r`: rings at `ticks` (labelled with `unit`) and spokes every
/// 45°, with the material directions named.
pub fn polar_axes(chart: &mut PolarChart, r: f64, ticks: &[f64], unit: &str) -> Result<()> {
    let grey = RGBColor(200, 200, 200);
    for &t in ticks {
        let ring: Vec<(f64, f64)> = (0..=180)
            .map(|i| {
                let a = i as f64 * std::f64::consts::PI / 90.0;
                (t * a.cos(), t * a.sin())
            })
            .collect();
        chart.draw_series(LineSeries::new(ring, grey.stroke_width(1)))?;
        let label = format!("{} {unit}", trim(t));
        let a = 100f64.to_radians();
        chart.draw_series(std::iter::once(Text::new(
            label,
            (t * a.cos(), t * a.sin()),
            ("sans-serif", 13)
                .into_font()
                .color(&RGBColor(110, 110, 110)),
        )))?;
    }
    for k in 0..8 {
        let a = k as f64 * std::f64::consts::FRAC_PI_4;
        chart.draw_series(LineSeries::new(
            vec![(0.0, 0.0), (r * a.cos(), r * a.sin())],
            grey.stroke_width(1),
        ))?;
    }
    let names = [
        (0.0, "0° warp"),
        (45.0, "45°"),
        (90.0, "90° weft"),
        (135.0, "135°"),
    ];
    for (deg, name) in names {
        let a = f64::to_radians(deg);
        let pos = (0.93 * r * a.cos(), 0.93 * r * a.sin());
        chart.draw_series(std::iter::once(Text::new(
            name.to_owned(),
            pos,
            ("sans-serif", 14).into_font(),
        )))?;
    }
    Ok(())
}

/// `(r cos θ, r sin θ)` for samples `(θ rad, r)`, closed.
pub fn polar_points(samples: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut pts: Vec<(f64, f64)> = samples
        .iter()
        .map(|&(t, r)| (r * t.cos(), r * t.sin()))
        .collect();
    if let Some(&first) = pts.first() {
        pts.push(first);
    }
    pts
}

/// Round ring limits to a "nice" value: 1, 2 or 5 × 10ⁿ at or above `x`.
pub fn nice_ceiling(x: f64) -> f64 {
    let p = 10f64.powf(x.log10().floor());
    for m in [1.0, 2.0, 5.0, 10.0] {
        if m * p >= x {
            return m * p;
        }
    }
    10.0 * p
}

fn trim(x: f64) -> String {
    let s = format!("{x:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// A plotters colour from components in [0, 1].
pub fn to_rgb(c: [f64; 3]) -> RGBColor {
    let [r, g, b] = atelier::picture::to_bytes(c);
    RGBColor(r, g, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pareto_front_keeps_the_points_nothing_beats() {
        let points = [
            (1.0, Some(10.0)),
            (2.0, Some(12.0)),
            (3.0, Some(5.0)),
            (4.0, None),
            (5.0, Some(1.0)),
            (0.5, None),
        ];
        assert_eq!(
            pareto_front(&points),
            vec![true, false, true, false, true, false]
        );
    }
}
