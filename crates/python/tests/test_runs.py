"""atelier.run, atelier.drape and atelier.cantilever against `atelier run` on the same
scenarios, and their bad input."""

import re

import numpy as np
import pytest

import atelier
from conftest import FABRICS, SCENARIOS, read_obj_part


def test_run_returns_the_programs_report(cli, tmp_path):
    """`atelier.run` writes the same outputs as `atelier run` and returns its report.json: the
    same metrics to the last bit, the same expectations, outputs and convergence; only the wall
    times and the file names given differ."""
    scenario = SCENARIOS / "cantilever_cotton_broad.ron"
    ours = atelier.run(str(scenario), str(tmp_path / "out"))
    theirs, folder = cli.run("cantilever_cotton_broad")
    assert ours["format"] == "atelier-report/1"
    assert ours["metrics"] == theirs["metrics"]
    for key in ("expectations", "expectations_met", "convergence", "outputs", "warnings", "failure", "steps", "fabric"):
        assert ours[key] == theirs[key], key
    assert ours["scenario"]["name"] == theirs["scenario"]["name"] == "cantilever_cotton_broad"
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(p.name for p in folder.iterdir())
    ours_v, _ = read_obj_part(tmp_path / "out" / "final.obj", "cloth")
    theirs_v, _ = read_obj_part(folder / "final.obj", "cloth")
    assert ours_v == theirs_v


def test_run_raises_atelier_error_naming_file_line_column_and_field(tmp_path):
    text = (SCENARIOS / "cantilever_cotton_broad.ron").read_text()
    bad = tmp_path / "bad.ron"
    bad.write_text(text.replace("segments: 40", "segment: 40"))
    line = next(i for i, l in enumerate(bad.read_text().splitlines(), 1) if "segment: 40" in l)
    with pytest.raises(atelier.AtelierError, match=rf"bad\.ron:{line}:\d+: field `kind\.segment`: unknown field"):
        atelier.run(str(bad), str(tmp_path / "out"))
    bad.write_text(text.replace("segments: 40", "segments: 2"))
    with pytest.raises(atelier.AtelierError, match=r"bad\.ron:\d+:\d+: field `kind\.segments`"):
        atelier.run(str(bad), str(tmp_path / "out"))
    # The fabric file is named relative to the scenario's folder: missing from a copy here.
    bad.write_text(text)
    with pytest.raises(atelier.AtelierError, match=r"cotton_broad\.ron"):
        atelier.run(str(bad), str(tmp_path / "out"))
    with pytest.raises(atelier.AtelierError, match="no_such"):
        atelier.run(str(tmp_path / "no_such.ron"), str(tmp_path / "out"))
    with pytest.raises(ValueError, match="frames"):
        atelier.run(str(SCENARIOS / "cantilever_cotton_broad.ron"), str(tmp_path / "out"), frames=1)
    assert not (tmp_path / "out" / "report.json").exists()


def test_drape_is_the_programs_drape_scenario(cli):
    """`drape(silk, "thesis", max_time=6.0)` is the scenario drape_thesis_silk.ron
    (`Drape(fabric: "../fabrics/silk.ron", tester: Thesis, max_time: 6.0)`, every other field
    its default): every metric equals the program's to the last bit, the outline is the
    report's `drape` section and the outer ring of its final.obj, seen from above."""
    text = (SCENARIOS / "drape_thesis_silk.ron").read_text()
    assert 'kind: Drape(fabric: "../fabrics/silk.ron", tester: Thesis, max_time: 6.0),' in text
    silk = atelier.Fabric.load(str(FABRICS / "silk.ron"))
    ours = atelier.drape(silk, tester="thesis", max_time=6.0)
    theirs, folder = cli.run("drape_thesis_silk")
    for name, value in theirs["metrics"].items():
        assert ours[name] == value, name
    assert isinstance(ours["node_count"], int) and isinstance(ours["settled"], bool)
    outline = ours["outline"]
    assert outline.shape == (60, 2) and outline.dtype == np.float64
    top = theirs.get("drape")
    if top is not None:  # report.json's drape section
        assert np.array_equal(outline, np.array(top["outline_m"]))
        assert np.array_equal(ours["node_points"], np.array(top["node_points_m"]).reshape(-1, 2))
        assert ours["support_radius_m"] == top["support_radius_m"]
        assert ours["specimen_radius_m"] == top["specimen_radius_m"]
    cloth, _ = read_obj_part(folder / "final.obj", "cloth")
    ring = np.array(cloth[-60:])  # the outer ring: the last 60 nodes (y up: x, z horizontal)
    assert np.array_equal(outline, ring[:, [0, 2]])
    radii = np.hypot(outline[:, 0], outline[:, 1])
    assert radii.min() == pytest.approx(ours["min_edge_radius_m"], rel=1e-12)
    assert radii.max() == pytest.approx(ours["max_edge_radius_m"], rel=1e-12)
    assert len(ours["node_points"]) == ours["node_count"]
    assert ours["support_radius_m"] == pytest.approx(0.0635)
    assert ours["specimen_radius_m"] == pytest.approx(0.3175)
    assert ours["positions"].shape == (ours["nodes"], 3)
    assert ours["triangles"].shape == (ours["cloth_triangles"], 3)


def test_cantilever_is_the_programs_cantilever_scenario(cli):
    """`cantilever(cotton)` is cantilever_cotton_broad.ron (`Cantilever(fabric: …, direction:
    Warp, segments: 40)`, 40 the default): the same metrics to the last bit and the same final
    strip."""
    text = (SCENARIOS / "cantilever_cotton_broad.ron").read_text()
    assert 'kind: Cantilever(fabric: "../fabrics/cotton_broad.ron", direction: Warp, segments: 40),' in text
    cotton = atelier.Fabric.load(str(FABRICS / "cotton_broad.ron"))
    ours = atelier.cantilever(cotton, direction="warp")
    theirs, folder = cli.run("cantilever_cotton_broad")
    for name, value in theirs["metrics"].items():
        assert ours[name] == value, name
    cloth, _ = read_obj_part(folder / "final.obj", "cloth")
    assert np.array_equal(ours["positions"], np.array(cloth))
    assert ours["direction"] == "warp" and ours["failure"] is None


def test_a_fabric_from_kes_drapes_as_its_file():
    """A short drape (0.05 s) of silk built in Python and of silk read from its file: the same
    numbers (the fabric is all that differs between them)."""
    from test_fabric import SILK, from_kes

    a = atelier.drape(from_kes(SILK), "jis", max_time=0.05)
    b = atelier.drape(atelier.Fabric.load(str(FABRICS / "silk.ron")), "jis", max_time=0.05)
    assert a["drape_coefficient_percent"] == b["drape_coefficient_percent"]
    assert np.array_equal(a["positions"], b["positions"])
    assert a["settled"] is False and any("not at rest" in w for w in a["warnings"])


@pytest.mark.parametrize(
    "call,error,pattern",
    [
        (lambda f: atelier.drape(f, tester="iso"), ValueError, "`tester`.*iso"),
        (lambda f: atelier.drape(f, max_tim=1.0), ValueError, "`max_tim`: unknown field"),
        (lambda f: atelier.drape(f, max_time="1"), TypeError, "`max_time`"),
        (lambda f: atelier.drape(f, max_time=-1.0), ValueError, "`max_time`"),
        (lambda f: atelier.drape(f, n_rings=1), ValueError, "`n_rings`"),
        (lambda f: atelier.drape(f, form="Plate"), ValueError, "`form`: unknown variant"),
        (lambda f: atelier.drape(f, step={"damping": -1.0}, max_time=0.01), atelier.AtelierError, "`damping`"),
        (lambda f: atelier.cantilever(f, direction="bias"), ValueError, "`direction`"),
        (lambda f: atelier.cantilever(f, segments=2), ValueError, "`segments`"),
        (lambda f: atelier.cantilever(f, segments=4.5), TypeError, "`segments`"),
        (lambda f: atelier.drape("silk.ron"), TypeError, "fabric"),
    ],
)
def test_bad_test_options_name_the_field(call, error, pattern):
    silk = atelier.Fabric.load(str(FABRICS / "silk.ron"))
    with pytest.raises(error, match=pattern):
        call(silk)


def test_a_run_that_fails_is_a_result_not_an_error():
    """A step that diverges ends the run: the dict says why (`failure`), the metrics it could
    not measure are None, and no outline is drawn."""
    silk = atelier.Fabric.load(str(FABRICS / "silk.ron"))
    r = atelier.drape(silk, "jis", perturbation=10.0, max_time=0.01)
    assert re.search("diverging|non-finite", r["failure"])
    assert r["drape_coefficient_percent"] is None and r["outline"] is None
