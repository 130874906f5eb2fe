"""atelier.Fabric: from_kes against load, the loops against the atelier program's virtual KES
tests and the fabric files' own values, and bad input."""

import math
import re

import numpy as np
import pytest

import atelier
from conftest import FABRICS, REPO

GF_CM = 0.980665  # 1 gf/cm in N/m
# The fixtures' values as their files give them (fixtures/fabrics/silk.ron, cotton_broad.ron).
SILK = dict(
    name="silk habutae (banded, not measured)",
    mass_per_area_mg_cm2=5.0,
    thickness_mm=0.15,
    friction=0.3,
    tensile={
        "warp": {"lt": 0.65, "emt_percent": 8.0, "rt_percent": 60.0},
        "weft": {"lt": 0.62, "emt_percent": 10.0, "rt_percent": 58.0},
    },
    shear={"g_gf_cm_deg": 0.4, "two_hg_gf_cm": 0.4, "two_hg5_gf_cm": 0.8},
    bending={
        "warp": {"b_gf_cm2_cm": 0.02, "two_hb_gf_cm_cm": 0.012},
        "weft": {"b_gf_cm2_cm": 0.015, "two_hb_gf_cm_cm": 0.01},
    },
)
COTTON = dict(
    name="cotton broad, plain (Matsudaira A)",
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
)


def from_kes(values):
    v = dict(values)
    name = v.pop("name")
    return atelier.Fabric.from_kes(name, v.pop("mass_per_area_mg_cm2"), v.pop("thickness_mm"), **v)


def test_version_is_the_crates():
    cargo = (REPO / "Cargo.toml").read_text()
    version = re.search(r'\[workspace\.package\][^\[]*?version = "([^"]+)"', cargo).group(1)
    assert atelier.__version__ == version


@pytest.mark.parametrize("values,file", [(SILK, "silk.ron"), (COTTON, "cotton_broad.ron")])
def test_from_kes_with_a_files_values_gives_its_loops(values, file):
    given, loaded = from_kes(values), atelier.Fabric.load(str(FABRICS / file))
    assert given.name == loaded.name
    assert given == loaded  # every loop, mass, thickness and friction
    for d in ("warp", "weft"):
        assert np.array_equal(given.tensile_loop(d), loaded.tensile_loop(d))
        assert np.array_equal(given.bending_loop(d), loaded.bending_loop(d))
    assert np.array_equal(given.shear_loop(), loaded.shear_loop())
    assert given.kes() == loaded.kes()
    assert "Fabric" in repr(given) and values["name"] in repr(given)


def test_a_measured_loop_from_a_dict_is_the_files(tmp_path):
    """`{"loading": …, "unloading": …}` is the file's `Measured(…)` (and `{"Kes": …}` is
    accepted as written)."""
    loading = [(0.0, 0.0), (20.0, 0.5), (50.0, 0.9), (100.0, 1.4), (200.0, 2.1), (500.0, 3.5)]
    unloading = [(0.0, 1.7), (20.0, 2.3), (50.0, 2.6), (100.0, 2.9), (200.0, 3.2), (500.0, 3.5)]
    text = (FABRICS / "silk.ron").read_text().replace(
        "warp: Kes(lt: 0.65, emt_percent: 8.0, rt_percent: 60.0)",
        f"warp: Measured(loading: {loading}, unloading: {unloading})",
    )
    assert "Measured" in text
    (tmp_path / "measured.ron").write_text(text)
    values = dict(SILK)
    values["tensile"] = {
        "warp": {"loading": loading, "unloading": np.array(unloading)},  # numpy works too
        "weft": {"Kes": SILK["tensile"]["weft"]},
    }
    assert from_kes(values) == atelier.Fabric.load(str(tmp_path / "measured.ron"))


def test_loops_columns_and_units():
    cotton = atelier.Fabric.load(str(FABRICS / "cotton_broad.ron"))
    t = cotton.tensile_loop("warp")
    assert t.shape == (201, 2) and t.dtype == np.float64
    assert np.array_equal(t[0], [0.0, 0.0])
    # Column 1 is N/m: the KES F_m of 500 gf/cm at the turn; column 0 the strain (EMT 3 %).
    assert t[100, 1] == pytest.approx(500 * GF_CM, rel=1e-12)
    assert t[100, 0] == pytest.approx(0.03, rel=1e-9)
    assert t[-1, 1] == 0.0 and 0 < t[-1, 0] < 0.03  # the residual strain after unloading
    b = cotton.bending_loop("weft")
    assert b.shape == (201, 2)
    # Column 0 is 1/m: ±2.5 cm⁻¹ = ±250 m⁻¹; column 1 N·m/m: B = 0.118 gf·cm²/cm on the branch.
    assert b[:, 0].max() == pytest.approx(250.0) and b[:, 0].min() == pytest.approx(-250.0)
    s = cotton.shear_loop()
    assert s.shape == (401, 2)
    assert s[:, 0].max() == pytest.approx(math.radians(8.0))  # rad


def kes_tensile_values(loop):
    """EMT, LT, WT (J/m²) and RT of a loop 0 → F_m → 0 sampled at equal force steps, as KES-FB1
    defines them (the work under the loading branch, the work recovered while unloading)."""
    n = (len(loop) - 1) // 2
    up, down = loop[: n + 1], loop[n:]
    fm, emt = up[-1, 1], up[-1, 0]
    wt = np.sum(0.5 * (up[1:, 1] + up[:-1, 1]) * np.diff(up[:, 0]))
    recovered = np.sum(0.5 * (down[1:, 1] + down[:-1, 1]) * -np.diff(down[:, 0]))
    return emt, wt / (0.5 * fm * emt), wt, recovered / wt


def test_tensile_loop_matches_the_programs_kes_tensile_test(cli):
    """The warp loop of cotton broad gives the fabric's own EMT, LT, WT, RT that `atelier run
    kes_tensile_cotton_broad.ron` reports as `input_*` (to 0.2 %, the trapezoid rule over 1000
    force levels), and the simulated specimen's within the scenario's 3 %."""
    report, _ = cli.run("kes_tensile_cotton_broad")
    m = report["metrics"]
    loop = atelier.Fabric.load(str(FABRICS / "cotton_broad.ron")).tensile_loop("warp", levels=1000)
    emt, lt, wt, rt = kes_tensile_values(loop)
    wt_kes = wt / (GF_CM * 1e-2 / 1e-4 * 1e-2)  # J/m² → gf·cm/cm²
    assert 100 * emt == pytest.approx(m["input_emt_percent"], rel=1e-9)
    assert lt == pytest.approx(m["input_lt"], rel=2e-3)
    assert wt_kes == pytest.approx(m["input_wt_gf_cm_cm2"], rel=2e-3)
    assert 100 * rt == pytest.approx(m["input_rt_percent"], rel=2e-3)
    for ours, simulated in [
        (100 * emt, m["emt_percent"]),
        (lt, m["lt"]),
        (wt_kes, m["wt_gf_cm_cm2"]),
        (100 * rt, m["rt_percent"]),
    ]:
        assert ours == pytest.approx(simulated, rel=0.03)


def test_bending_loop_matches_the_programs_kes_bending_test(cli):
    """B (slope of the falling branch over −1.5…−0.5 cm⁻¹) and 2HB (the loop's width at
    +1 cm⁻¹) of the warp loop are the fabric's values `atelier run kes_bending_cotton_broad.ron`
    reports as `input_*` (to 1e-9), and the simulated specimen's within the scenario's 5 %."""
    report, _ = cli.run("kes_bending_cotton_broad")
    m = report["metrics"]
    loop = atelier.Fabric.load(str(FABRICS / "cotton_broad.ron")).bending_loop("warp", steps_per_cm=20)
    n = 50  # samples per 2.5 cm⁻¹ leg
    rising, falling = loop[: n + 1], loop[n : 3 * n + 1]
    band = (falling[:, 0] <= -50.0) & (falling[:, 0] >= -150.0)
    b = np.polyfit(falling[band, 0], falling[band, 1], 1)[0]  # N·m
    at = lambda leg, k: leg[np.argmin(np.abs(leg[:, 0] - k)), 1]  # noqa: E731
    two_hb = at(rising, 100.0) - at(falling, 100.0)  # N
    b_kes, two_hb_kes = b / 9.80665e-5, two_hb / 9.80665e-3
    assert b_kes == pytest.approx(m["input_b_gf_cm2_cm"], rel=1e-9)
    assert two_hb_kes == pytest.approx(m["input_two_hb_gf_cm_cm"], rel=1e-9)
    assert b_kes == pytest.approx(m["b_gf_cm2_cm"], rel=0.05)
    assert two_hb_kes == pytest.approx(m["two_hb_gf_cm_cm"], rel=0.05)


def test_shear_loop_gives_the_files_kes_values():
    """G (mean secant 0.5°…5° of both branches, both signs), 2HG and 2HG5 (widths at ±0.5°, ±5°)
    read off the last lap of the loop are cotton broad's file values 1.5 gf/(cm·deg), 2.5 and
    4.5 gf/cm (no scenario runs the shear test; docs/fabric.md §9 asserts the same)."""
    loop = atelier.Fabric.load(str(FABRICS / "cotton_broad.ron")).shear_loop(steps_per_deg=10)
    n = 80  # samples per 8°
    lower = loop[n : 3 * n + 1][::-1]  # +8° → −8°, reversed to increasing angle
    upper = loop[3 * n :]  # −8° → +8°
    deg = math.radians(1.0)
    at = lambda branch, g: np.interp(g * deg, branch[:, 0], branch[:, 1])  # noqa: E731
    secants = [
        (at(br, s * 5.0) - at(br, s * 0.5)) / (s * 4.5) for br in (upper, lower) for s in (1, -1)
    ]
    g = np.mean(secants) / GF_CM  # per degree, gf/cm
    width = lambda a: 0.5 * ((at(upper, a) - at(lower, a)) + (at(upper, -a) - at(lower, -a)))  # noqa: E731
    assert g == pytest.approx(1.5, rel=1e-6)
    assert width(0.5) / GF_CM == pytest.approx(2.5, rel=1e-6)
    assert width(5.0) / GF_CM == pytest.approx(4.5, rel=1e-6)


def test_direction_and_sampling_are_checked():
    silk = atelier.Fabric.load(str(FABRICS / "silk.ron"))
    with pytest.raises(ValueError, match="direction.*bias"):
        silk.tensile_loop("bias")
    with pytest.raises(ValueError, match="direction"):
        silk.bending_loop("north")
    with pytest.raises(ValueError, match="levels"):
        silk.tensile_loop("warp", levels=0)
    with pytest.raises(TypeError):
        silk.tensile_loop(0)


def with_change(path, value):
    """SILK with the entry at `path` (dotted) set to `value` (None removes it)."""
    import copy

    values = copy.deepcopy(SILK)
    *parents, last = path.split(".")
    d = values
    for p in parents:
        d = d[p]
    if value is None:
        del d[last]
    else:
        d[last] = value
    return values


@pytest.mark.parametrize(
    "path,value,error,field",
    [
        ("tensile.warp.lt", "0.65", TypeError, "tensile.warp.lt"),
        ("tensile.warp.lt", True, TypeError, "tensile.warp.lt"),
        ("tensile.warp.lt", 2.5, ValueError, "tensile.warp.lt"),
        ("tensile.warp.lt", float("nan"), ValueError, "tensile.warp.lt"),
        ("tensile.warp.rt_percent", None, ValueError, "tensile.warp.rt_percent"),
        ("tensile.weft.emt", 10.0, ValueError, "tensile.weft.emt"),
        ("tensile.bias", {"lt": 0.6}, ValueError, "tensile.bias"),
        ("tensile.weft.wt_gf_cm_cm2", 99.0, ValueError, "tensile.weft.wt_gf_cm_cm2"),
        ("tensile", [1, 2], TypeError, "tensile"),
        ("bending.warp.b_gf_cm2_cm", -0.02, ValueError, "bending.warp.b_gf_cm2_cm"),
        ("bending.weft", None, ValueError, "bending.weft"),
        ("shear.g_gf_cm_deg", object(), TypeError, "shear.g_gf_cm_deg"),
        ("shear", None, ValueError, "tensile.bias45"),
        ("mass_per_area_mg_cm2", "5", TypeError, "mass_per_area_mg_cm2"),
        ("thickness_mm", 0.0, ValueError, "thickness_mm"),
        ("friction", -1.0, ValueError, "friction"),
        ("name", "", ValueError, "name"),
    ],
)
def test_bad_kes_values_name_the_field(path, value, error, field):
    with pytest.raises(error, match=re.escape(f"`{field}`")):
        from_kes(with_change(path, value))


def test_a_bad_file_names_file_line_column_and_field(tmp_path):
    bad = tmp_path / "bad.ron"
    text = (FABRICS / "silk.ron").read_text().replace("emt_percent: 8.0", "emt_percent: -8.0")
    bad.write_text(text)
    line = next(i for i, l in enumerate(text.splitlines(), 1) if "emt_percent: -8.0" in l)
    with pytest.raises(atelier.AtelierError, match=rf"bad\.ron:{line}:\d+: field `tensile\.warp\.emt_percent`"):
        atelier.Fabric.load(str(bad))
    with pytest.raises(atelier.AtelierError, match="missing.ron"):
        atelier.Fabric.load(str(tmp_path / "missing.ron"))
    assert issubclass(atelier.AtelierError, Exception)
