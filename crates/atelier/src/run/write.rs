//! The run's outputs written into its folder: exports, pictures, a wet scene's series and
//! charts.

use std::path::{Path, PathBuf};

use super::{PictureStyle, RunOptions, outputs};
use crate::export::{
    Animation, ExportError, FrameValues, GlbOptions, MeshPart, VertexColours, write_glb, write_obj,
    write_ply,
};
use crate::outcome::{KindOutputs, RunError, Simulated};

/// Colour of the cloth in exports and pictures.
const CLOTH_COLOUR: [f32; 3] = [0.85, 0.35, 0.25];
/// Colours of a garment's panels in `run.glb` (sRGB; Tableau 10, distinct for up to ten panels,
/// then repeated).
const PANEL_COLOURS: [[f32; 3]; 10] = [
    [0.306, 0.475, 0.655],
    [0.949, 0.557, 0.169],
    [0.882, 0.341, 0.349],
    [0.463, 0.718, 0.698],
    [0.349, 0.631, 0.310],
    [0.929, 0.788, 0.282],
    [0.690, 0.478, 0.631],
    [1.000, 0.616, 0.655],
    [0.612, 0.459, 0.373],
    [0.729, 0.690, 0.675],
];
/// Colour of the body or tester.
const SOLID_COLOUR: [f32; 3] = [0.75, 0.75, 0.78];

/// Write the exports and pictures; returns the names written and warnings for exports that
/// could not be made (other than for I/O, which is an error).
pub(super) fn write_outputs(
    sim: &Simulated,
    out: &Path,
    options: &RunOptions,
    style: PictureStyle,
) -> Result<(Vec<String>, Vec<String>), RunError> {
    let mut written = Vec::new();
    let mut warnings = Vec::new();
    if let KindOutputs::Fit(fit, chart) = &sim.outputs {
        // A string identification: its parameters and the shapes' chart, no cloth.
        let (w, h) = options.picture;
        let io = |path: PathBuf| move |source| RunError::Output { path, source };
        let path = out.join(outputs::PARAMETERS);
        atelier_files::files::write_atomic(&path, fit.parameters_ron.as_bytes())
            .map_err(io(path))?;
        written.push(outputs::PARAMETERS.into());
        let size = (2 * w as u32, h as u32);
        write_chart(
            out,
            outputs::PICTURE,
            chart,
            size,
            &mut written,
            &mut warnings,
        )?;
        return Ok((written, warnings));
    }
    let Some(final_cloth) = sim.cloth.last() else {
        warnings.push("no frame to write".into());
        return Ok((written, warnings));
    };
    let cloth_part = MeshPart::cloth("cloth", &sim.cloth_triangles, CLOTH_COLOUR);
    let solid_part = sim
        .solid
        .as_ref()
        .map(|s| (MeshPart::body(s.name, &s.triangles, SOLID_COLOUR), s));
    let mut still: Vec<(MeshPart<'_>, &[[f64; 3]])> = vec![(cloth_part, final_cloth)];
    if let Some((part, s)) = &solid_part
        && let Some(last) = s.motion.last()
    {
        still.push((*part, last));
    }
    let mut export = |name: &str, result: Result<(), ExportError>| -> Result<(), RunError> {
        match result {
            Ok(()) => {
                written.push(name.to_string());
                Ok(())
            }
            Err(ExportError::Io { path, source }) => Err(RunError::Output { path, source }),
            Err(e) => {
                warnings.push(format!("{name} not written: {e}"));
                Ok(())
            }
        }
    };
    export(outputs::OBJ, write_obj(&out.join(outputs::OBJ), &still))?;
    export(outputs::PLY, write_ply(&out.join(outputs::PLY), &still))?;
    // run.glb also carries what the viewer colours the cloth by: its panels and, per frame,
    // each node's strain error.
    let panel_colours: Vec<[f32; 3]> = sim
        .detail
        .node_panel
        .iter()
        .map(|&p| PANEL_COLOURS[p as usize % PANEL_COLOURS.len()])
        .collect();
    let name_colours: Vec<[f32; 3]> = (0..sim.detail.panels.len())
        .map(|p| PANEL_COLOURS[p % PANEL_COLOURS.len()])
        .collect();
    let mut cloth_glb = cloth_part;
    if !panel_colours.is_empty() {
        cloth_glb.vertex_colours = Some(VertexColours {
            colours: &panel_colours,
            names: &sim.detail.panels,
            name_colours: &name_colours,
        });
    }
    if !sim.detail.strain_error.is_empty() {
        cloth_glb.frame_values = Some(FrameValues {
            name: "strain_error",
            values: &sim.detail.strain_error,
        });
    }
    let mut animated: Vec<(MeshPart<'_>, &Animation)> = vec![(cloth_glb, &sim.cloth)];
    if let Some((part, s)) = &solid_part {
        animated.push((*part, &s.motion));
    }
    let glb = GlbOptions {
        frames: options.frames,
        ..GlbOptions::default()
    };
    export(
        outputs::GLB,
        write_glb(&out.join(outputs::GLB), &animated, &glb),
    )?;

    let (w, h) = options.picture;
    if let KindOutputs::Wet(wet, _) = &sim.outputs {
        write_wet_outputs(
            wet,
            &sim.cloth_triangles,
            out,
            (w, h),
            &mut written,
            &mut warnings,
        )?;
        return Ok((written, warnings));
    }
    let solid_final = solid_part
        .as_ref()
        .and_then(|(_, s)| s.motion.last().map(|p| (p, s.triangles.as_slice())));
    let draw = |map: &dyn Fn(&[f64; 3]) -> [f64; 3], w: usize, h: usize| {
        let cloth: Vec<[f64; 3]> = final_cloth.iter().map(map).collect();
        let solid_points: Option<Vec<[f64; 3]>> =
            solid_final.map(|(p, _)| p.iter().map(map).collect());
        let solid = solid_points.as_deref().zip(solid_final.map(|(_, t)| t));
        crate::picture::garment_views((&cloth, &sim.cloth_triangles), solid, w, h)
    };
    let pixels = match style {
        // A strip is seen edge-on from the front: tilt it 35° about x (its top towards the
        // camera) so that its droop and its surface both show.
        PictureStyle::Tilted => {
            let (s, c) = 35f64.to_radians().sin_cos();
            draw(&|p| [p[0], p[1] * c - p[2] * s, p[1] * s + p[2] * c], w, h)
        }
        _ => draw(&|p| *p, w, h),
    };
    match &sim.outputs {
        KindOutputs::Chart(chart) if crate::chart::DRAWN => {
            let size = (2 * w as u32, h as u32);
            write_chart(
                out,
                outputs::PICTURE,
                chart,
                size,
                &mut written,
                &mut warnings,
            )?;
        }
        _ => {
            // Without the `charts` feature a virtual test's chart gives way to the cloth's picture.
            let path = out.join(outputs::PICTURE);
            crate::picture::write_png(&path, &pixels, 2 * w, h, [1.0; 3])
                .map_err(|source| RunError::Output { path, source })?;
            written.push(outputs::PICTURE.into());
        }
    }
    if style == PictureStyle::WithTop {
        // Seen from above: screen x = x, screen y = −z (forward is down), depth y.
        let pixels = draw(&|p| [p[0], -p[2], p[1]], h, h);
        // Keep the left (front) half: the view from above.
        let mut top = Vec::with_capacity(h * h);
        for row in pixels.chunks(2 * h) {
            top.extend_from_slice(&row[..h]);
        }
        let path = out.join(outputs::TOP);
        crate::picture::write_png(&path, &top, h, h, [1.0; 3])
            .map_err(|source| RunError::Output { path, source })?;
        written.push(outputs::TOP.into());
    }
    Ok((written, warnings))
}

/// The pictures, series and charts of a wet scene.
fn write_wet_outputs(
    wet: &crate::wet::WetOutputs,
    triangles: &[[u32; 3]],
    out: &Path,
    (w, h): (usize, usize),
    written: &mut Vec<String>,
    warnings: &mut Vec<String>,
) -> Result<(), RunError> {
    let io = |path: PathBuf| move |source| RunError::Output { path, source };
    // One height scale for both runs' pictures.
    let top = std::iter::once(&wet.final_z_up)
        .chain(wet.compare_z_up.as_ref())
        .flatten()
        .map(|p| p[2])
        .fold(0.01, f64::max);
    for (name, positions) in std::iter::once((outputs::PICTURE, &wet.final_z_up))
        .chain(wet.compare_z_up.as_ref().map(|c| (outputs::COMPARE, c)))
    {
        let pixels = crate::picture::wet_views((positions, triangles), wet.size, top, w, h);
        let path = out.join(name);
        crate::picture::write_png(&path, &pixels, 2 * w, h, [1.0; 3]).map_err(io(path))?;
        written.push(name.into());
    }
    let path = out.join(outputs::SERIES);
    atelier_files::files::write_atomic(&path, wet.series_csv.as_bytes()).map_err(io(path))?;
    written.push(outputs::SERIES.into());
    for (name, chart) in &wet.charts {
        write_chart(
            out,
            name,
            chart,
            (2 * w as u32, h as u32),
            written,
            warnings,
        )?;
    }
    Ok(())
}

/// Draw `chart` into `out/name` and list it as written; without the `charts` feature, a warning
/// that it was left out instead.
fn write_chart(
    out: &Path,
    name: &str,
    chart: &crate::chart::Chart,
    size: (u32, u32),
    written: &mut Vec<String>,
    warnings: &mut Vec<String>,
) -> Result<(), RunError> {
    #[cfg(feature = "charts")]
    {
        let _ = warnings;
        let path = out.join(name);
        crate::chart::write_chart(&path, chart, size)
            .map_err(|source| RunError::Output { path, source })?;
        written.push(name.into());
    }
    #[cfg(not(feature = "charts"))]
    {
        let _ = (out, chart, size, written);
        warnings.push(format!(
            "{name} ({}) not drawn: atelier was built without its `charts` feature",
            chart.title
        ));
    }
    Ok(())
}
