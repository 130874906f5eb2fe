"""A notebook-style walk-through of atelier's Python bindings (docs/python.md): a fabric from
its KES values, its loops plotted, its drape on the JIS tester beside a fabric read from its
file, and a garment stepped from Python.

    pip install ./crates/python matplotlib
    python crates/python/examples/walkthrough.py [--out DIR]

Writes loops.png and drape.png into DIR (default docs/img/python, where docs/python.md shows
them). Each `# %%` block is one notebook cell; the printed lines are what the cells show. It
takes about a minute (the two drapes).
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import atelier  # noqa: E402

REPO = Path(__file__).resolve().parents[3]
parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("--out", type=Path, default=REPO / "docs" / "img" / "python")
out = parser.parse_args().out
out.mkdir(parents=True, exist_ok=True)

# %% A fabric from KES values (KES units, the keys of a fabric file's fields): Matsudaira et
# al.'s cotton broad (fabric A: W, T, B and 2HB measured; tensile and shear banded guesses, as
# fixtures/fabrics/cotton_broad.ron says).
cotton = atelier.Fabric.from_kes(
    "cotton broad (Matsudaira A)",
    mass_per_area_mg_cm2=12.38,
    thickness_mm=0.497,
    friction=0.6,
    tensile={
        "warp": {"lt": 0.72, "emt_percent": 3.0, "rt_percent": 48.0},
        "weft": {"lt": 0.68, "emt_percent": 6.0, "rt_percent": 45.0},
    },
    shear={"g_gf_cm_deg": 1.5, "two_hg_gf_cm": 2.5, "two_hg5_gf_cm": 4.5},
    bending={
        "warp": {"b_gf_cm2_cm": 0.118, "two_hb_gf_cm_cm": 0.124},
        "weft": {"b_gf_cm2_cm": 0.118, "two_hb_gf_cm_cm": 0.124},
    },
    provenance={
        "source": "Matsudaira et al. 2015, fabric A (W, T, B, 2HB); tensile and shear banded",
        "measured": ["MassPerArea", "Thickness", "BendingRigidity", "BendingHysteresis"],
        "banded": ["Tensile", "Shear", "Friction"],
    },
)
# And one read from its file: silk habutae (every value a banded guess).
silk = atelier.Fabric.load(REPO / "fixtures" / "fabrics" / "silk.ron")
print(cotton)
print(silk)

# %% Their loops, sampled through one KES cycle (numpy arrays, SI: strain and N/m, 1/m and
# N·m/m, rad and N/m), plotted in the units a KES report uses.
GF_CM = 0.980665  # N/m per gf/cm
fabrics = [("cotton", cotton, "tab:blue"), ("silk", silk, "tab:red")]
fig, axes = plt.subplots(2, 3, figsize=(13.5, 7.6), constrained_layout=True)
for row, (label, fabric, colour) in zip(axes, fabrics):
    for direction, style in [("warp", "-"), ("weft", "--")]:
        t = fabric.tensile_loop(direction)  # columns: strain, N/m
        row[0].plot(100 * t[:, 0], t[:, 1] / GF_CM, style, color=colour, label=direction)
        b = fabric.bending_loop(direction)  # columns: 1/m, N·m/m
        same = direction == "weft" and np.array_equal(b, fabric.bending_loop("warp"))
        if not same:
            row[1].plot(b[:, 0] / 100, b[:, 1] / 9.80665e-3, style, color=colour, label=direction)
        else:
            row[1].lines[-1].set_label("warp = weft")
    s = fabric.shear_loop()  # columns: rad, N/m
    row[2].plot(np.degrees(s[:, 0]), s[:, 1] / GF_CM, color=colour, label="KES-FB1 cycle")
    row[0].set(xlabel="strain (%)", ylabel="force per width (gf/cm)", title=f"{label}: tensile, 0 → 500 gf/cm → 0")
    row[1].set(
        xlabel="curvature (1/cm)",
        ylabel="moment per width (gf·cm/cm)",
        title=f"{label}: bending, 0 → 2.5 → −2.5 → 0 1/cm",
    )
    row[2].set(xlabel="shear angle (°)", ylabel="shear force per width (gf/cm)", title=f"{label}: shear, 0 → 8° → −8° → 8°")
    for ax in row:
        ax.grid(alpha=0.3)
        ax.axhline(0, color="0.6", lw=0.6)
        ax.axvline(0, color="0.6", lw=0.6)
        ax.legend(fontsize=8, loc="upper left")
fig.suptitle("The fabrics' own loops (atelier.Fabric.tensile_loop, bending_loop, shear_loop): cotton broad from KES values, silk from its file")
fig.savefig(out / "loops.png", dpi=110)
print(f"wrote {out / 'loops.png'}")

# %% The JIS drape test of each (Ø 25.4 cm on a Ø 12.7 cm support), as the scenario kind
# Drape(fabric: …, tester: Jis) runs it: the drape coefficient, the folds, the outline from
# above.
drapes = {label: atelier.drape(fabric, tester="jis") for label, fabric, _ in fabrics}
colours = {label: colour for label, _, colour in fabrics}
for label, d in drapes.items():
    print(
        f"{label}: DC {d['drape_coefficient_percent']:.1f} %, {d['node_count']} nodes, "
        f"{'at rest' if d['settled'] else 'not at rest'} after {d['simulated_s']:.2f} s "
        f"({d['steps']} steps, {d['wall_s']:.1f} s)"
    )

fig, axes = plt.subplots(1, 2, figsize=(10, 5.6), constrained_layout=True)
theta = np.linspace(0, 2 * np.pi, 200)
for ax, (label, d) in zip(axes, drapes.items()):
    r_support, r_specimen = d["support_radius_m"], d["specimen_radius_m"]
    ax.fill(100 * r_specimen * np.cos(theta), 100 * r_specimen * np.sin(theta), color="0.93", label="flat specimen")
    ring = np.vstack([d["outline"], d["outline"][:1]])  # close the outline
    ax.fill(100 * ring[:, 0], 100 * ring[:, 1], color=colours[label], alpha=0.35)
    ax.plot(100 * ring[:, 0], 100 * ring[:, 1], color=colours[label], lw=1.5, label="outline (from above)")
    ax.fill(100 * r_support * np.cos(theta), 100 * r_support * np.sin(theta), color="0.45", label="support")
    nodes = d["node_points"]
    ax.plot(100 * nodes[:, 0], 100 * nodes[:, 1], "o", color="k", ms=5, label=f"{d['node_count']} nodes")
    ax.set(
        aspect="equal",
        xlabel="x (cm)",
        ylabel="z (cm)",
        title=f"{label}: DC {d['drape_coefficient_percent']:.1f} %, {d['node_count']} nodes",
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=4)
fig.suptitle("JIS drape test (atelier.drape): the specimen's outer edge seen from above, its counted nodes")
fig.savefig(out / "drape.png", dpi=110)
print(f"wrote {out / 'drape.png'}")

# %% A garment stepped from Python: the skirt sewn round the mannequin, a few steps at a time.
sim = atelier.Simulation(REPO / "fixtures" / "scenarios" / "skirt_sewn.ron")
while sim.phase == "Sewing":
    sim.step()
r = sim.report()
print(
    f"{sim.name}: sewn {r['sewing']['pairs_sewn']}/{r['sewing']['pairs']} pairs at "
    f"{r['sewing']['sewn_at_s']:.2f} s; {len(sim.positions)} nodes, lowest at "
    f"{r['metrics']['lowest_node_m']:.3f} m"
)
