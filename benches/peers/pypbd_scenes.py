#!/usr/bin/env python3
"""Issue 10's peer benchmark, PositionBasedDynamics side (its Python package pypbd 2.2.2).

atelier's `peer_scene` (a 1 m square sheet of side x side nodes pinned at the two corners of one
edge, falling for 2 s at dt 0.01 s) and the JIS drape (a 25.4 cm cotton disc on a 12.7 cm
pedestal), run with pypbd's defaults and then with a sweep of its accuracy knobs.

    python pypbd_scenes.py --out FILE.json [--quick]

Each case runs in its own child process (pypbd keeps one global Simulation and TimeManager), so
cases cannot leak state into each other and a crash in one is a recorded row, not a lost run.
Everything is measured: wall time per step with time.perf_counter around the whole step, stretch
from the node positions read back from pypbd. Nothing is copied from the issue.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

PEER = "pypbd 2.2.2"
G_ATELIER = 9.80665  # atelier's gravity; pypbd's is fixed at 9.81 (see differences)
COTTON_DENSITY = 0.1238  # kg/m^2 (12.38 mg/cm^2)
COTTON_TENSILE = 500.0  # N/m per unit width (EMT 3 % at 500 gf/cm)
DT = 0.01
STEPS = 200
DIVERGED_STRETCH = 1.0
DISC_R, PEDESTAL_R = 0.127, 0.0635
AROUND, RINGS = 72, 14  # atelier's JIS grid density in the free annulus, see the Rust runner
PEDESTAL_HEIGHT = 0.1

# atelier (x, y, z up) -> pypbd (x, z, -y): a proper rotation of -90 degrees about x.
R_ATELIER_TO_PBD = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


# ------------------------------------------------------------------ geometry and measures

def sheet_edges(side):
    """Structural edges (grid neighbours, no diagonals) of node index j*side + i."""
    idx = np.arange(side * side).reshape(side, side)  # [j, i]
    h = np.stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()], axis=1)
    v = np.stack([idx[:-1, :].ravel(), idx[1:, :].ravel()], axis=1)
    e = np.concatenate([h, v])
    return e, np.full(len(e), 1.0 / (side - 1))


def max_stretch(x, edges, rest):
    d = x[edges[:, 0]] - x[edges[:, 1]]
    l = np.sqrt((d * d).sum(axis=1))
    if not np.all(np.isfinite(l)):
        return float("nan")
    return float((l / rest - 1.0).max())


def polar_disc():
    """Centre node 0, ring k (1..RINGS) node j at 1 + (k-1)*AROUND + j; (u, v) plane; triangles
    counter-clockwise; structural (radial, circumferential) edges with rest lengths."""
    dr = DISC_R / RINGS
    pts = [(0.0, 0.0)]
    for k in range(1, RINGS + 1):
        for j in range(AROUND):
            a = 2.0 * math.pi * j / AROUND
            pts.append((k * dr * math.cos(a), k * dr * math.sin(a)))
    pts = np.array(pts)

    def idx(k, j):
        return 0 if k == 0 else 1 + (k - 1) * AROUND + (j % AROUND)

    tris = [(0, idx(1, j), idx(1, j + 1)) for j in range(AROUND)]
    for k in range(1, RINGS):
        for j in range(AROUND):
            a, b, c, d = idx(k, j), idx(k + 1, j), idx(k + 1, j + 1), idx(k, j + 1)
            tris += [(a, b, c), (a, c, d)]
    edges = []
    for k in range(1, RINGS + 1):
        for j in range(AROUND):
            edges.append((idx(k - 1, j), idx(k, j)))
            edges.append((idx(k, j), idx(k, j + 1)))
    edges = np.array(edges)
    d = pts[edges[:, 0]] - pts[edges[:, 1]]
    return pts, np.array(tris), edges, np.sqrt((d * d).sum(axis=1))


def lumped_masses(points3, tris, total):
    """A third of each adjacent triangle's area per node, scaled to `total` kg."""
    a, b, c = points3[tris[:, 0]], points3[tris[:, 1]], points3[tris[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    m = np.zeros(len(points3))
    for k in range(3):
        np.add.at(m, tris[:, k], area / 3.0)
    return m * (total / m.sum())


def convex_hull_area(p):
    """Andrew's monotone chain on 2-D points; the hull's area."""
    pts = sorted(map(tuple, p))
    if len(pts) < 3:
        return 0.0

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for q in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], q) <= 0:
            lower.pop()
        lower.append(q)
    for q in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], q) <= 0:
            upper.pop()
        upper.append(q)
    hull = np.array(lower[:-1] + upper[:-1])
    x, y = hull[:, 0], hull[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def drape_coefficient(x):
    shadow = convex_hull_area(x[:, [0, 2]])  # horizontal plane of the y-up frame
    a_disc, a_ped = math.pi * DISC_R ** 2, math.pi * PEDESTAL_R ** 2
    return (shadow - a_ped) / (a_disc - a_ped)


def omp_max_threads():
    """omp_get_max_threads() of the libgomp bundled with pypbd (None if it cannot be found)."""
    try:
        import ctypes
        import glob
        import pypbd
        libs = glob.glob(os.path.join(os.path.dirname(pypbd.__file__), "pypbd.libs", "libgomp*"))
        if not libs:
            return None
        return int(ctypes.CDLL(libs[0]).omp_get_max_threads())
    except Exception:
        return None


def os_threads():
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("Threads:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


# ------------------------------------------------------------------ one case (child process)

def run_case(case):
    import pypbd as pbd

    sim = pbd.Simulation.getCurrent()
    sim.initDefault()  # new SimulationModel + CubicSDFCollisionDetection, as pypbd's demos do
    model = sim.getModel()
    ts = sim.getTimeStep()
    tsc = pbd.TimeStepController
    defaults = {
        "num_sub_steps": ts.getValueUInt(tsc.NUM_SUB_STEPS),
        "max_iterations": ts.getValueUInt(tsc.MAX_ITERATIONS),
        "max_iterations_v": ts.getValueUInt(tsc.MAX_ITERATIONS_V),
        "velocity_update_method": ts.getValueInt(tsc.VELOCITY_UPDATE_METHOD),
        # SimulationModel's cloth parameters, in the order its initParameters creates them:
        # cloth simulation method, bending method, stiffness, xx, yy, xy Young's moduli,
        # xy and yx Poisson ratios, bending stiffness, normalize stretch, normalize shear.
        "cloth_method": model.getValueInt(0),
        "bending_method": model.getValueInt(1),
        "cloth_stiffness": model.getValueFloat(2),
        "cloth_xx": model.getValueFloat(3),
        "cloth_yy": model.getValueFloat(4),
        "cloth_xy": model.getValueFloat(5),
        "poisson_xy": model.getValueFloat(6),
        "poisson_yx": model.getValueFloat(7),
        "bending_stiffness": model.getValueFloat(8),
        "normalize_stretch": model.getValueBool(9),
        "normalize_shear": model.getValueBool(10),
        "collision_tolerance": ts.getCollisionDetection().getTolerance(),
        "default_dt": pbd.TimeManager.getCurrent().getTimeStepSize(),
    }
    p = dict(defaults)
    p.update(case.get("params", {}))

    pd = model.getParticles()
    scene = case["scene"]
    if scene == "sheet":
        side = case["side"]
        tm = model.addRegularTriangleModel(side, side, [0.0, 0.0, 0.0], R_ATELIER_TO_PBD, [1.0, 1.0])
        edges, rest = sheet_edges(side)
        pins = [(side - 1) * side, side * side - 1]
        total = COTTON_DENSITY * 1.0
    else:
        pts2, tris, edges, rest = polar_disc()
        y0 = p["collision_tolerance"]  # flat, one collision tolerance above the pedestal top
        pts3 = [np.array([u, y0, -v]) for u, v in pts2]
        tm = model.addTriangleModel(pts3, [int(i) for i in tris.ravel()], testMesh=True)
        pins = []
        total = COTTON_DENSITY * math.pi * DISC_R ** 2
    n = pd.size()
    mesh = tm.getParticleMesh()
    faces = np.array(list(mesh.getFaces()), dtype=np.int64).reshape(-1, 3)
    x0 = np.array(pd.getVertices())
    masses = lumped_masses(x0, faces, total)
    for i in range(n):
        pd.setMass(i, float(masses[i]))
    for i in pins:
        pd.setMass(i, 0.0)

    model.addClothConstraints(
        tm, int(p["cloth_method"]), float(p["cloth_stiffness"]), float(p["cloth_xx"]),
        float(p["cloth_yy"]), float(p["cloth_xy"]), float(p["poisson_xy"]),
        float(p["poisson_yx"]), bool(p["normalize_stretch"]), bool(p["normalize_shear"]))
    model.addBendingConstraints(tm, int(p["bending_method"]), float(p["bending_stiffness"]))

    if scene == "drape":
        cd = ts.getCollisionDetection()
        # Static pedestal: a rigid body (mass 0) with a 64-sided prism mesh for its bounding
        # volume and pypbd's analytic cylinder distance field (axis along y) for the contact.
        vd = pbd.VertexData()
        rb_mesh = pbd.IndexedFaceMesh()
        sides = 64
        hh = 0.5 * PEDESTAL_HEIGHT
        for y in (-hh, hh):
            for j in range(sides):
                a = 2.0 * math.pi * j / sides
                vd.addVertex(np.array([PEDESTAL_R * math.cos(a), y, PEDESTAL_R * math.sin(a)]))
        vd.addVertex(np.array([0.0, -hh, 0.0]))
        vd.addVertex(np.array([0.0, hh, 0.0]))
        nv = vd.size()
        faces_rb = []
        for j in range(sides):
            k = (j + 1) % sides
            faces_rb += [(j, k, sides + k), (j, sides + k, sides + j)]
            faces_rb += [(nv - 2, k, j), (nv - 1, sides + j, sides + k)]
        rb_mesh.initMesh(nv, len(faces_rb), 3)
        for f in faces_rb:
            rb_mesh.addFace(list(f))
        rb_mesh.buildNeighbors()
        rb = model.addRigidBody(1.0, vd, rb_mesh, [0.0, -hh, 0.0], np.eye(3), [1.0, 1.0, 1.0],
                                False, None)
        rb.setMass(0.0)
        rb_index = len(model.getRigidBodies()) - 1
        geo = rb.getGeometry().getVertexData()
        cd.addCollisionCylinder(rb_index, pbd.CollisionObject.RigidBodyCollisionObjectType, geo,
                                0, geo.size(), np.array([PEDESTAL_R, PEDESTAL_HEIGHT]), True,
                                False)
        # (addTriangleModel(..., testMesh=True) has already registered the cloth's particles as
        # a collision object; do not call CollisionDetection.getCollisionObjects from Python:
        # the returned list takes ownership of the C++ objects and frees them.)
        if "collision_tolerance" in case.get("params", {}):
            cd.setTolerance(float(p["collision_tolerance"]))

    ts.setValueUInt(tsc.NUM_SUB_STEPS, int(p["num_sub_steps"]))
    ts.setValueUInt(tsc.MAX_ITERATIONS, int(p["max_iterations"]))
    ts.setValueUInt(tsc.MAX_ITERATIONS_V, int(p["max_iterations_v"]))
    pbd.TimeManager.getCurrent().setTimeStepSize(DT)

    wall, done = 0.0, 0
    worst, diverged_at, stopped = -math.inf, None, None
    threads = None
    for k in range(1, STEPS + 1):
        t0 = time.perf_counter()
        ts.step(model)
        wall += time.perf_counter() - t0
        done = k
        if k == 1:
            threads = os_threads()
        if k % 10 == 0:
            x = np.array(pd.getVertices())
            s = max_stretch(x, edges, rest)
            if not np.all(np.isfinite(x)) or not math.isfinite(s):
                diverged_at = diverged_at if diverged_at is not None else k * DT
                stopped = f"non-finite positions at step {k}"
                break
            worst = max(worst, s)
            if s > DIVERGED_STRETCH and diverged_at is None:
                diverged_at = k * DT
    x = np.array(pd.getVertices())
    end = max_stretch(x, edges, rest) if done == STEPS else float("nan")
    out = {
        "ms_per_step": 1e3 * wall / max(done, 1),
        "stretch_end": end if math.isfinite(end) else None,
        "stretch_max": worst if math.isfinite(worst) else None,
        "diverged_at_s": diverged_at,
        "drape_coefficient": None,
        "threads": threads,
        "omp_max_threads": omp_max_threads(),
        "omp_env": os.environ.get("OMP_NUM_THREADS", "unset"),
        "params": p,
        "stopped": stopped,
        "sim_time": pbd.TimeManager.getCurrent().getTime(),
    }
    if scene == "drape" and done == STEPS and np.all(np.isfinite(x)):
        out["lowest_y"] = float(x[:, 1].min())
        out["centre_y"] = float(x[0, 1])
        # A disc whose centre is no longer on the pedestal has no drape coefficient.
        if x[0, 1] > -0.01 and math.hypot(x[0, 0], x[0, 2]) < PEDESTAL_R:
            out["drape_coefficient"] = drape_coefficient(x)
    return out


# ------------------------------------------------------------------ the sweep (parent process)

CLOTH_METHODS = {1: "distance constraints (PBD)", 2: "FEM triangles (PBD)",
                 3: "strain triangles (PBD)", 4: "distance constraints (XPBD)"}
BENDING_METHODS = {1: "dihedral angle (PBD)", 2: "isometric bending (PBD)",
                   3: "isometric bending (XPBD)"}


def sweep(quick):
    cases = [("defaults", {})]
    if not quick:
        cases += [
            ("substeps=1", {"num_sub_steps": 1}),
            ("substeps=10", {"num_sub_steps": 10}),
            ("substeps=20", {"num_sub_steps": 20}),
            ("iterations=5", {"max_iterations": 5}),
            ("substeps=20, iterations=5", {"num_sub_steps": 20, "max_iterations": 5}),
            ("distance constraints (PBD, stiffness 1)", {"cloth_method": 1}),
            ("cotton: XPBD distance, stiffness 500 N/m",
             {"cloth_method": 4, "cloth_stiffness": COTTON_TENSILE}),
        ]
    return cases


def describe(p):
    return (f"{p['num_sub_steps']} substep(s) of {DT / p['num_sub_steps']:g} s, "
            f"{p['max_iterations']} position iteration(s) and {p['max_iterations_v']} velocity "
            f"iteration(s) per substep; cloth: {CLOTH_METHODS.get(p['cloth_method'], p['cloth_method'])}"
            f", stiffness {p['cloth_stiffness']:g}, Young's moduli xx/yy/xy {p['cloth_xx']:g}/"
            f"{p['cloth_yy']:g}/{p['cloth_xy']:g}, Poisson {p['poisson_xy']:g}/{p['poisson_yx']:g}; "
            f"bending: {BENDING_METHODS.get(p['bending_method'], p['bending_method'])}, "
            f"stiffness {p['bending_stiffness']:g}")


def differences():
    return [
        "Frame: pypbd is y-up with gravity along -y; atelier's sheet (x, y, z up) is mapped to pypbd (x, z, -y), a rotation of -90 degrees about x, so node (i, j) has index j*side + i in both and the pins are the two corners of the edge y = 1 m (indices (side-1)*side and side*side-1), as in atelier's peer_scene.",
        "Gravity: pypbd's Simulation gravitation is 9.81 m/s2 and its Python binding has no setter for vector parameters, so the peer runs at 9.81 instead of atelier's 9.80665 (0.03 % more weight).",
        "Triangulation: pypbd's addRegularTriangleModel alternates the diagonal from cell to cell (a criss-cross 'union jack' pattern); atelier's PARTY grid is made of quad cells with both diagonals and a shear cell, not triangles.",
        "Stretch model (defaults): PBD FEM triangle constraints (Bender et al.) with pypbd's default parameters (stiffness 1, orthotropic Young's moduli 1/1/1, Poisson 0.3/0.3); in plain PBD the moduli only set ratios, so the material's stiffness is whatever the iteration count and substeps make of it, not a fabric's; atelier uses cotton's measured tensile curve (KES).",
        "The cotton row uses pypbd's XPBD distance constraints on every mesh edge (diagonals included) with stiffness 500 N/m (compliance 1/500 m/N), i.e. cotton's 500 N/m per unit width on a square cell, ignoring the diagonals' extra stiffness.",
        "Bending: pypbd's default isometric bending (Bergou et al., PBD) with stiffness 0.01 (dimensionless in PBD); atelier uses cotton's measured bending (spindle model of the KES B curve).",
        "Mass: pypbd gives every particle 1 kg; here each node gets a third of its adjacent triangles' area times 0.1238 kg/m2 (0.1238 kg in all for the sheet), the same lumping as rapier-cloth, and the two pins mass 0 (pypbd's way of fixing a particle).",
        "Damping: pypbd has no velocity damping for particles; atelier has its own damping model.",
        "Time stepping: TimeStepController with pypbd's defaults (5 substeps per step, 1 position iteration and 5 velocity iterations per substep, first-order velocity update) and the scene's dt = 0.01 s (pypbd's own default step is 0.005 s).",
        "Threading: pypbd is built with OpenMP (bundled libgomp) and parallelises constraint groups and particle loops; with OMP_NUM_THREADS unset it uses one thread per core (2 here); the sweep rows here run with OMP_NUM_THREADS=1 (like rapier-cloth's single thread) and one 'OpenMP default' row per size shows pypbd's own threading; atelier's bench runs its step on 2 threads.",
        "What a step includes: TimeStepController.step: integration, position projection over constraint groups, velocity update, collision detection (CubicSDFCollisionDetection, idle on the sheet: no collision objects) and the velocity solver, for all substeps; the timing wraps the Python call.",
        "Precision: pypbd is built in double precision (Real = double), as atelier.",
        "Drape: atelier simulates only the annulus outside the pedestal with its inner ring held (hinged), no contact; here the whole disc (polar mesh, 72 around x 14 rings + centre, the same spacing as atelier's JIS 72 x 8 grid) falls on a static rigid body (mass 0) whose contact is pypbd's analytic cylinder distance field (radius 6.35 cm, axis vertical, top at y = 0), with pypbd's particle-rigid-body contacts (collision tolerance 0.01 m, the default; friction coefficient the sum of the cloth's 0.2 and the body's default), starting flat one tolerance above the pedestal top.",
        "Drape coefficient: shadow area taken as the convex hull of the nodes projected on the horizontal plane (overestimates the shadow between folds); atelier takes the union of the projected triangles plus the support disk.",
        "Stretch measure: largest l/l0 - 1 over the structural grid edges (horizontal and vertical neighbours, no diagonals; on the drape the radial and circumferential edges), checked every 10 steps and at 2 s from positions read back with ParticleData.getVertices; atelier's axial_strains measures the same edges of its grid.",
        "Divergence: non-finite positions, or stretch above 100 %; a run whose stretch passes 100 % but stays finite is run on to 2 s and its diverged_at_s records when it passed.",
    ]


def run_child(case, omp_threads):
    """Runs one case in a child; `omp_threads` None leaves OMP_NUM_THREADS as inherited (pypbd's
    default: one OpenMP thread per core), else sets it."""
    cmd = [sys.executable, os.path.abspath(__file__), "--case", json.dumps(case)]
    env = dict(os.environ)
    if omp_threads is not None:
        env["OMP_NUM_THREADS"] = str(omp_threads)
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if r.returncode != 0:
        tail = (r.stderr or r.stdout).strip().splitlines()[-3:]
        return None, f"child exited with {r.returncode}: {' | '.join(tail)}"
    for line in reversed(r.stdout.strip().splitlines()):
        if line.startswith("{"):
            return json.loads(line), None
    return None, "child printed no result"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--case")
    a = ap.parse_args()
    if a.case:
        print(json.dumps(run_case(json.loads(a.case))))
        return 0
    if not a.out:
        ap.error("--out FILE.json is required")
    rows, threads = [], set()
    sides = [50] if a.quick else [50, 100]
    for side in sides:
        # The sweep runs on one OpenMP thread (see the README: on this 2-core machine under
        # load, pypbd's default two-thread OpenMP barriers cost more than they save), then the
        # defaults once more with pypbd's own threading.
        for label, params in sweep(a.quick):
            rows.append(one_row("sheet", side, label, params, threads))
        rows.append(one_row("sheet", side, "defaults", {}, threads, omp_threads=None))
    if not a.quick:
        for label, params in [
                ("defaults", {}),
                ("substeps=20", {"num_sub_steps": 20}),
                ("substeps=20, iterations=5", {"num_sub_steps": 20, "max_iterations": 5}),
                ("cotton: XPBD distance, stiffness 500 N/m",
                 {"cloth_method": 4, "cloth_stiffness": COTTON_TENSILE}),
        ]:
            rows.append(one_row("drape", None, label, params, threads))
    import pypbd  # noqa: F401  (only to fail early and clearly if the package is missing)

    doc = {
        "peer": PEER,
        # The sweep's thread count; the rows labelled 'OpenMP default' say theirs in the note.
        "threads": max(threads) if threads else None,
        "machine_note": (
            f"{os.cpu_count()} cores seen by the process; OMP_NUM_THREADS="
            f"{os.environ.get('OMP_NUM_THREADS', 'unset')} in the parent; the sweep rows run with OMP_NUM_THREADS=1, the rows labelled 'OpenMP default' with the parent's setting; pypbd 2.2.2 manylinux wheel from PyPI, "
            f"Python {sys.version.split()[0]}; {'--quick (50 x 50 defaults only)' if a.quick else 'full sweep'}; "
            "one run, each case in a fresh child process, wall time with time.perf_counter around each whole 0.01 s step"),
        "rows": rows,
        "differences": differences(),
    }
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    with open(a.out, "w") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")
    if all(r["ms_per_step"] is None for r in rows):
        print("pypbd did not run any case", file=sys.stderr)
        return 1
    return 0


def one_row(scene, side, label, params, threads, omp_threads=1):
    case = {"scene": scene, "side": side, "params": params}
    res, err = run_child(case, omp_threads)
    if omp_threads is None:
        label += f", OpenMP default ({os.environ.get('OMP_NUM_THREADS', 'OMP_NUM_THREADS unset')})"
    nodes = side * side if side else 1 + AROUND * RINGS
    row = {"scene": scene, "side": side, "nodes": nodes, "setting": label, "ms_per_step": None,
           "stretch_end": None, "stretch_max": None, "diverged_at_s": None,
           "drape_coefficient": None, "note": ""}
    if res is None:
        row["note"] = f"failed: {err}"
    else:
        for k in ("ms_per_step", "stretch_end", "stretch_max", "diverged_at_s", "drape_coefficient"):
            row[k] = res[k]
        if res.get("threads") and omp_threads is not None:
            threads.add(res["omp_max_threads"])
        note = (describe(res["params"]) + f"; OpenMP max threads {res.get('omp_max_threads')}"
                f" (OMP_NUM_THREADS={res.get('omp_env')}), {res.get('threads')} OS threads in the"
                " process after the first step")
        if scene == "drape":
            note += (f"; polar disc {AROUND} around x {RINGS} rings + centre on an analytic cylinder;"
                     f" at 2 s the centre node is at y = {res.get('centre_y', float('nan')):.4f} m"
                     f" and the lowest node at y = {res.get('lowest_y', float('nan')):.4f} m")
            if res["drape_coefficient"] is None and res.get("centre_y") is not None:
                note += "; the disc slid off the pedestal, so no drape coefficient"
        if res.get("stopped"):
            note += f"; stopped: {res['stopped']}"
        elif res["diverged_at_s"] is not None:
            note += "; stretch passed 100 % but the run went on to 2 s"
        row["note"] = note
    pct = lambda v: "-" if v is None else f"{100 * v:.1f} %"
    ms = "-" if row["ms_per_step"] is None else f"{row['ms_per_step']:.2f}"
    dc = "" if row["drape_coefficient"] is None else f", DC {row['drape_coefficient']:.3f}"
    print(f"{scene} {side or ''} [{label}]: {ms} ms/step, stretch end {pct(row['stretch_end'])}, "
          f"max {pct(row['stretch_max'])}, diverged at {row['diverged_at_s']}{dc}; {row['note']}",
          file=sys.stderr)
    return row


if __name__ == "__main__":
    sys.exit(main())
