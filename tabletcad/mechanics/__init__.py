"""Compaction mechanics: press data, Heckel and related fits, contact laws, strength, die and shell models.

Units throughout: mm, N, MPa (= N/mm²), mg, mg/mm³.  Only numpy, scipy and
matplotlib are used (matplotlib lazily, with the Agg backend, for plots).

Modules
-------
pressdata    reading force/position records and their metadata, machine compliance
compaction   pressure, thickness, relative density, porosity, Heckel term, branches
heckel       Heckel fit with a given or automatically chosen window, plot
kawakita     Kawakita and Walker fits
profiles     tabletability / compressibility / compactibility, Ryshkewitch-Duckworth
strength     tensile-strength formulas with validity warnings
contact      Hertz and Antonyuk contact laws, compressed spherical tablet
materials    material table (tabletcad/data/materials.toml)
love         the thesis's Love stress-function die model, exact confined compression
shell        thick elastic spherical shell under band and internal pressure
validity     warning classes
"""

from tabletcad.mechanics.compaction import CompactionCurves, compaction_curves, split_branches
from tabletcad.mechanics.contact import compress_sphere
from tabletcad.mechanics.heckel import HeckelFit, fit_heckel, fit_heckel_arrays, plot_heckel
from tabletcad.mechanics.materials import Material, get_material
from tabletcad.mechanics.pressdata import MachineCompliance, PressData, PressMetadata, read_press_data
from tabletcad.mechanics.shell import lame_displacement, solve_shell
from tabletcad.mechanics.validity import DataWarning, FitQualityWarning, MechanicsWarning, ValidityWarning

__all__ = [
    "CompactionCurves",
    "DataWarning",
    "FitQualityWarning",
    "HeckelFit",
    "MachineCompliance",
    "Material",
    "MechanicsWarning",
    "PressData",
    "PressMetadata",
    "ValidityWarning",
    "compaction_curves",
    "compress_sphere",
    "fit_heckel",
    "fit_heckel_arrays",
    "get_material",
    "lame_displacement",
    "plot_heckel",
    "read_press_data",
    "solve_shell",
    "split_branches",
]
