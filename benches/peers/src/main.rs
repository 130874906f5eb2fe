//! Issue 10's peer benchmark, rapier-cloth side: atelier's `peer_scene` (a 1 m square sheet of
//! side × side nodes pinned at the two corners of one edge, falling for 2 s at Δt 0.01 s) and the
//! JIS drape (Ø 25.4 cm cotton disc on a Ø 12.7 cm pedestal), run in rapier-cloth 0.3.0 with its
//! default material and solver settings and then with a sweep of its accuracy knobs.
//!
//! `cargo run --release --manifest-path benches/peers/Cargo.toml -- --out FILE.json [--quick]`
//!
//! Everything is measured here: wall time per step with `Instant`, stretch from the node
//! positions read back from the cloth. Nothing is copied from the issue.

use std::fmt::Write as _;
use std::time::Instant;

use rapier_cloth::rapier::prelude::*;
use rapier_cloth::{
    Cloth, ClothError, ClothMaterial, ClothMesh, GridBuilder, RapierClothWorld, RapierScene,
    SceneSnapshot, Solver, SolverSettings, Vec3, WorldId,
};

/// Standard gravity, m/s² (atelier's value).
const G: f32 = 9.80665;
/// Cotton broadcloth, 12.38 mg/cm² in kg/m².
const COTTON_DENSITY: f32 = 0.1238;
/// Cotton's tensile stiffness along the warp per unit width, N/m (EMT 3 % at 500 gf/cm).
const COTTON_TENSILE: f32 = 500.0;
/// Scene step, s, and number of steps (2 s).
const DT: f32 = 0.01;
/// The same step in f64, for reporting times.
const DT_S: f64 = 0.01;
const STEPS: usize = 200;
/// Stretch above this (a fraction) counts as divergence.
const DIVERGED_STRETCH: f64 = 1.0;

/// One measured case.
#[derive(Clone, Debug, Default)]
struct Row {
    scene: &'static str,
    side: usize,
    nodes: usize,
    setting: String,
    ms_per_step: Option<f64>,
    stretch_end: Option<f64>,
    stretch_max: Option<f64>,
    diverged_at_s: Option<f64>,
    drape_coefficient: Option<f64>,
    note: String,
}

/// A solver configuration of the sweep.
#[derive(Clone, Debug)]
struct Setting {
    label: String,
    substeps: usize,
    iterations: usize,
    stretch_compliance: Option<f32>,
    /// Step the core `Solver` directly instead of `RapierClothWorld` + an empty Rapier world.
    core_only: bool,
}

impl Setting {
    fn new(label: &str, substeps: usize, iterations: usize) -> Self {
        Self {
            label: label.to_string(),
            substeps,
            iterations,
            stretch_compliance: None,
            core_only: false,
        }
    }
}

/// Structural ("axial") edges: pairs of node indices with their rest length.
type Edges = Vec<(usize, usize, f64)>;

/// Largest l/l0 − 1 over `edges` (NaN if any length is non-finite).
fn max_stretch(positions: &[Vec3], edges: &Edges) -> f64 {
    let mut worst = f64::MIN;
    for &(a, b, l0) in edges {
        let (pa, pb) = (positions[a], positions[b]);
        let d = [
            pa.x as f64 - pb.x as f64,
            pa.y as f64 - pb.y as f64,
            pa.z as f64 - pb.z as f64,
        ];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if !l.is_finite() {
            return f64::NAN;
        }
        worst = worst.max(l / l0 - 1.0);
    }
    worst
}

fn all_finite(positions: &[Vec3]) -> bool {
    positions.iter().all(|p| p.is_finite())
}

/// atelier's sheet in rapier-cloth's y-up frame: atelier (x, y, z) ↦ rapier (x, z, −y), a proper
/// rotation of −90° about x. Node (i, j) (i along atelier x, j along atelier y) has index
/// j·side + i, as in atelier's `StructuredGrid::sheet`.
fn sheet_mesh(side: usize) -> Result<ClothMesh, ClothError> {
    GridBuilder::new(side, side)
        .size(1.0, 1.0)
        .origin(Vec3::ZERO)
        .axes(Vec3::X, -Vec3::Z)
        .build()
}

fn sheet_edges(side: usize) -> Edges {
    let l0 = 1.0 / (side as f64 - 1.0);
    let mut e = Vec::with_capacity(2 * side * (side - 1));
    for j in 0..side {
        for i in 0..side {
            let n = j * side + i;
            if i + 1 < side {
                e.push((n, n + 1, l0));
            }
            if j + 1 < side {
                e.push((n, n + side, l0));
            }
        }
    }
    e
}

/// What a run produced before measuring stretch and time.
struct Outcome {
    wall: f64,
    steps_done: usize,
    stretch_max: f64,
    diverged_at: Option<f64>,
    error: Option<String>,
    positions: Vec<Vec3>,
    /// rapier-cloth's own `StepReport::max_stretch` after the last substep (all mesh edges,
    /// diagonals included).
    reported_max_stretch: Option<f64>,
}

/// Runs `steps` steps of `DT`, each as `setting.substeps` calls of the cloth step, checking
/// stretch every 10 steps. `colliders` adds static colliders to the Rapier world.
fn run(
    mesh: ClothMesh,
    material: ClothMaterial,
    pins: &[usize],
    setting: &Setting,
    colliders: Vec<Collider>,
    edges: &Edges,
) -> Result<Outcome, String> {
    let mut cloth = Cloth::new(mesh, material).map_err(|e| format!("cloth: {e}"))?;
    for &p in pins {
        let x = cloth.positions()[p];
        cloth.pin(p as u32, x).map_err(|e| format!("pin: {e}"))?;
    }
    let h = DT / setting.substeps as f32;
    let gravity = Vec3::new(0.0, -G, 0.0);
    let settings = SolverSettings {
        iterations: setting.iterations,
        ..SolverSettings::default()
    };
    let mut out = Outcome {
        wall: 0.0,
        steps_done: 0,
        stretch_max: f64::MIN,
        diverged_at: None,
        error: None,
        positions: Vec::new(),
        reported_max_stretch: None,
    };
    let check = |k: usize, positions: &[Vec3], out: &mut Outcome| -> bool {
        let s = max_stretch(positions, edges);
        let t = k as f64 * DT_S;
        if !all_finite(positions) || !s.is_finite() {
            out.diverged_at.get_or_insert(t);
            return false;
        }
        out.stretch_max = out.stretch_max.max(s);
        if s > DIVERGED_STRETCH {
            out.diverged_at.get_or_insert(t);
        }
        true
    };
    if setting.core_only {
        let mut solver = Solver::new();
        for k in 1..=STEPS {
            let t0 = Instant::now();
            let mut result = Ok(());
            for _ in 0..setting.substeps {
                match solver.step(&mut cloth, h, gravity, &settings) {
                    Ok(report) => out.reported_max_stretch = Some(report.max_stretch as f64),
                    Err(e) => {
                        result = Err(e);
                        break;
                    }
                }
            }
            out.wall += t0.elapsed().as_secs_f64();
            if let Err(e) = result {
                out.diverged_at.get_or_insert(k as f64 * DT_S);
                out.error = Some(format!("step {k}: {e}"));
                break;
            }
            out.steps_done = k;
            if k % 10 == 0 && !check(k, cloth.positions(), &mut out) {
                break;
            }
        }
        out.positions = cloth.positions().to_vec();
        return Ok(out);
    }
    let id = WorldId::new();
    let mut rigid = PhysicsWorld::new();
    rigid.gravity = gravity;
    rigid.integration_parameters.dt = h;
    for c in colliders {
        rigid.colliders.insert(c);
    }
    let mut world = RapierClothWorld::new(id);
    world.solver_settings = settings;
    let handle = world.add_cloth(cloth);
    let mut substep_index = 0u64;
    for k in 1..=STEPS {
        let t0 = Instant::now();
        let mut result = Ok(());
        for _ in 0..setting.substeps {
            let before = SceneSnapshot::capture(id, substep_index, &rigid.bodies, &rigid.colliders);
            rigid.step();
            let query = rigid.broad_phase.as_query_pipeline(
                rigid.narrow_phase.query_dispatcher(),
                &rigid.bodies,
                &rigid.colliders,
                QueryFilter::default(),
            );
            match world.step_substep(h, &RapierScene::new(query, &before, h, gravity)) {
                Ok(report) => {
                    out.reported_max_stretch =
                        report.cloths.first().map(|c| c.1.max_stretch as f64);
                }
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
            substep_index += 1;
        }
        out.wall += t0.elapsed().as_secs_f64();
        if let Err(e) = result {
            out.diverged_at.get_or_insert(k as f64 * DT_S);
            out.error = Some(format!("step {k}: {e}"));
            break;
        }
        out.steps_done = k;
        let cloth = world.cloth(handle).map_err(|e| e.to_string())?;
        if k % 10 == 0 && !check(k, cloth.positions(), &mut out) {
            break;
        }
    }
    out.positions = world
        .cloth(handle)
        .map_err(|e| e.to_string())?
        .positions()
        .to_vec();
    Ok(out)
}

fn material(setting: &Setting) -> ClothMaterial {
    let mut m = ClothMaterial {
        surface_density: COTTON_DENSITY,
        ..ClothMaterial::default()
    };
    if let Some(c) = setting.stretch_compliance {
        m.stretch_compliance = c;
    }
    m
}

fn sheet_row(side: usize, setting: &Setting) -> Row {
    let mut row = Row {
        scene: "sheet",
        side,
        nodes: side * side,
        setting: setting.label.clone(),
        ..Row::default()
    };
    let edges = sheet_edges(side);
    let pins = [(side - 1) * side, side * side - 1];
    let mesh = match sheet_mesh(side) {
        Ok(m) => m,
        Err(e) => {
            row.note = format!("failed to build the mesh: {e}");
            return row;
        }
    };
    match run(mesh, material(setting), &pins, setting, vec![], &edges) {
        Err(e) => row.note = format!("failed: {e}"),
        Ok(o) => fill(&mut row, &o, &edges, setting),
    }
    row
}

fn fill(row: &mut Row, o: &Outcome, edges: &Edges, setting: &Setting) {
    if o.steps_done > 0 || o.error.is_some() {
        let steps = (o.steps_done + usize::from(o.error.is_some())).max(1);
        row.ms_per_step = Some(1e3 * o.wall / steps as f64);
    }
    let end = max_stretch(&o.positions, edges);
    if o.steps_done == STEPS && end.is_finite() {
        row.stretch_end = Some(end);
    }
    if o.stretch_max.is_finite() && o.stretch_max > f64::MIN {
        row.stretch_max = Some(o.stretch_max);
    }
    row.diverged_at_s = o.diverged_at;
    let mut note = format!(
        "{} substep(s) of {} s, {} XPBD iteration(s) each; {}",
        setting.substeps,
        DT / setting.substeps as f32,
        setting.iterations,
        if setting.core_only {
            "core Solver::step only (no Rapier world)"
        } else {
            "RapierClothWorld::step_substep + PhysicsWorld::step"
        }
    );
    if let Some(c) = setting.stretch_compliance {
        let _ = write!(note, "; stretch_compliance {c} m/N (= 1/{COTTON_TENSILE} N/m)");
    }
    if let (Some(r), STEPS) = (o.reported_max_stretch, o.steps_done) {
        let _ = write!(
            note,
            "; rapier's own StepReport max_stretch at 2 s (all edges, diagonals included): {:.1} %",
            100.0 * r
        );
    }
    if let Some(e) = &o.error {
        let _ = write!(note, "; stopped: {e}");
    } else if o.steps_done < STEPS {
        let _ = write!(note, "; stopped after {} steps: non-finite positions", o.steps_done);
    }
    if o.diverged_at.is_some() && o.error.is_none() && o.steps_done == STEPS {
        note.push_str("; stretch passed 100 % but the run went on to 2 s");
    }
    row.note = note;
}

// ---------------------------------------------------------------- drape

const DISC_R: f64 = 0.127;
const PEDESTAL_R: f64 = 0.0635;
/// Nodes around each ring and radial cells, chosen so the free annulus (6.35–12.7 cm) has
/// atelier's JIS grid density (72 around, 7 radial cells of 9.07 mm): 14 radial cells from the
/// centre, the 7th ring on the pedestal's rim.
const AROUND: usize = 72;
const RINGS: usize = 14;

/// A polar disc in the (u, v) plane: node 0 the centre, ring k (1..=RINGS) node j at index
/// 1 + (k−1)·AROUND + j. Triangles counter-clockwise in (u, v); returns also the structural
/// (radial and circumferential) edges with their rest lengths.
fn polar_disc() -> (Vec<[f64; 2]>, Vec<[u32; 3]>, Edges) {
    let dr = DISC_R / RINGS as f64;
    let mut p = vec![[0.0, 0.0]];
    for k in 1..=RINGS {
        for j in 0..AROUND {
            let a = 2.0 * std::f64::consts::PI * j as f64 / AROUND as f64;
            let r = k as f64 * dr;
            p.push([r * a.cos(), r * a.sin()]);
        }
    }
    let idx = |k: usize, j: usize| -> usize {
        if k == 0 {
            0
        } else {
            1 + (k - 1) * AROUND + (j % AROUND)
        }
    };
    let mut t = Vec::new();
    for j in 0..AROUND {
        t.push([0, idx(1, j) as u32, idx(1, j + 1) as u32]);
    }
    for k in 1..RINGS {
        for j in 0..AROUND {
            let (a, b, c, d) = (idx(k, j), idx(k + 1, j), idx(k + 1, j + 1), idx(k, j + 1));
            t.push([a as u32, b as u32, c as u32]);
            t.push([a as u32, c as u32, d as u32]);
        }
    }
    let len = |a: usize, b: usize| ((p[a][0] - p[b][0]).powi(2) + (p[a][1] - p[b][1]).powi(2)).sqrt();
    let mut e = Vec::new();
    for k in 1..=RINGS {
        for j in 0..AROUND {
            let n = idx(k, j);
            let inner = idx(k - 1, j);
            e.push((inner, n, len(inner, n)));
            let next = idx(k, j + 1);
            e.push((n, next, len(n, next)));
        }
    }
    (p, t, e)
}

/// Area of the convex hull of 2-D points (Andrew's monotone chain).
fn convex_hull_area(points: &mut [[f64; 2]]) -> f64 {
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    let n = hull.len();
    (0..n)
        .map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % n]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum::<f64>()
        .abs()
        * 0.5
}

/// DC = (A_shadow − A_pedestal)/(A_disc − A_pedestal), a fraction; A_shadow the convex hull of
/// the nodes projected on the horizontal plane (rapier's x–z).
fn drape_coefficient(positions: &[Vec3]) -> f64 {
    let mut pts: Vec<[f64; 2]> = positions.iter().map(|p| [p.x as f64, p.z as f64]).collect();
    let shadow = convex_hull_area(&mut pts);
    let pi = std::f64::consts::PI;
    let (a_disc, a_ped) = (pi * DISC_R * DISC_R, pi * PEDESTAL_R * PEDESTAL_R);
    (shadow - a_ped) / (a_disc - a_ped)
}

fn drape_row(setting: &Setting) -> Row {
    let (p2, tris, edges) = polar_disc();
    let mut row = Row {
        scene: "drape",
        side: 0,
        nodes: p2.len(),
        setting: setting.label.clone(),
        ..Row::default()
    };
    let material = material(setting);
    // The disc starts flat, one contact radius above the pedestal's top face (y = 0).
    let y0 = material.contact_radius;
    let positions: Vec<Vec3> = p2
        .iter()
        .map(|q| Vec3::new(q[0] as f32, y0, -(q[1] as f32)))
        .collect();
    // (u, v) ↦ (u, y, −v) keeps the triangles' orientation consistent (a proper rotation).
    let mesh = match ClothMesh::new(positions, tris) {
        Ok(m) => m,
        Err(e) => {
            row.note = format!("failed to build the disc mesh: {e}");
            return row;
        }
    };
    // The pedestal: a 128-sided prism (convex hull), radius 6.35 cm, top face at y = 0, 10 cm high
    // (rapier-cloth collides with balls, cuboids, capsules and convex hulls, not cylinders).
    let mut hull = Vec::new();
    for j in 0..128 {
        let a = 2.0 * std::f32::consts::PI * j as f32 / 128.0;
        let (x, z) = (PEDESTAL_R as f32 * a.cos(), PEDESTAL_R as f32 * a.sin());
        hull.push(Vec3::new(x, 0.0, z));
        hull.push(Vec3::new(x, -0.1, z));
    }
    let Some(pedestal) = ColliderBuilder::convex_hull(&hull) else {
        row.note = "failed to build the pedestal's convex hull".into();
        return row;
    };
    match run(mesh, material, &[], setting, vec![pedestal.build()], &edges) {
        Err(e) => row.note = format!("failed: {e}"),
        Ok(o) => {
            fill(&mut row, &o, &edges, setting);
            let centre = o.positions[0];
            // A disc whose centre is no longer on the pedestal has no drape coefficient.
            let on_pedestal = centre.y > -0.01
                && (centre.x as f64).hypot(centre.z as f64) < PEDESTAL_R;
            if o.steps_done == STEPS && all_finite(&o.positions) && on_pedestal {
                row.drape_coefficient = Some(drape_coefficient(&o.positions));
            }
            let lowest = o.positions.iter().map(|p| p.y).fold(f32::MAX, f32::min);
            let _ = write!(
                row.note,
                "; polar disc {AROUND} around x {RINGS} rings + centre, pedestal a 128-gon prism; at the end the centre node is at y = {:.4} m and the lowest node at y = {lowest:.4} m",
                centre.y
            );
            if !on_pedestal {
                row.note.push_str("; the disc slid off the pedestal, so no drape coefficient");
            }
        }
    }
    row
}

// ---------------------------------------------------------------- output

fn json_str(s: &str) -> String {
    let mut o = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => o.push_str("\\\""),
            '\\' => o.push_str("\\\\"),
            '\n' => o.push_str("\\n"),
            c if (c as u32) < 0x20 => {
                let _ = write!(o, "\\u{:04x}", c as u32);
            }
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

fn json_num(x: Option<f64>) -> String {
    match x {
        Some(v) if v.is_finite() => format!("{v}"),
        _ => "null".into(),
    }
}

fn differences() -> Vec<String> {
    [
        "Frame: rapier-cloth is y-up; atelier's sheet (x, y, z up) is mapped to rapier (x, z, -y), a rotation of -90 degrees about x, so node (i, j) has index j*side + i in both and the pins are the two corners of the edge y = 1 m (indices (side-1)*side and side*side-1), as in atelier's peer_scene.",
        "Triangulation: rapier-cloth's GridBuilder splits every cell along the same diagonal (from (i+1, j) to (i, j+1)); atelier's PARTY grid is made of quad cells with both diagonals and a shear cell, not triangles.",
        "Stretch model: rapier-cloth's default material is inextensible (stretch_compliance 0): a hard XPBD distance constraint on every mesh edge including the diagonals, plus long-range tethers to the pins (its 'redundant distance bounds', active only with zero compliance); atelier uses cotton's measured tensile curve (KES), so its stretch is physical, not a solver residual.",
        "The cotton row sets stretch_compliance = 1/500 m/N, i.e. a 500 N/m spring per edge (cotton's 500 N/m per unit width on a square cell, ignoring that the diagonals add stiffness in rapier); this disables the tethers.",
        "Bending: rapier-cloth's default is an XPBD dihedral-angle constraint per interior edge with bend_compliance 1e-4 (not calibrated to a fabric); atelier uses cotton's measured bending (spindle model of the KES B curve).",
        "Mass: surface_density set to cotton's 0.1238 kg/m2 (rapier's default is 0.2), lumped by rapier as a third of each adjacent triangle's area per node (corners of the sheet get 1/6 or 1/3 of a cell depending on the diagonal), 0.1238 kg in all.",
        "Damping: rapier-cloth's default exponential velocity damping of 0.1 1/s is kept; atelier has its own damping model.",
        "Pins: rapier-cloth pins are hard targets (zero-compliance, inverse mass zeroed inside the step) placed at the nodes' rest positions.",
        "Gravity 9.80665 m/s2 along -y; Rapier's world gravity set to the same value.",
        "Precision: rapier-cloth's default f32 build (atelier is f64); stretch is computed here in f64 from the f32 positions.",
        "Threading: rapier-cloth's XPBD solver is single-threaded (rayon is used only by its optional implicit solver, not enabled) and Rapier's 'parallel' feature is off by default, so one thread; atelier's bench runs its step on 2 threads.",
        "What a step includes: per substep a SceneSnapshot, an (empty or one-collider) Rapier PhysicsWorld::step, the query pipeline and RapierClothWorld::step_substep, which clones the cloth set for atomic commit and runs the overlap stabilisation, XPBD iterations and contact queries; the 'defaults, core only' row steps rapier_cloth_core's Solver alone.",
        "Sub-stepping: rapier-cloth's step takes one substep (h <= max_substep 1/30 s); 'substeps=n' calls it n times with h = 0.01/n s per 0.01 s step, as its docs advise (they use h = 1/240 s).",
        "Drape: atelier simulates only the annulus outside the pedestal with its inner ring held (hinged), no contact; here the whole Ø 25.4 cm disc (polar mesh, 72 around x 14 rings + centre, same radial and angular spacing as atelier's JIS 72 x 8 grid) falls onto a static convex 128-gon prism pedestal of Ø 12.7 cm, with rapier's particle contact (contact_radius 5 mm, friction 0.5), starting flat 5 mm above the pedestal top.",
        "Drape coefficient: shadow area taken as the convex hull of the nodes projected on the horizontal plane (overestimates the shadow between folds); atelier takes the union of the projected triangles plus the support disk.",
        "Stretch measure: largest l/l0 - 1 over the structural grid edges (horizontal and vertical neighbours, no diagonals; on the drape the radial and circumferential edges), checked every 10 steps and at 2 s, from positions read back from the cloth; atelier's axial_strains measures the same edges of its grid.",
        "Divergence: a step error (rapier refuses to commit non-finite states), non-finite positions, or stretch above 100 %; a run whose stretch passes 100 % but stays finite is run on to 2 s and its diverged_at_s records when it passed.",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

fn write_json(path: &str, rows: &[Row], quick: bool) -> std::io::Result<()> {
    let mut s = String::new();
    s.push_str("{\n");
    let _ = writeln!(s, "  \"peer\": {},", json_str("rapier-cloth 0.3.0"));
    let _ = writeln!(s, "  \"threads\": 1,");
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0);
    let note = format!(
        "{cores} cores seen by the process; release build (opt-level 3) of rapier-cloth 0.3.0 (f32, rapier3d 0.34, default features); {}; one run, wall time with std::time::Instant around each whole 0.01 s step",
        if quick { "--quick (50 x 50 defaults only)" } else { "full sweep" }
    );
    let _ = writeln!(s, "  \"machine_note\": {},", json_str(&note));
    s.push_str("  \"rows\": [\n");
    for (i, r) in rows.iter().enumerate() {
        let _ = write!(
            s,
            "    {{\"scene\": {}, \"side\": {}, \"nodes\": {}, \"setting\": {}, \"ms_per_step\": {}, \"stretch_end\": {}, \"stretch_max\": {}, \"diverged_at_s\": {}, \"drape_coefficient\": {}, \"note\": {}}}",
            json_str(r.scene),
            if r.side == 0 { "null".to_string() } else { r.side.to_string() },
            r.nodes,
            json_str(&r.setting),
            json_num(r.ms_per_step),
            json_num(r.stretch_end),
            json_num(r.stretch_max),
            json_num(r.diverged_at_s),
            json_num(r.drape_coefficient),
            json_str(&r.note)
        );
        s.push_str(if i + 1 < rows.len() { ",\n" } else { "\n" });
    }
    s.push_str("  ],\n  \"differences\": [\n");
    let d = differences();
    for (i, x) in d.iter().enumerate() {
        let _ = write!(s, "    {}", json_str(x));
        s.push_str(if i + 1 < d.len() { ",\n" } else { "\n" });
    }
    s.push_str("  ]\n}\n");
    if let Some(dir) = std::path::Path::new(path).parent() {
        if !dir.as_os_str().is_empty() {
            std::fs::create_dir_all(dir)?;
        }
    }
    std::fs::write(path, s)
}

fn fmt_opt(x: Option<f64>, scale: f64, digits: usize) -> String {
    x.map_or("-".into(), |v| format!("{:.*}", digits, v * scale))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut out = None;
    let mut quick = false;
    let mut i = 1;
    while i < args.len() {
        match args[i].as_str() {
            "--out" => {
                out = args.get(i + 1).cloned();
                i += 1;
            }
            "--quick" => quick = true,
            a => {
                eprintln!("unknown argument {a}; usage: --out FILE.json [--quick]");
                std::process::exit(2);
            }
        }
        i += 1;
    }
    let Some(out) = out else {
        eprintln!("usage: atelier-peers-rapier --out FILE.json [--quick]");
        std::process::exit(2);
    };
    let defaults = Setting::new("defaults", 1, SolverSettings::default().iterations);
    let mut sweep = vec![defaults.clone()];
    if !quick {
        let it = SolverSettings::default().iterations;
        sweep.push(Setting {
            label: "defaults, core only".into(),
            core_only: true,
            ..defaults.clone()
        });
        sweep.push(Setting::new("substeps=2", 2, it));
        sweep.push(Setting::new("substeps=4", 4, it));
        sweep.push(Setting::new("substeps=8", 8, it));
        sweep.push(Setting::new("iterations=32", 1, 32));
        sweep.push(Setting::new("substeps=4, iterations=32", 4, 32));
        sweep.push(Setting {
            label: "cotton stretch_compliance=0.002".into(),
            stretch_compliance: Some(1.0 / COTTON_TENSILE),
            ..defaults.clone()
        });
        sweep.push(Setting {
            label: "cotton stretch_compliance=0.002, substeps=4".into(),
            stretch_compliance: Some(1.0 / COTTON_TENSILE),
            ..Setting::new("", 4, it)
        });
    }
    let sides: &[usize] = if quick { &[50] } else { &[50, 100] };
    let mut rows = Vec::new();
    for &side in sides {
        for s in &sweep {
            let r = sheet_row(side, s);
            eprintln!(
                "sheet {side}x{side} [{}]: {} ms/step, stretch end {} %, max {} %, diverged at {:?} s; {}",
                r.setting,
                fmt_opt(r.ms_per_step, 1.0, 2),
                fmt_opt(r.stretch_end, 100.0, 1),
                fmt_opt(r.stretch_max, 100.0, 1),
                r.diverged_at_s,
                r.note
            );
            rows.push(r);
        }
    }
    if !quick {
        let it = SolverSettings::default().iterations;
        for s in [
            defaults.clone(),
            Setting::new("substeps=4", 4, it),
            Setting {
                label: "cotton stretch_compliance=0.002".into(),
                stretch_compliance: Some(1.0 / COTTON_TENSILE),
                ..defaults.clone()
            },
        ] {
            let r = drape_row(&s);
            eprintln!(
                "drape [{}]: {} ms/step, DC {}, stretch end {} %, max {} %; {}",
                r.setting,
                fmt_opt(r.ms_per_step, 1.0, 2),
                fmt_opt(r.drape_coefficient, 1.0, 3),
                fmt_opt(r.stretch_end, 100.0, 1),
                fmt_opt(r.stretch_max, 100.0, 1),
                r.note
            );
            rows.push(r);
        }
    }
    if let Err(e) = write_json(&out, &rows, quick) {
        eprintln!("cannot write {out}: {e}");
        std::process::exit(1);
    }
    // Fail only if no case ran at all.
    if rows.iter().all(|r| r.ms_per_step.is_none()) {
        eprintln!("rapier-cloth did not run any case");
        std::process::exit(1);
    }
}
