//! Line charts for the reports of virtual tests: a KES loop, simulated against the fabric's own,
//! drawn with plotters and the bundled DejaVu Sans (no system fonts needed), written
//! atomically. The data types are always here; drawing needs the `charts` feature (plotters),
//! which the command-line program and xtask turn on ([`DRAWN`]).

#[cfg(feature = "charts")]
use std::path::Path;
#[cfg(feature = "charts")]
use std::sync::OnceLock;

#[cfg(feature = "charts")]
use plotters::prelude::*;

/// Whether this build draws charts (the `charts` feature); without it a run leaves the chart
/// pictures out and says so in its warnings.
pub const DRAWN: bool = cfg!(feature = "charts");

/// One curve of a chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Its name in the legend.
    pub name: String,
    /// Its points (x, y), in order.
    pub points: Vec<(f64, f64)>,
}

/// A chart: title, axis labels and curves.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// Title.
    pub title: String,
    /// X axis label, with its unit.
    pub x_label: String,
    /// Y axis label, with its unit.
    pub y_label: String,
    /// The curves (the first drawn as a thick line, the others thin and on top).
    pub series: Vec<Series>,
    /// Points drawn as open black circles over the curves (observed markers), if any.
    pub markers: Option<Series>,
    /// One scale on both axes (shapes), instead of each axis fitted to the data.
    pub equal_aspect: bool,
}

#[cfg(feature = "charts")]
/// Register the bundled font once; false when it cannot be loaded.
fn font() -> bool {
    static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()
    })
}

#[cfg(feature = "charts")]
const COLOURS: [RGBColor; 3] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
];

#[cfg(feature = "charts")]
/// Draw `chart` into a PNG of `size` pixels at `path` (a temporary file beside it, renamed when
/// complete).
pub fn write_chart(path: &Path, chart: &Chart, size: (u32, u32)) -> std::io::Result<()> {
    write_png(path, |tmp| draw(tmp, chart, size))
}

#[cfg(feature = "charts")]
/// Draw with `draw` into a temporary file beside `path` (the bundled font registered first),
/// renamed to `path` when complete and removed when drawing fails.
fn write_png(
    path: &Path,
    draw: impl FnOnce(&Path) -> Result<(), Box<dyn std::error::Error + Send + Sync>>,
) -> std::io::Result<()> {
    if !font() {
        return Err(std::io::Error::other(
            "the bundled font could not be loaded",
        ));
    }
    let tmp = atelier_files::files::temporary_sibling(path);
    match draw(&tmp) {
        Ok(()) => std::fs::rename(&tmp, path),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(std::io::Error::other(e))
        }
    }
}

#[cfg(feature = "charts")]
fn draw(
    file: &Path,
    chart: &Chart,
    size: (u32, u32),
) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let root = BitMapBackend::new(file, size).into_drawing_area();
    root.fill(&WHITE)?;
    let all = chart
        .series
        .iter()
        .chain(&chart.markers)
        .flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in all {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if !(x1 > x0 && y1 > y0) {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let (mut px, mut py) = (0.05 * (x1 - x0), 0.05 * (y1 - y0));
    if chart.equal_aspect {
        // Widen the narrower range so that a unit spans as many pixels on both axes (the plot
        // area is about the picture less its label areas).
        let (w, h) = (f64::from(size.0) - 96.0, f64::from(size.1) - 92.0);
        let scale = ((x1 - x0 + 2.0 * px) / w).max((y1 - y0 + 2.0 * py) / h);
        px = 0.5 * (scale * w - (x1 - x0));
        py = 0.5 * (scale * h - (y1 - y0));
    }
    let mut c = ChartBuilder::on(&root)
        .caption(&chart.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0 - px)..(x1 + px), (y0 - py)..(y1 + py))?;
    c.configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .label_style(("sans-serif", 14))
        .draw()?;
    for (k, s) in chart.series.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let width = if k == 0 { 5 } else { 2 };
        c.draw_series(LineSeries::new(
            s.points.iter().copied(),
            colour.stroke_width(width),
        ))?
        .label(s.name.as_str())
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(3)));
    }
    if let Some(m) = &chart.markers {
        c.draw_series(
            m.points
                .iter()
                .map(|&p| Circle::new(p, 4, BLACK.stroke_width(1))),
        )?
        .label(m.name.as_str())
        .legend(|(x, y)| Circle::new((x + 10, y), 4, BLACK.stroke_width(1)));
    }
    c.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    root.present()?;
    Ok(())
}

/// One pattern piece on a sheet ([`write_pieces`]), cm in the piece's own frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PieceDrawing {
    /// Name, written under the piece.
    pub name: String,
    /// The closed outline (the seam line).
    pub outline: Vec<(f64, f64)>,
    /// The grid's edges (thin grey).
    pub grid: Vec<[(f64, f64); 2]>,
    /// The grain line, drawn as an arrow.
    pub grain: Option<[(f64, f64); 2]>,
    /// Notches (red ticks into the piece are drawn as dots).
    pub notches: Vec<(f64, f64)>,
    /// The grid's four corners.
    pub corners: Vec<(f64, f64)>,
    /// Darts: first end, apex, second end.
    pub darts: Vec<[(f64, f64); 3]>,
    /// Internal lines drawn only.
    pub lines: Vec<Vec<(f64, f64)>>,
    /// The team ends in order, numbered from 0 (team `k-(k+1)` runs from `k` to `k + 1`; the
    /// names a garment's seams use).
    pub breakpoints: Vec<(f64, f64)>,
}

#[cfg(feature = "charts")]
/// Draw pattern pieces side by side on one sheet, at one scale (cm on both axes): outline
/// black, grid grey, grain line a green arrow, notches red dots, the grid's corners blue
/// squares, darts purple, internal lines dashed grey, the team ends numbered in blue; each
/// piece's name under it. Written
/// atomically.
pub fn write_pieces(path: &Path, title: &str, pieces: &[PieceDrawing]) -> std::io::Result<()> {
    write_png(path, |tmp| draw_pieces(tmp, title, pieces))
}

#[cfg(feature = "charts")]
fn draw_pieces(
    file: &Path,
    title: &str,
    pieces: &[PieceDrawing],
) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    // Lay the pieces out in a row, 8 cm apart, bottoms aligned.
    const GAP: f64 = 8.0;
    let bounds = |p: &PieceDrawing| {
        p.outline.iter().fold(
            (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ),
            |(a, b, c, d), &(x, y)| (a.min(x), b.max(x), c.min(y), d.max(y)),
        )
    };
    let mut shifts = Vec::with_capacity(pieces.len());
    let (mut x, mut top) = (0.0, 1.0_f64);
    for p in pieces {
        let (x0, x1, y0, y1) = bounds(p);
        shifts.push((x - x0, -y0));
        x += x1 - x0 + GAP;
        top = top.max(y1 - y0);
    }
    let width = (x - GAP).max(1.0);
    let (w_px, margin) = (1600_u32, 60.0);
    let scale = (f64::from(w_px) - 2.0 * margin) / width;
    let h_px = (top * scale + 2.0 * margin + 40.0).clamp(300.0, 1600.0) as u32;
    let root = BitMapBackend::new(file, (w_px, h_px)).into_drawing_area();
    root.fill(&WHITE)?;
    let (x_lo, y_lo) = (-margin / scale, -(margin + 30.0) / scale);
    let (x_hi, y_hi) = (
        x_lo + f64::from(w_px) / scale,
        y_lo + f64::from(h_px - 30) / scale,
    );
    let mut c = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)?;
    let grey = RGBColor(190, 190, 190);
    let purple = RGBColor(150, 60, 170);
    let green = RGBColor(0, 140, 60);
    for (p, &(dx, dy)) in pieces.iter().zip(&shifts) {
        let at = |q: (f64, f64)| (q.0 + dx, q.1 + dy);
        for e in &p.grid {
            c.draw_series(std::iter::once(PathElement::new(
                vec![at(e[0]), at(e[1])],
                grey.stroke_width(1),
            )))?;
        }
        for l in &p.lines {
            c.draw_series(DashedLineSeries::new(
                l.iter().map(|&q| at(q)),
                6,
                4,
                grey.stroke_width(2),
            ))?;
        }
        for d in &p.darts {
            c.draw_series(std::iter::once(PathElement::new(
                d.iter().map(|&q| at(q)).collect::<Vec<_>>(),
                purple.stroke_width(2),
            )))?;
        }
        let mut ring: Vec<(f64, f64)> = p.outline.iter().map(|&q| at(q)).collect();
        ring.extend(ring.first().copied());
        c.draw_series(std::iter::once(PathElement::new(
            ring,
            BLACK.stroke_width(2),
        )))?;
        if let Some([a, b]) = p.grain {
            let (a, b) = (at(a), at(b));
            let (ux, uy) = (b.0 - a.0, b.1 - a.1);
            let len = ux.hypot(uy).max(1e-9);
            let (ux, uy) = (ux / len, uy / len);
            let head = 1.5;
            let wing = |s: f64| {
                (
                    b.0 - head * ux - s * head * 0.5 * uy,
                    b.1 - head * uy + s * head * 0.5 * ux,
                )
            };
            c.draw_series(std::iter::once(PathElement::new(
                vec![a, b],
                green.stroke_width(3),
            )))?;
            c.draw_series(std::iter::once(PathElement::new(
                vec![wing(1.0), b, wing(-1.0)],
                green.stroke_width(3),
            )))?;
        }
        c.draw_series(
            p.notches
                .iter()
                .map(|&q| Circle::new(at(q), 4, RED.filled())),
        )?;
        c.draw_series(p.corners.iter().map(|&q| {
            let (x, y) = at(q);
            let h = 5.0 / scale;
            Rectangle::new([(x - h, y - h), (x + h, y + h)], BLUE.stroke_width(2))
        }))?;
        // Breakpoint numbers, set in from the outline towards the piece's centre.
        let n = p.outline.len().max(1) as f64;
        let centre = p
            .outline
            .iter()
            .fold((0.0, 0.0), |(sx, sy), &(x, y)| (sx + x / n, sy + y / n));
        c.draw_series(p.breakpoints.iter().enumerate().map(|(k, &q)| {
            let (vx, vy) = (centre.0 - q.0, centre.1 - q.1);
            let inset = 16.0 / scale / vx.hypot(vy).max(1e-9);
            let (x, y) = at((q.0 + inset * vx, q.1 + inset * vy));
            Text::new(
                k.to_string(),
                (x - 4.0 / scale, y + 6.0 / scale),
                ("sans-serif", 13).into_font().color(&BLUE),
            )
        }))?;
        let (x0, x1, _, _) = bounds(p);
        c.draw_series(std::iter::once(Text::new(
            p.name.clone(),
            (
                0.5 * (x0 + x1) + dx - 0.25 * p.name.len() as f64 * 14.0 / scale,
                -20.0 / scale,
            ),
            ("sans-serif", 16),
        )))?;
    }
    root.present()?;
    Ok(())
}
