"""Type stubs of the extension module atelier._atelier (docs/python.md has the units)."""

import os
from typing import Any, Dict, Mapping, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, os.PathLike]
Float2 = npt.NDArray[np.float64]
Int2 = npt.NDArray[np.int64]

class AtelierError(Exception):
    """A file that does not read (file:line:column and field), a scene that cannot be set up,
    a step that failed, or an internal error (a Rust panic, caught)."""

class Fabric:
    @staticmethod
    def load(path: PathLike) -> "Fabric": ...
    @staticmethod
    def from_kes(
        name: str,
        mass_per_area_mg_cm2: float,
        thickness_mm: float,
        *,
        tensile: Mapping[str, Any],
        bending: Mapping[str, Any],
        shear: Optional[Mapping[str, Any]] = None,
        friction: Optional[float] = None,
        provenance: Optional[Mapping[str, Any]] = None,
        fabric_class: Optional[str] = None,
    ) -> "Fabric": ...
    @property
    def name(self) -> str: ...
    @property
    def origin(self) -> str: ...
    @property
    def mass_per_area(self) -> float: ...
    @property
    def thickness(self) -> float: ...
    @property
    def friction(self) -> float: ...
    def tensile_loop(self, direction: str, levels: int = 100) -> Float2:
        """(2·levels + 1, 2): strain (fraction), force per width (N/m)."""
    def bending_loop(self, direction: str, steps_per_cm: int = 20) -> Float2:
        """(10·steps_per_cm + 1, 2): curvature (1/m), moment per width (N·m/m)."""
    def shear_loop(self, steps_per_deg: int = 10) -> Float2:
        """(40·steps_per_deg + 1, 2): shear angle (rad), shear force per width (N/m)."""
    def kes(self) -> Dict[str, Any]: ...
    def __eq__(self, other: object) -> bool: ...

def run(scenario: PathLike, out: PathLike, *, frames: Optional[int] = None) -> Dict[str, Any]: ...
def drape(fabric: Fabric, tester: str = "jis", **options: Any) -> Dict[str, Any]: ...
def cantilever(fabric: Fabric, direction: str = "warp", **options: Any) -> Dict[str, Any]: ...

class Simulation:
    def __init__(self, scenario: PathLike) -> None: ...
    def step(self) -> Optional[Dict[str, Any]]: ...
    def advance(self, duration: Optional[float] = None) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def phase(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def positions(self) -> Float2:
        """(N, 3) float64, m, body frame (a copy)."""
    @property
    def triangles(self) -> Int2: ...
    @property
    def body_positions(self) -> Float2: ...
    @property
    def body_triangles(self) -> Int2: ...
    def report(self) -> Dict[str, Any]: ...

def _panic_for_test(message: str) -> None: ...
