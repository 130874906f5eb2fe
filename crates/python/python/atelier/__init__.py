"""atelier: garments and drape from measured fabric mechanics.

Python bindings of the atelier cloth simulator (docs/python.md):

- ``run(scenario, out)``: run a scenario file into a folder, as ``atelier run``; returns
  report.json as a dict.
- ``Fabric.load(path)``, ``Fabric.from_kes(...)``: a fabric from its file or from KES values;
  ``tensile_loop``, ``bending_loop``, ``shear_loop`` as numpy arrays (SI).
- ``drape(fabric, tester="jis")``, ``cantilever(fabric, direction="warp")``: the drape test and
  the Peirce cantilever of a fabric, as the scenario kinds run them.
- ``Simulation(scenario)``: a garment scenario stepped from Python.
- ``AtelierError``: what atelier raises for bad files, scenes that cannot be set up, failed
  steps and internal errors (wrong Python types raise ``TypeError``, refused values
  ``ValueError``, both naming the field).

Units are SI (metres, seconds, newtons) except where a name says otherwise (``_percent``,
``_deg``, KES units ``_gf_cm`` in ``Fabric.from_kes``).
"""

from ._atelier import (
    AtelierError,
    Fabric,
    Simulation,
    __version__,
    cantilever,
    drape,
    run,
)

__all__ = [
    "AtelierError",
    "Fabric",
    "Simulation",
    "__version__",
    "cantilever",
    "drape",
    "run",
]
