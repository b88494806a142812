"""Material property table (``tabletcad/data/materials.toml``) and its loader.

Units: radius mm, ``E`` MPa, ``nu`` dimensionless, ``s_y`` MPa, ``true_density`` mg/mm³.
The granule entries come from the thesis's Table 5.2 (see the file for the cited
original sources).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import tomllib

from tabletcad.errors import DesignError, check_positive, check_range

__all__ = ["MATERIALS_FILE", "Material", "get_material", "load_materials"]

MATERIALS_FILE = Path(__file__).resolve().parent.parent / "data" / "materials.toml"


@dataclass(frozen=True)
class Material:
    """Elastic / elastic-plastic properties of a granule or compact.

    Attributes
    ----------
    key : str
        Identifier in the table.
    name : str
        Display name.
    E : float
        Young's modulus, MPa.
    nu : float
        Poisson's ratio.
    radius : float or None
        Granule (sphere) radius, mm.
    s_y : float or None
        Micro-yield strength, MPa (eq 5.22).
    true_density : float or None
        mg/mm³.
    cited : str
        Source.
    """

    key: str
    name: str
    E: float
    nu: float
    radius: float | None = None
    s_y: float | None = None
    true_density: float | None = None
    cited: str = ""

    def __post_init__(self) -> None:
        check_positive("E", self.E, "MPa")
        check_range("nu", self.nu, -1.0, 0.5, hi_open=True, lo_open=True)
        if self.radius is not None:
            check_positive("radius", self.radius, "mm")
        if self.s_y is not None:
            check_positive("s_y", self.s_y, "MPa")


@lru_cache(maxsize=4)
def load_materials(path: str | None = None) -> dict[str, Material]:
    """Read the material table; keys and aliases are lower-case."""
    p = Path(path) if path else MATERIALS_FILE
    raw = tomllib.loads(p.read_text(encoding="utf-8-sig"))
    out: dict[str, Material] = {}
    for key, d in raw.items():
        m = Material(
            key=key, name=d.get("display_name", key), E=float(d["E"]), nu=float(d["nu"]),
            radius=d.get("radius"), s_y=d.get("s_y"), true_density=d.get("true_density"), cited=d.get("cited", ""),
        )
        out[key.lower()] = m
        for alias in d.get("aliases", []):
            out[alias.lower()] = m
    return out


def get_material(name: str | Material) -> Material:
    """Look a material up by key or alias (case-insensitive)."""
    if isinstance(name, Material):
        return name
    table = load_materials()
    m = table.get(str(name).strip().lower())
    if m is None:
        keys = sorted({v.key for v in table.values()})
        raise DesignError("material", name, "must be one of " + ", ".join(keys))
    return m
