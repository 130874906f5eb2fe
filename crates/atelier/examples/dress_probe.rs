//! Probe (not a test): run a garment scenario and print, for every unsewn pair, its gap and
//! the strain of the axial edges at its two nodes, with the steps' convergence:
//! `cargo run --release -p atelier --example dress_probe -- SCENARIO.ron [seconds]`
//! (`PROBE_STEPS=1`: a line per step; `PROBE_EDGE=i,j,…`: where those edges are at the end;
//! `PROBE_DUMP=FILE`: the final positions, one node per line; `PROBE_TOL=x`: the shape
//! tolerance).
use atelier::scenario::{Scenario, ScenarioKind};
use atelier::{Scene, Simulation};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let file = Path::new(&args[1]);
    let until: f64 = args.get(2).map_or(1.0, |s| s.parse().unwrap());
    let sc = Scenario::load(file).expect("scenario");
    let ScenarioKind::Garment(spec) = &sc.kind else {
        panic!("garment")
    };
    let mut scene = Scene::load(spec, file.parent().unwrap()).expect("scene");
    if let Ok(t) = std::env::var("PROBE_TOL") {
        scene.settings.step.shape.tolerance = t.parse().expect("PROBE_TOL: a number");
    }
    let mut sim = Simulation::new(scene).expect("sim");
    let (mut steps, mut bad, mut worst) = (0, 0, 0.0f64);
    let (mut inside, mut depth, mut iterations, mut halved) = (0usize, 0.0f64, 0usize, 0usize);
    let mut extra = 0usize;
    let wall = std::time::Instant::now();
    println!("inside at the start: {}", sim.inside_by_part());
    while sim.time() < until - 1e-9 {
        match sim.step() {
            Ok(Some(o)) => {
                steps += 1;
                inside = inside.max(o.inside);
                depth = depth.max(o.depth);
                iterations += o.report.shape_iterations;
                halved += usize::from(o.substeps > 1);
                extra += usize::from(
                    o.report.collision_passes > sim.scene().settings.step.shape.collision_passes,
                );
                if !o.report.converged {
                    bad += 1;
                    worst = worst.max(o.report.violation);
                }
                if std::env::var("PROBE_STEPS").is_ok() {
                    println!(
                        "step t={:.2} inside {} sub {} it {} fact {} conv {} viol {:.1e} worst {:?} self hits {} planes {} vertex planes {} {:.2}s",
                        sim.time(),
                        o.inside,
                        o.substeps,
                        o.report.shape_iterations,
                        o.report.factorizations,
                        o.report.converged,
                        o.report.violation,
                        o.report.worst,
                        o.contacts.self_hits,
                        o.contacts.planes,
                        o.contacts.vertex_planes,
                        wall.elapsed().as_secs_f64()
                    );
                }
            }
            Ok(None) => break,
            Err(e) => {
                println!("error {e}");
                break;
            }
        }
    }
    if let Ok(path) = std::env::var("PROBE_DUMP") {
        let text: String = sim
            .state()
            .positions
            .iter()
            .map(|p| format!("{:.9} {:.9} {:.9}\n", p.x, p.y, p.z))
            .collect();
        std::fs::write(&path, text).expect("dump written");
    }
    let g = &sim.scene().garment.cloth;
    let topo = g.cloth.topology();
    let x = &sim.state().positions;
    let strain = |e: &atelier_grid::topology::Edge| {
        (x[e.b as usize] - x[e.a as usize]).norm() / e.rest_length - 1.0
    };
    if let Ok(list) = std::env::var("PROBE_NODES") {
        let rest = topo.rest_positions();
        let axial = g.cloth.bending_neighbours();
        for k in list.split(',') {
            let i: usize = k.parse().unwrap();
            for dir in 0..2 {
                let (a, b) = (axial[i][2 * dir], axial[i][2 * dir + 1]);
                if a == atelier_grid::NO_NODE || b == atelier_grid::NO_NODE {
                    continue;
                }
                let p2 = |k: u32| nalgebra::Vector2::new(rest[k as usize][0], rest[k as usize][1]);
                let (e1, e2) = (p2(i as u32) - p2(b), p2(a) - p2(i as u32));
                let (f1, f2) = (x[i] - x[b as usize], x[a as usize] - x[i]);
                let ang = |c: f64| c.clamp(-1.0, 1.0).acos().to_degrees();
                let panel = g.offsets.iter().rposition(|&o| o as usize <= i).unwrap();
                println!(
                    "node {i} dir {dir} panel {panel}: rest turn {:.1}°, now {:.1}° (edges {:.4} {:.4}, rest {:.4} {:.4}) at {:?}",
                    ang(e1.dot(&e2) / (e1.norm() * e2.norm())),
                    ang(f1.dot(&f2) / (f1.norm() * f2.norm())),
                    f1.norm(),
                    f2.norm(),
                    e1.norm(),
                    e2.norm(),
                    x[i]
                );
            }
        }
    }
    if let Ok(list) = std::env::var("PROBE_EDGE") {
        let seam_nodes: std::collections::HashSet<u32> =
            g.pairs.iter().flat_map(|&(a, b)| [a, b]).collect();
        for e in list.split(',') {
            let k: usize = e.parse().unwrap();
            let ed = &topo.edges()[k];
            let panel = g.offsets.iter().rposition(|&o| o <= ed.a).unwrap();
            println!(
                "edge {k}: {:?} nodes {} {} panel {panel} rest {:.4} strain {:+.4} seam nodes {} {} at {:?}",
                ed.kind,
                ed.a,
                ed.b,
                ed.rest_length,
                strain(ed),
                seam_nodes.contains(&ed.a),
                seam_nodes.contains(&ed.b),
                x[ed.a as usize]
            );
        }
    }
    let (sewn, all) = sim.sewing_progress();
    println!(
        "{steps} steps, {bad} unconverged (worst {worst:.2e}), {:.1} s wall, sewn at {:?}; {:.1} shape iterations per step; most nodes inside the body {inside} (deepest {:.1} mm); {halved} steps taken again in parts, {extra} with extra collision passes",
        wall.elapsed().as_secs_f64(),
        sim.sewn_at(),
        iterations as f64 / steps.max(1) as f64,
        depth * 1e3
    );
    println!("t = {:.2} s, {sewn}/{all} sewn", sim.time());
    let unsewn = {
        let mut v = Vec::new();
        for (k, &(a, b)) in g.pairs.iter().enumerate() {
            let gap = (x[a as usize] - x[b as usize]).norm();
            if gap > 2e-3 {
                v.push((k, a, b, gap));
            }
        }
        v
    };
    for (k, a, b, gap) in unsewn {
        let s = |n: u32| {
            let es = topo.incident_edges(n as usize);
            let mut out = Vec::new();
            for &e in es {
                let e = &topo.edges()[e as usize];
                if e.kind.is_axial() {
                    out.push(format!("{:+.3}", strain(e)));
                }
            }
            out.join(" ")
        };
        let p = x[a as usize];
        println!(
            "{:>3} {:<28} gap {:5.1} mm at ({:+.3},{:+.3},{:+.3})  a: {}  b: {}",
            k,
            g.pair_names[k],
            gap * 1e3,
            p.x,
            p.y,
            p.z,
            s(a),
            s(b)
        );
    }
    // Overall strain statistics by panel.
    let mut worst = vec![0.0f64; g.offsets.len()];
    for e in topo.edges() {
        if !e.kind.is_axial() {
            continue;
        }
        let panel = g.offsets.iter().rposition(|&o| o <= e.a).unwrap();
        worst[panel] = worst[panel].max(strain(e));
    }
    println!(
        "largest axial strain per panel: {:?}",
        worst.iter().map(|w| format!("{w:.4}")).collect::<Vec<_>>()
    );
}
