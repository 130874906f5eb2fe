//! Scenes 4 and 5: virtual KES tests. The simulated strip, loaded the way the KES-FB
//! instruments load a specimen, must give back the characteristics it was built from.

use atelier_fabric::{AnisotropyForm, Branch, TensileState, units};
use atelier_grid::{ClothTopology, StructuredGrid};
use atelier_solver::{Cloth, ClothState, PinMotion, Solver, StepParams};
use nalgebra::Vector3;

use crate::common::fabric;

/// The KES-FB1 tensile specimen: 20 cm wide (u), 5 cm gauge along the warp (v), bottom edge
/// clamped, a force per width f pulling the top edge. Returns the mean strain of the interior
/// warp edges after holding each force of `path` (gf/cm) for `hold` steps.
fn tensile_test(name: &str, path: &[f64], hold: usize) -> Vec<(f64, f64)> {
    let f = fabric(name);
    let (nu, nv, width, gauge) = (21, 6, 0.20, 0.05);
    let topo = ClothTopology::from_structured(&StructuredGrid::sheet(nu, nv, width, gauge)).expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let place = |[x, y]: [f64; 2]| Vector3::new(x, y, 0.0);
    for i in 0..nu {
        let p = cloth.topology().rest_positions()[i];
        cloth.pin(i as u32, place(p), PinMotion::Fixed).expect("pin");
    }
    let mut state = ClothState::placed(&cloth, place);
    let params = StepParams {
        dt: 0.01,
        gravity: [0.0; 3],
        damping: 5.0,
        shape_tolerance: 1e-9,
        shape_max_iterations: 200,
        ..StepParams::default()
    };
    let mut solver = Solver::new();
    let h = width / (nu - 1) as f64;
    let top: Vec<usize> = ((nv - 1) * nu..nv * nu).collect();
    let mut out = Vec::new();
    for &force in path {
        let per_width = units::force_from_kes(force);
        solver.external_forces = vec![Vector3::zeros(); nu * nv];
        for &i in &top {
            let share = if i == top[0] || i == top[nu - 1] { 0.5 * h } else { h };
            solver.external_forces[i] = Vector3::new(0.0, per_width * share, 0.0);
        }
        for _ in 0..hold {
            solver.step(&cloth, &mut state, &params).expect("step");
        }
        // Mean strain of the warp edges of the interior columns.
        let strains: Vec<f64> = (2..nu - 2)
            .flat_map(|i| (0..nv - 1).map(move |j| (j * nu + i, (j + 1) * nu + i)))
            .map(|(a, b)| (state.positions[b] - state.positions[a]).norm() / (gauge / (nv - 1) as f64) - 1.0)
            .collect();
        out.push((force, strains.iter().sum::<f64>() / strains.len() as f64));
    }
    out
}

/// The strain the tensile model itself gives along `path` (gf/cm), edge by edge.
fn model_strains(name: &str, path: &[f64]) -> Vec<f64> {
    let l = fabric(name).tensile.warp;
    let mut st = TensileState::VIRGIN;
    path.iter().map(|&f| st.update(&l, units::force_from_kes(f))).collect()
}

/// A quasi-static path: `0 → peak → 0` in steps of 5 gf/cm.
fn cycle(peak: f64) -> Vec<f64> {
    let up = (1..=(peak / 5.0) as usize).map(|k| 5.0 * k as f64);
    let down = (0..(peak / 5.0) as usize).rev().map(|k| 5.0 * k as f64);
    up.chain(down).collect()
}

/// Scene 4: loaded to 500 gf/cm and back, and a partial cycle to 250 gf/cm, the strip returns
/// the input loading and unloading curves and the minor loop within 2 % strain at ten force
/// levels each.
#[test]
fn virtual_kes_tensile_test_recovers_the_loops() {
    for name in ["cotton_broad", "silk"] {
        let l = fabric(name).tensile.warp;
        let full = cycle(500.0);
        let sim = tensile_test(name, &full, 3);
        let model = model_strains(name, &full);
        let mut checked = 0;
        for (k, (&(force, strain), &expect)) in sim.iter().zip(&model).enumerate() {
            let loading = k < 100;
            if force % 50.0 != 0.0 || force == 0.0 && loading {
                continue;
            }
            // The model along the path is the major loop: loading, then unloading from Fm.
            let branch = if loading { Branch::Loading } else { Branch::Unloading };
            let major = l.strain(branch, units::force_from_kes(force));
            assert!((expect - major).abs() < 1e-9, "{name}: path model off the major loop");
            let err = (strain - expect).abs() / expect;
            assert!(err < 0.02, "{name} at {force} gf/cm ({branch:?}): simulated {strain:.5}, input {expect:.5} ({:.2} %)", 100.0 * err);
            checked += 1;
        }
        assert_eq!(checked, 20, "{name}: ten levels on each branch");
        // Partial cycle to 250 gf/cm: the minor unloading branch of (40).
        let partial = cycle(250.0);
        let sim = tensile_test(name, &partial, 3);
        let model = model_strains(name, &partial);
        let minor: Vec<(f64, f64, f64)> = sim
            .iter()
            .zip(&model)
            .skip(50)
            .filter(|((f, _), _)| f % 25.0 == 0.0)
            .map(|(&(f, s), &m)| (f, s, m))
            .collect();
        assert_eq!(minor.len(), 10);
        for (force, strain, expect) in minor {
            let err = (strain - expect).abs() / expect;
            assert!(err < 0.02, "{name} minor loop at {force} gf/cm: {strain:.5} vs {expect:.5}");
            // And it lies strictly inside the major loop.
            let f = units::force_from_kes(force);
            assert!(expect < l.strain(Branch::Unloading, f) && expect >= l.strain(Branch::Loading, f) - 1e-12);
        }
    }
}
