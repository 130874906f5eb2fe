//! Figures of the fabric model (issue 2): the tensile major loop with minor loops (thesis
//! Fig. 11), the bending loop with initial and reversal curves (Fig. 13), and polar plots of the
//! interpolated tensile and bending characteristics at 11.25° steps in both forms (Figs. 16–18),
//! and the KES-FB1 shear loop with its initial, reversal and minor-loop curves (issue 21).

use std::path::{Path, PathBuf};

use anyhow::Result;
use atelier_fabric::{
    AnisotropyForm, BendingState, Branch, Fabric, ShearLoop, ShearState, Spindle, TensileLoop,
    TensileState, units,
};
use plotters::prelude::*;

use crate::figures::plot::{PALETTE, nice_ceiling, png, polar_axes, polar_points};

const FIXTURES: [&str; 6] = [
    "cotton_broad",
    "wool_tropical",
    "polyester_tropical",
    "polyester_faille",
    "denim",
    "silk",
];

/// Draw every fabric figure into `out`; returns the files written.
pub fn draw_all(root: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let load =
        |name: &str| Fabric::load(&root.join("fixtures/fabrics").join(format!("{name}.ron")));
    let cotton = load("cotton_broad")?;
    let mut written = vec![
        tensile_minor_loops(
            &cotton.tensile.warp,
            &cotton.name,
            &out.join("tensile_minor_loops.png"),
        )?,
        bending_loop(
            &cotton.bending.warp,
            &cotton.name,
            &out.join("bending_loop.png"),
        )?,
        shear_loop(
            &cotton.shear_loop()?,
            &cotton.name,
            &out.join("shear_loop.png"),
        )?,
    ];
    for name in FIXTURES {
        let fabric = load(name)?;
        written.push(polar(&fabric, &out.join(format!("polar_{name}.png")))?);
    }
    Ok(written)
}

/// Follow a force path through the hysteresis model, sampling each leg finely: (strain %, gf/cm).
fn tensile_path(l: &TensileLoop, turning_forces_gf: &[f64]) -> Vec<(f64, f64)> {
    let mut st = TensileState::VIRGIN;
    let mut pts = vec![(0.0, 0.0)];
    let mut from = 0.0;
    for &to in turning_forces_gf {
        for i in 1..=200 {
            let f = from + (to - from) * i as f64 / 200.0;
            let e = st.update(l, units::force_from_kes(f));
            pts.push((units::strain_to_percent(e), f));
        }
        from = to;
    }
    pts
}

fn tensile_minor_loops(l: &TensileLoop, name: &str, path: &Path) -> Result<PathBuf> {
    let fm = units::force_to_kes(l.max_force());
    let major: Vec<(f64, f64)> = tensile_path(l, &[fm, 0.0]);
    let x_max = units::strain_to_percent(l.apex_strain()) * 1.05;
    png(path, (1100, 800), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("Tensile hysteresis, {name}, warp: major loop and minor loops (40)"),
                ("sans-serif", 22),
            )
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..x_max, 0.0..fm * 1.05)?;
        chart
            .configure_mesh()
            .x_desc("strain ε (%)")
            .y_desc("force per width f (gf/cm)")
            .axis_desc_style(("sans-serif", 18))
            .label_style(("sans-serif", 15))
            .draw()?;
        chart
            .draw_series(LineSeries::new(major, BLACK.stroke_width(3)))?
            .label("major loop (KES, 0 → 500 → 0 gf/cm)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(3)));
        let paths: [(&[f64], &str); 4] = [
            (&[100.0, 0.0, fm], "to 100, back to 0, to 500"),
            (&[250.0, 0.0, fm], "to 250, back to 0, to 500"),
            (&[400.0, 120.0, fm], "to 400, back to 120, to 500"),
            (&[300.0, 150.0, 250.0, 50.0], "nested: 300 → 150 → 250 → 50"),
        ];
        for (k, (turns, label)) in paths.into_iter().enumerate() {
            let c = PALETTE[k];
            chart
                .draw_series(LineSeries::new(tensile_path(l, turns), c.stroke_width(2)))?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(("sans-serif", 15))
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()?;
        Ok(())
    })
}

/// Follow a curvature path (cm⁻¹ turning points) through the spindle model: (cm⁻¹, gf·cm/cm).
fn bending_path(s: &Spindle, turns: &[f64]) -> Vec<(f64, f64)> {
    let mut st = BendingState::VIRGIN;
    let mut pts = vec![(0.0, 0.0)];
    let mut from = 0.0;
    for &to in turns {
        for i in 1..=300 {
            let k = from + (to - from) * i as f64 / 300.0;
            let m = st.update(s, units::curvature_from_kes(k));
            pts.push((k, units::moment_to_kes(m)));
        }
        from = to;
    }
    pts
}

fn bending_loop(s: &Spindle, name: &str, path: &Path) -> Result<PathBuf> {
    let kes = bending_path(s, &[2.5, -2.5, 0.0]);
    let m_max = kes.iter().map(|p| p.1.abs()).fold(0.0, f64::max) * 1.1;
    let (b, m0) = (
        units::rigidity_to_kes(s.rigidity()),
        units::moment_to_kes(s.residual_moment()),
    );
    png(path, (1100, 800), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("Bending hysteresis (spindle model), {name}: B = {b:.3} gf·cm²/cm, 2HB = {:.3} gf·cm/cm", 2.0 * m0),
                ("sans-serif", 20),
            )
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(-2.7..2.7, -m_max..m_max)?;
        chart
            .configure_mesh()
            .x_desc("curvature K (1/cm)")
            .y_desc("moment per width M (gf·cm/cm)")
            .y_label_formatter(&|v| format!("{:.2}", if v.abs() < 1e-9 { 0.0 } else { *v }))
            .axis_desc_style(("sans-serif", 18))
            .label_style(("sans-serif", 15))
            .draw()?;
        let grey = RGBColor(150, 150, 150);
        for sign in [1.0, -1.0] {
            let line = vec![(-2.7, -2.7 * b + sign * m0), (2.7, 2.7 * b + sign * m0)];
            chart.draw_series(DashedLineSeries::new(line, 8, 6, grey.stroke_width(1)))?;
        }
        chart
            .draw_series(std::iter::once(PathElement::new(vec![(0.0, 0.0)], grey)))?
            .label("branches M = BK ± HB")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(1))
            });
        chart
            .draw_series(LineSeries::new(kes, BLACK.stroke_width(3)))?
            .label("KES cycle 0 → 2.5 → −2.5 → 0 (initial curve, reversals at ±2.5)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(3)));
        let paths: [(&[f64], &str); 3] = [
            (&[1.2, -0.6, 0.9], "0 → 1.2 → −0.6 → 0.9"),
            (&[0.3, -0.2, 0.5], "0 → 0.3 → −0.2 → 0.5 (inside the loop)"),
            (&[-1.8, -0.4, -1.2, 0.6], "0 → −1.8 → −0.4 → −1.2 → 0.6"),
        ];
        for (k, (turns, label)) in paths.into_iter().enumerate() {
            let c = PALETTE[k];
            chart
                .draw_series(LineSeries::new(bending_path(s, turns), c.stroke_width(2)))?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(("sans-serif", 15))
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()?;
        Ok(())
    })
}

/// Follow a shear-angle path (degrees, turning points) through the shear loop from rest, with
/// `per_deg` samples per degree: (°, gf/cm).
fn shear_path(l: &ShearLoop, turns: &[f64], per_deg: f64) -> Vec<(f64, f64)> {
    let mut st = ShearState::VIRGIN;
    let mut pts = vec![(0.0, 0.0)];
    let mut from = 0.0;
    for &to in turns {
        let n = ((to - from).abs() * per_deg).ceil().max(1.0) as usize;
        for i in 1..=n {
            let g = from + (to - from) * i as f64 / n as f64;
            let tau = st.update(l, g.to_radians());
            pts.push((g, units::force_to_kes(tau)));
        }
        from = to;
    }
    pts
}

/// The KES-FB1 shear loop of one fabric: left, the cycle 0 → +8° → −8° → +8° with the branches
/// and the measuring angles, and minor loops; right, the small angles enlarged (the initial
/// curve's finite slope 3G, a reversal inside the loop).
fn shear_loop(l: &ShearLoop, name: &str, path: &Path) -> Result<PathBuf> {
    let g = units::shear_stiffness_to_kes(l.stiffness());
    let (hg, hg5) = (
        units::force_to_kes(l.half_width(0.0)),
        units::force_to_kes(l.half_width(8f64.to_radians())),
    );
    let join = l.join_angle().to_degrees();
    let s0 = units::shear_stiffness_to_kes(l.initial_slope());
    let kes = shear_path(l, &[8.0, -8.0, 8.0], 12.0);
    let t_max = kes.iter().map(|p| p.1.abs()).fold(0.0, f64::max) * 1.08;
    let grey = RGBColor(150, 150, 150);
    png(path, (1600, 800), |root| {
        let (title, body) = root.split_vertically(64);
        title.draw(&Text::new(
            format!("Shear hysteresis (KES-FB1 loop), {name}"),
            (20, 8),
            ("sans-serif", 22).into_font(),
        ))?;
        title.draw(&Text::new(
            format!(
                "G = {g:.2} gf/(cm·deg), 2HG = {:.2} gf/cm, 2HG5 = {:.2} gf/cm; join angle \
                 Δj = 2HG/G = {join:.2}°; initial slope {s0:.2} gf/(cm·deg) = 3G",
                2.0 * hg,
                2.0 * hg5
            ),
            (20, 36),
            ("sans-serif", 18).into_font(),
        ))?;
        let (left, right) = body.split_horizontally(1000);
        // Left: the whole loop.
        let mut chart = ChartBuilder::on(&left)
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(-9.0..9.0, -t_max..t_max)?;
        chart
            .configure_mesh()
            .x_desc("shear angle γ (°)")
            .y_desc("shear force per width τ (gf/cm)")
            .axis_desc_style(("sans-serif", 18))
            .label_style(("sans-serif", 15))
            .draw()?;
        for x in [-5.0, -0.5, 0.5, 5.0] {
            chart.draw_series(DashedLineSeries::new(
                vec![(x, -t_max), (x, t_max)],
                3,
                5,
                grey.mix(0.6).stroke_width(1),
            ))?;
        }
        let branch = |sign: f64| -> Vec<(f64, f64)> {
            (0..=180)
                .map(|i| {
                    let x = -9.0 + 18.0 * i as f64 / 180.0;
                    let r = x.to_radians();
                    let tau = if sign > 0.0 { l.upper(r) } else { l.lower(r) };
                    (x, units::force_to_kes(tau))
                })
                .collect()
        };
        for sign in [1.0, -1.0] {
            chart.draw_series(DashedLineSeries::new(
                branch(sign),
                8,
                6,
                grey.stroke_width(2),
            ))?;
        }
        chart
            .draw_series(std::iter::once(PathElement::new(vec![(0.0, 0.0)], grey)))?
            .label("branches τ = Gγ ± h(|γ|) (h: HG to 0.5°, HG5 from 5°); dotted: ±0.5°, ±5°")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(2))
            });
        chart
            .draw_series(LineSeries::new(kes.clone(), BLACK.stroke_width(3)))?
            .label("KES cycle 0 → +8° → −8° → +8°")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(3)));
        let paths: [(&[f64], &str); 3] = [
            (&[6.0, 1.5, 7.0], "0 → 6° → 1.5° → 7°"),
            (&[-4.0, -1.0, -3.0, 2.5], "0 → −4° → −1° → −3° → 2.5°"),
            (
                &[3.0, 2.2, 3.5, -6.0],
                "0 → 3° → 2.2° → 3.5° → −6° (inside the loop)",
            ),
        ];
        for (k, (turns, label)) in paths.into_iter().enumerate() {
            let c = PALETTE[k];
            chart
                .draw_series(LineSeries::new(
                    shear_path(l, turns, 12.0),
                    c.stroke_width(2),
                ))?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(("sans-serif", 15))
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()?;
        // Right: small angles.
        let (x_max, y_max) = (2.0, units::force_to_kes(l.upper(2f64.to_radians())) * 1.15);
        let mut zoom = ChartBuilder::on(&right)
            .caption("small angles", ("sans-serif", 18))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(60)
            .build_cartesian_2d(-x_max..x_max, -y_max..y_max)?;
        zoom.configure_mesh()
            .x_desc("shear angle γ (°)")
            .y_desc("τ (gf/cm)")
            .axis_desc_style(("sans-serif", 18))
            .label_style(("sans-serif", 15))
            .draw()?;
        let narrow = |sign: f64| -> Vec<(f64, f64)> {
            (0..=80)
                .map(|i| {
                    let x = -x_max + 2.0 * x_max * i as f64 / 80.0;
                    let r = x.to_radians();
                    let tau = if sign > 0.0 { l.upper(r) } else { l.lower(r) };
                    (x, units::force_to_kes(tau))
                })
                .collect()
        };
        for sign in [1.0, -1.0] {
            zoom.draw_series(DashedLineSeries::new(
                narrow(sign),
                8,
                6,
                grey.stroke_width(2),
            ))?;
        }
        let tangent = vec![(-0.6, -0.6 * s0), (0.6, 0.6 * s0)];
        let amber = PALETTE[4];
        zoom.draw_series(DashedLineSeries::new(tangent, 6, 4, amber.stroke_width(2)))?
            .label(format!("slope at rest {s0:.2} gf/(cm·deg) = 3G"))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], amber.stroke_width(2))
            });
        zoom.draw_series(LineSeries::new(
            shear_path(l, &[1.6, -1.6, 1.6], 40.0),
            BLACK.stroke_width(3),
        ))?
        .label("0 → 1.6° → −1.6° → 1.6°")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(3)));
        let c = PALETTE[5];
        zoom.draw_series(LineSeries::new(
            shear_path(l, &[0.4, -0.3, 0.6], 80.0),
            c.stroke_width(2),
        ))?
        .label("0 → 0.4° → −0.3° → 0.6°")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(2)));
        zoom.configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(("sans-serif", 14))
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()?;
        Ok(())
    })
}

/// Polar plots for one fabric: loading-branch strain at three forces, and bending rigidity, at
/// 11.25° steps, thesis form (solid, circles) against compliance form (dashed, crosses).
fn polar(fabric: &Fabric, path: &Path) -> Result<PathBuf> {
    let steps = 32;
    let angles: Vec<f64> = (0..steps)
        .map(|k| (k as f64 * 11.25).to_radians())
        .collect();
    let forms = [AnisotropyForm::Thesis, AnisotropyForm::Compliance];
    // Per panel: title, unit, and per form the samples (θ, value).
    type Samples = Vec<(f64, f64)>;
    let mut panels: Vec<(String, &str, Vec<Samples>)> = Vec::new();
    for force_gf in [2.0, 20.0, 100.0] {
        let f = units::force_from_kes(force_gf);
        let mut per_form = Vec::new();
        for form in forms {
            let mut samples = Vec::new();
            for &th in &angles {
                let l = fabric.tensile_at(th, form)?;
                samples.push((th, units::strain_to_percent(l.strain(Branch::Loading, f))));
            }
            per_form.push(samples);
        }
        panels.push((
            format!("tensile strain at {force_gf} gf/cm (loading)"),
            "%",
            per_form,
        ));
    }
    let mut per_form = Vec::new();
    for form in forms {
        let mut samples = Vec::new();
        for &th in &angles {
            samples.push((
                th,
                units::rigidity_to_kes(fabric.bending_at(th, form)?.rigidity()),
            ));
        }
        per_form.push(samples);
    }
    panels.push(("bending rigidity B".to_owned(), "gf·cm²/cm", per_form));

    png(path, (1400, 1450), |root| {
        let (title, body) = root.split_vertically(50);
        title.draw(&Text::new(
            format!("Orthotropic interpolation at 11.25° steps: {}", fabric.name),
            (20, 12),
            ("sans-serif", 24).into_font(),
        ))?;
        for (area, (caption, unit, per_form)) in body.split_evenly((2, 2)).iter().zip(&panels) {
            let r_data = per_form.iter().flatten().map(|p| p.1).fold(0.0, f64::max);
            let r = nice_ceiling(r_data);
            let mut chart = ChartBuilder::on(area)
                .caption(caption.as_str(), ("sans-serif", 19))
                .margin(12)
                .build_cartesian_2d(-1.1 * r..1.1 * r, -1.1 * r..1.1 * r)?;
            polar_axes(
                &mut chart,
                1.1 * r,
                &[r / 4.0, r / 2.0, 3.0 * r / 4.0, r],
                unit,
            )?;
            for (k, samples) in per_form.iter().enumerate() {
                let c = PALETTE[k];
                let pts = polar_points(samples);
                let label = format!("{:?} form", forms[k]);
                if k == 0 {
                    chart
                        .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?
                        .label(label)
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(2))
                        });
                    chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
                } else {
                    chart
                        .draw_series(DashedLineSeries::new(pts.clone(), 8, 5, c.stroke_width(2)))?
                        .label(label)
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(2))
                        });
                    chart.draw_series(pts.iter().map(|&p| Cross::new(p, 5, c.stroke_width(2))))?;
                }
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::LowerRight)
                .label_font(("sans-serif", 14))
                .background_style(WHITE.mix(0.9))
                .border_style(BLACK)
                .draw()?;
        }
        Ok(())
    })
}
