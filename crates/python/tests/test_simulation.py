"""atelier.Simulation: skirt_sewn.ron stepped to its end against `atelier run`'s final.obj and
report, and what it refuses."""

import numpy as np
import pytest

import atelier
from conftest import SCENARIOS, read_obj_part


def test_stepping_skirt_sewn_to_the_end_gives_the_programs_final_state(cli):
    """Every step through `step()` until it returns None: the final cloth is final.obj's to
    1e-6 m (in fact to the bit), with the same triangles, and the report's garment metrics are
    report.json's."""
    sim = atelier.Simulation(str(SCENARIOS / "skirt_sewn.ron"))
    assert sim.name == "skirt_sewn" and sim.time == 0.0 and sim.phase == "Sewing"
    start = sim.positions
    first = sim.step()
    assert first["phase"] == "Sewing" and first["time_s"] == pytest.approx(0.01)
    assert sim.time == pytest.approx(0.01)
    assert not np.array_equal(sim.positions, start)
    steps, phases = 1, {first["phase"]}
    while (outcome := sim.step()) is not None:
        steps += 1
        phases.add(outcome["phase"])
    assert sim.step() is None and sim.phase == "Done"
    assert phases == {"Sewing", "Settling"}

    theirs, folder = cli.run("skirt_sewn")
    cloth, faces = read_obj_part(folder / "final.obj", "cloth")
    positions = sim.positions
    assert positions.shape == (len(cloth), 3) and positions.dtype == np.float64
    assert np.abs(positions - np.array(cloth)).max() <= 1e-6
    assert np.array_equal(sim.triangles, np.array(faces))
    report = sim.report()
    assert report["steps"] == steps == theirs["steps"]
    assert report["time_s"] == pytest.approx(theirs["simulated_s"], abs=1e-9)
    assert report["failure"] is None and report["ended"]
    assert report["convergence"] == theirs["convergence"]
    m, t = report["metrics"], theirs["metrics"]
    same = [
        "nodes", "cloth_triangles", "body_triangles", "pairs", "pairs_sewn", "unsewn_pairs",
        "sewn_at_s", "max_penetration_m", "steps_with_penetration", "max_strain_error",
        "final_strain_error", "kinetic_energy_j", "max_motion_kinetic_energy_j",
        "lowest_node_m", "hem_width_m", "hem_depth_m", "unconverged_fraction",
    ]
    for name in same:
        assert m[name] == pytest.approx(t[name], rel=1e-12, abs=1e-15), name
    assert m["nodes_inside"] == t["nodes_inside_at_end"]
    assert report["sewing"] == {"pairs_sewn": 115, "pairs": 115, "sewn_at_s": t["sewn_at_s"]}
    assert sim.body_positions.shape[1] == 3 and sim.body_triangles.shape[1] == 3


def test_advance_steps_for_a_duration():
    sim = atelier.Simulation(str(SCENARIOS / "skirt_sewn.ron"))
    assert sim.advance(0.03) == 3
    assert sim.time == pytest.approx(0.03)
    assert sim.report()["steps"] == 3
    with pytest.raises(ValueError, match="duration"):
        sim.advance(-1.0)


def test_other_kinds_are_refused_with_what_to_use_instead():
    with pytest.raises(atelier.AtelierError, match=r"garment scenarios.*Drape.*atelier\.run\(\)"):
        atelier.Simulation(str(SCENARIOS / "drape_thesis_silk.ron"))


def test_a_bad_garment_scenario_names_file_line_column_and_field(tmp_path):
    text = (SCENARIOS / "skirt_sewn.ron").read_text()
    bad = tmp_path / "skirt.ron"
    bad.write_text(text.replace("dt: 0.01,", "dt: -0.01,"))
    with pytest.raises(atelier.AtelierError, match=r"skirt\.ron:\d+:\d+: field `kind\.settings\.dt`"):
        atelier.Simulation(str(bad))
    bad.write_text(text)  # its pattern and fabric files are relative to fixtures/scenarios
    with pytest.raises(atelier.AtelierError, match=r"skirt\.ron"):
        atelier.Simulation(str(bad))
    with pytest.raises(TypeError):
        atelier.Simulation(3)
