"""Shared fixtures: the repository, and the `atelier` program's runs of the same scenarios the
tests run through the Python module (the reference every test compares with).

The program is `target/release/atelier` (test.sh builds it), or the path in $ATELIER_CLI. Its
runs start in the background when the session starts, one at a time, so that they overlap the
tests' own (Python-side) runs; each test waits only for the run it compares with.
"""

import json
import os
import subprocess
import threading
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
SCENARIOS = REPO / "fixtures" / "scenarios"
FABRICS = REPO / "fixtures" / "fabrics"

# The scenarios the tests compare with, in the order they are needed.
CLI_SCENARIOS = [
    "kes_tensile_cotton_broad",
    "kes_bending_cotton_broad",
    "cantilever_cotton_broad",
    "drape_thesis_silk",
    "skirt_sewn",
]


def cli_path() -> Path:
    return Path(os.environ.get("ATELIER_CLI", REPO / "target" / "release" / "atelier"))


class CliRuns:
    """`atelier run fixtures/scenarios/NAME.ron --out DIR/NAME` for every name, in a
    background thread, one after the other."""

    def __init__(self, out: Path):
        self.out = out
        self.done = {name: threading.Event() for name in CLI_SCENARIOS}
        self.results = {}
        self.thread = threading.Thread(target=self._run_all, daemon=True)
        self.thread.start()

    def _run_all(self):
        for name in CLI_SCENARIOS:
            folder = self.out / name
            try:
                p = subprocess.run(
                    [str(cli_path()), "run", str(SCENARIOS / f"{name}.ron"), "--out", str(folder)],
                    capture_output=True,
                    text=True,
                    timeout=600,
                )
                self.results[name] = (p.returncode, p.stdout + p.stderr, folder)
            except Exception as e:  # reported by `run` below
                self.results[name] = (None, repr(e), folder)
            self.done[name].set()

    def run(self, name: str):
        """The program's report.json (a dict) and output folder for scenario NAME."""
        assert self.done[name].wait(900), f"the atelier program did not finish {name}"
        code, output, folder = self.results[name]
        # 0: passed; 2: ran, but missed an expectation or did not converge (still a reference).
        assert code in (0, 2), f"atelier run {name} exited {code}: {output}"
        with open(folder / "report.json") as f:
            return json.load(f), folder


@pytest.fixture(scope="session", autouse=True)
def cli(tmp_path_factory):
    if not cli_path().is_file():
        pytest.exit(
            f"{cli_path()} is missing: build it with `cargo build --release -p atelier-cli` "
            "(crates/python/test.sh does) or set ATELIER_CLI",
            returncode=1,
        )
    return CliRuns(tmp_path_factory.mktemp("cli"))


def read_obj_part(path: Path, part: str):
    """Vertices (list of [x, y, z]) and triangles (0-based, part-local) of one `o` part of an
    OBJ file written by atelier."""
    vertices, faces, current, offset, count = [], [], None, 0, 0
    for line in open(path):
        if line.startswith("o "):
            if current == part:
                break
            offset += count
            count = 0
            current = line.split(maxsplit=1)[1].strip()
        elif line.startswith("v "):
            count += 1
            if current == part:
                vertices.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f ") and current == part:
            faces.append([int(v.split("/")[0]) - 1 - offset for v in line.split()[1:4]])
    return vertices, faces

