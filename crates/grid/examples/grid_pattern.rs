//! A sewing pattern gridded into a cloth panel: the front bodice of the 9AR dress
//! (`fixtures/patterns/dress/front_bodice.ron`, the panel of the thesis's Fig. 32) is read, gridded
//! by Coons patches, improved by the smoothness, shear and spacing energies, and cooked into the
//! topology the solver consumes.
//!
//! `cargo run --release -p atelier-grid --example grid_pattern`

#![allow(clippy::print_stdout)] // an example shows its results on stdout

use std::path::Path;

use atelier_grid::pattern::{grid_pattern, load_pattern};
use atelier_grid::{GridQuality, ImproveParams, Stats};

const PATTERN: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../fixtures/patterns/dress/front_bodice.ron"
);

/// One line of the quality table: mean ± SD (min … max), scaled to the printed unit.
fn row(what: &str, s: &Stats, scale: f64, unit: &str) {
    println!(
        "  {what:<12} {:>8.3} ± {:<7.3} ({:.3} … {:.3}) {unit}",
        s.mean * scale,
        s.sd * scale,
        s.min * scale,
        s.max * scale
    );
}

fn quality(title: &str, q: &GridQuality) {
    println!("{title}:");
    row("u length", &q.u_length, 100.0, "cm");
    row("v length", &q.v_length, 100.0, "cm");
    row("shear", &q.shear_deg, 1.0, "°");
    row("cell area", &q.cell_area, 1e4, "cm²");
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The pattern file (RON, cm) is checked while it is parsed: a bad value names its line.
    let spec = load_pattern(Path::new(PATTERN))?;
    // Grid it with the default improvement weights (thesis §4.4).
    let panel = grid_pattern(&spec, ImproveParams::default())?;

    // The cooked topology: nodes, edges (axial and diagonal), quad cells, rest area (SI).
    let topo = &panel.topology;
    println!("panel \"{}\"", panel.name);
    println!(
        "  {} nodes, {} edges, {} cells, {} triangles, area {:.1} cm²",
        topo.node_count(),
        topo.edges().len(),
        topo.cells().len(),
        topo.triangles().len(),
        topo.area() * 1e4
    );
    println!(
        "  {} boundary teams, {} darts (each a list of node pairs to sew)",
        panel.teams.len(),
        panel.darts.len()
    );

    // Grid quality before and after the improvement (lengths measured on the grid, in m).
    quality("initial grid (Coons patches)", &panel.quality_before);
    quality("improved grid", &panel.quality_after);
    let e = &panel.improvement.energy;
    println!(
        "improvement: energy {:.4} → {:.4} in {} accepted steps (converged: {})",
        e.first().copied().unwrap_or(f64::NAN),
        e.last().copied().unwrap_or(f64::NAN),
        e.len().saturating_sub(1),
        panel.improvement.converged
    );
    Ok(())
}
