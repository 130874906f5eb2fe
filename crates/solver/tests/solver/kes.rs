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
    let topo =
        ClothTopology::from_structured(&StructuredGrid::sheet(nu, nv, width, gauge)).expect("grid");
    let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
    let place = |[x, y]: [f64; 2]| Vector3::new(x, y, 0.0);
    for i in 0..nu {
        let p = cloth.topology().rest_positions()[i];
        cloth
            .pin(i as u32, place(p), PinMotion::Fixed)
            .expect("pin");
    }
    let mut state = ClothState::placed(&cloth, place);
    let params = StepParams {
        dt: 0.01,
        gravity: [0.0; 3],
        damping: 5.0,
        // A quasi-static test with loads of 500 gf/cm on a few milligrams per node: the
        // internal forces must balance each node's load tightly, or the remainder accelerates
        // the light edge nodes far in one step.
        internal_tolerance: 1e-9,
        internal_max_iterations: 500,
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
            let share = if i == top[0] || i == top[nu - 1] {
                0.5 * h
            } else {
                h
            };
            solver.external_forces[i] = Vector3::new(0.0, per_width * share, 0.0);
        }
        for _ in 0..hold {
            solver.step(&cloth, &mut state, &params).expect("step");
        }
        // Mean strain of the warp edges of the interior columns.
        let strains: Vec<f64> = (2..nu - 2)
            .flat_map(|i| (0..nv - 1).map(move |j| (j * nu + i, (j + 1) * nu + i)))
            .map(|(a, b)| {
                (state.positions[b] - state.positions[a]).norm() / (gauge / (nv - 1) as f64) - 1.0
            })
            .collect();
        out.push((force, strains.iter().sum::<f64>() / strains.len() as f64));
    }
    out
}

/// The strain the tensile model itself gives along `path` (gf/cm), edge by edge.
fn model_strains(name: &str, path: &[f64]) -> Vec<f64> {
    let l = fabric(name).tensile.warp;
    let mut st = TensileState::VIRGIN;
    path.iter()
        .map(|&f| st.update(&l, units::force_from_kes(f)))
        .collect()
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
        let mut worst: f64 = 0.0;
        for (k, (&(force, strain), &expect)) in sim.iter().zip(&model).enumerate() {
            let loading = k < 100;
            if force % 50.0 != 0.0 || force == 0.0 && loading {
                continue;
            }
            // The model along the path is the major loop: loading, then unloading from Fm.
            let branch = if loading {
                Branch::Loading
            } else {
                Branch::Unloading
            };
            let major = l.strain(branch, units::force_from_kes(force));
            assert!(
                (expect - major).abs() < 1e-9,
                "{name}: path model off the major loop"
            );
            let err = (strain - expect).abs() / expect;
            assert!(
                err < 0.02,
                "{name} at {force} gf/cm ({branch:?}): simulated {strain:.5}, input {expect:.5} ({:.2} %)",
                100.0 * err
            );
            checked += 1;
            worst = worst.max(err);
        }
        assert_eq!(checked, 20, "{name}: ten levels on each branch");
        eprintln!(
            "KES tensile {name}: largest strain error on the major loop {:.2e} (relative)",
            worst
        );
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
        let mut worst_minor: f64 = 0.0;
        for (force, strain, expect) in minor {
            let err = (strain - expect).abs() / expect;
            worst_minor = worst_minor.max(err);
            assert!(
                err < 0.02,
                "{name} minor loop at {force} gf/cm: {strain:.5} vs {expect:.5}"
            );
            // And it lies strictly inside the major loop.
            let f = units::force_from_kes(force);
            assert!(
                expect < l.strain(Branch::Unloading, f)
                    && expect >= l.strain(Branch::Loading, f) - 1e-12
            );
        }
    }
}

/// Scene 5: the KES-FB2 bending test on a simulated strip. The instrument imposes a uniform
/// curvature on the whole 1 cm gauge; here every node of the strip (10 cells along the warp,
/// 2 nodes across 1 cm) is moved, step by step, onto a circular arc of curvature K:
/// 0 → +2.5 → −2.5 → 0 cm⁻¹. The solver's bending stage estimates the curvature from the node
/// normals, evaluates the moment through the hysteresis states it commits each step (with its
/// regularisation: stick slope, dead band), and the moment per width and curvature at the
/// middle nodes, recorded along the cycle, give B (slope over 0.5–1.5 cm⁻¹) and 2HB (loop width
/// at ±1 cm⁻¹) within 5 % of the fabric's. (Driving only the clamps and letting the interior
/// settle is a dynamic problem in its own right: at Δt = 2e-4 s the interior rings by
/// ±1 cm⁻¹ and every step starts a minor loop; see docs/solver.md.)
#[test]
fn virtual_kes_bending_test_recovers_b_and_2hb() {
    for name in ["cotton_broad", "wool_tropical"] {
        let f = fabric(name);
        let (cells, gauge, width) = (10usize, 0.01, 0.01);
        let h = gauge / cells as f64;
        let nv = cells + 3; // one clamp row beyond each end
        let topo = ClothTopology::from_structured(&StructuredGrid::sheet(
            2,
            nv,
            width,
            (nv - 1) as f64 * h,
        ))
        .expect("grid");
        let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
        let centre = 0.5 * (nv - 1) as f64 * h;
        // Node (i, j) on the arc of curvature k through the centre, tangent along x there.
        let on_arc = |k: f64, x: f64, y: f64| {
            let s = y - centre;
            if k.abs() < 1e-12 {
                Vector3::new(s, x, 0.0)
            } else {
                Vector3::new((k * s).sin() / k, x, (1.0 - (k * s).cos()) / k)
            }
        };
        let clamped: Vec<usize> = (0..2 * nv).collect();
        let rest = cloth.topology().rest_positions().to_vec();
        for &node in &clamped {
            let [x, y] = rest[node];
            cloth
                .pin(node as u32, on_arc(0.0, x, y), PinMotion::Fixed)
                .expect("pin");
        }
        let mut state = ClothState::placed(&cloth, |[x, y]| on_arc(0.0, x, y));
        let params = StepParams {
            dt: 1e-3,
            gravity: [0.0; 3],
            ..StepParams::default()
        };
        let mut solver = Solver::new();
        let kmax = units::KES_MAX_CURVATURE;
        let per_leg = 500;
        let leg =
            |a: f64, b: f64| (1..=per_leg).map(move |i| a + (b - a) * i as f64 / per_leg as f64);
        let path: Vec<(usize, f64)> = leg(0.0, kmax)
            .map(|k| (0, k))
            .chain(leg(kmax, -kmax).map(|k| (1, k)))
            .chain(leg(-kmax, 0.0).map(|k| (2, k)))
            .collect();
        let middle = [2 * (nv / 2), 2 * (nv / 2) + 1];
        let mut passes: [Vec<(f64, f64)>; 3] = [Vec::new(), Vec::new(), Vec::new()];
        for (pass, k) in path {
            for &node in &clamped {
                let [x, y] = rest[node];
                cloth
                    .pin(node as u32, on_arc(k, x, y), PinMotion::Fixed)
                    .expect("pin");
            }
            solver.step(&cloth, &mut state, &params).expect("step");
            let eta = middle
                .iter()
                .map(|&i| 0.5 * (solver.last_curvatures()[i][2] + solver.last_curvatures()[i][3]))
                .sum::<f64>()
                / 2.0;
            let moment: f64 = middle
                .iter()
                .map(|&i| solver.last_node_moments()[i])
                .sum::<f64>()
                / width;
            passes[pass].push((eta, moment));
        }
        // The strip's normal may point either way: orient curvature (and moment) so that the
        // first leg bends positively, as the instrument's first pass does.
        let orientation = passes[0].last().map_or(1.0, |p| p.0.signum());
        for pass in &mut passes {
            for p in pass.iter_mut() {
                *p = (orientation * p.0, orientation * p.1);
            }
        }
        let slope = |pts: &[(f64, f64)], sign: f64| {
            let sel: Vec<(f64, f64)> = pts
                .iter()
                .copied()
                .filter(|p| {
                    sign * p.0 >= 0.5 * units::CURVATURE && sign * p.0 <= 1.5 * units::CURVATURE
                })
                .collect();
            let n = sel.len() as f64;
            let (sx, sy) = sel.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
            let (mx, my) = (sx / n, sy / n);
            let (num, den) = sel.iter().fold((0.0, 0.0), |a, p| {
                (a.0 + (p.0 - mx) * (p.1 - my), a.1 + (p.0 - mx).powi(2))
            });
            num / den
        };
        let at = |pts: &[(f64, f64)], eta: f64| {
            pts.iter()
                .min_by(|a, b| (a.0 - eta).abs().total_cmp(&(b.0 - eta).abs()))
                .map(|p| p.1)
                .expect("points")
        };
        let one = units::CURVATURE;
        let b = 0.5 * (slope(&passes[0], 1.0) + slope(&passes[1], -1.0));
        let two_hb = 0.5
            * ((at(&passes[0], one) - at(&passes[1], one))
                + (at(&passes[2], -one) - at(&passes[1], -one)));
        let (b_in, hb_in) = (
            f.bending.warp.rigidity(),
            2.0 * f.bending.warp.residual_moment(),
        );
        eprintln!(
            "KES bending {name}: B {:.4} (input {:.4}) gf·cm²/cm, 2HB {:.4} (input {:.4}) gf·cm/cm",
            units::rigidity_to_kes(b),
            units::rigidity_to_kes(b_in),
            units::moment_to_kes(two_hb),
            units::moment_to_kes(hb_in)
        );
        assert!((b / b_in - 1.0).abs() < 0.05, "{name}: B {b} vs {b_in}");
        assert!(
            (two_hb / hb_in - 1.0).abs() < 0.05,
            "{name}: 2HB {two_hb} vs {hb_in}"
        );
    }
}

/// The KES-FB1 shear test with compliant diagonals (`ConstraintKind::Compliant`): a 20 × 5 cm
/// strip, bottom edge clamped, the top edge pulled along the strip by a shear force per width τ
/// under the instrument's 10 gf/cm pretension. The interior columns lean by γ = τ / G, G the
/// fabric's KES shear stiffness; with rigid diagonals they do not lean at all.
#[test]
#[ignore = "issue 7, not met yet: the strip leans 2.76° (Chebyshev) or 4.52° (Jacobi) at τ = 1 gf/cm against τ/G = 0.667°, and is still moving after 3 s (kinetic energy 7e-4 J, shape residual 1e-7 m after 800 iterations): the compliant iteration has not reached its fixed point, so the lean depends on the iteration"]
fn compliant_diagonals_shear_by_the_kes_stiffness() {
    use atelier_solver::ConstraintKind;
    let f = fabric("cotton_broad");
    let g = f.shear.as_ref().expect("KES shear values").stiffness;
    let (nu, nv, width, gauge) = (21, 6, 0.20, 0.05);
    let run = |kind: ConstraintKind, tau: f64| {
        let topo = ClothTopology::from_structured(&StructuredGrid::sheet(nu, nv, width, gauge))
            .expect("grid");
        let mut cloth = Cloth::new(topo, &f, AnisotropyForm::Thesis).expect("cloth");
        let place = |[x, y]: [f64; 2]| Vector3::new(x, y, 0.0);
        for i in 0..nu {
            let p = cloth.topology().rest_positions()[i];
            cloth
                .pin(i as u32, place(p), PinMotion::Fixed)
                .expect("pin");
        }
        let mut state = ClothState::placed(&cloth, place);
        let params = StepParams {
            dt: 0.01,
            gravity: [0.0; 3],
            damping: 5.0,
            internal_tolerance: 1e-9,
            internal_max_iterations: 200,
            shape_tolerance: 1e-10,
            shape_max_iterations: 400,
            diagonal_constraint: kind,
            ..StepParams::default()
        };
        let mut solver = Solver::new();
        let h = width / (nu - 1) as f64;
        let pre = units::force_from_kes(10.0);
        solver.external_forces = vec![Vector3::zeros(); nu * nv];
        for i in (nv - 1) * nu..nv * nu {
            let share = if i % nu == 0 || i % nu == nu - 1 {
                0.5 * h
            } else {
                h
            };
            solver.external_forces[i] = Vector3::new(tau * share, pre * share, 0.0);
        }
        for _ in 0..300 {
            solver.step(&cloth, &mut state, &params).expect("step");
        }
        // Mean lean of the vertical edges of the interior columns.
        let lean: Vec<f64> = (5..nu - 5)
            .flat_map(|i| (0..nv - 1).map(move |j| (j * nu + i, (j + 1) * nu + i)))
            .map(|(a, b)| {
                let d = state.positions[b] - state.positions[a];
                d.x.atan2(d.y)
            })
            .collect();
        lean.iter().sum::<f64>() / lean.len() as f64
    };
    for kes in [1.0, 2.0, 4.0] {
        let tau = units::force_from_kes(kes);
        let gamma = run(ConstraintKind::Compliant, tau);
        let want = tau / g;
        eprintln!(
            "τ = {kes} gf/cm: γ = {:.3}° (τ/G = {:.3}°)",
            gamma.to_degrees(),
            want.to_degrees()
        );
        assert!(
            (gamma / want - 1.0).abs() < 0.1,
            "τ = {kes} gf/cm: γ = {gamma} rad, τ/G = {want} rad"
        );
    }
    let rigid = run(ConstraintKind::Equality, units::force_from_kes(2.0));
    assert!(
        rigid.abs() < 0.05 * units::force_from_kes(2.0) / g,
        "rigid cells lean {rigid} rad"
    );
}
