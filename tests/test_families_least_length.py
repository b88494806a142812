"""The families' constructors from Python refuse a length between 0 and ``Tolerances.min_length``
(1e-3 mm) as a design file does, naming it, and say whether 0 is allowed as the family answers it.

Before, a design file refused such a length but ``tabletcad.families`` built it or failed late: a
1e-300 mm cup depth gave a tablet of volume NaN (every shaped family, the concave rounds), 5e-324 mm ran
for minutes, a 1e-9 mm band built and then failed in the CAD stage ("sewn shell has 2 faces"), a thesis
caplet or oval 1e-300 mm wide raised ZeroDivisionError, a thesis flat-faced round 1e-300 mm across was a
tablet of volume 0.  And a design file's ``band = 1e-9`` was told "must be 0 or at least 0.001 mm",
then ``band = 0`` "must be > 0".  Core only.
"""

from __future__ import annotations

import math
import re

import pytest

from tabletcad.cli import main
from tabletcad.errors import DesignError
from tabletcad.families import FAMILIES, outline_tablet
from tabletcad.pipeline.design import Design
from tabletcad.tolerance import DEFAULT

LEAST = DEFAULT.min_length
REFUSAL = re.compile(r"^(\S+) = (\S+) mm is not allowed: must be (0 or )?at least 0\.001 mm \(Tolerances\.min_length")

LENGTHS = [(name, k) for name, fam in FAMILIES.items() for k, unit in fam.params.items() if unit == "mm"]


def _zero_builds(fam, dims: dict, k: str) -> bool:
    try:
        fam.build(**{**dims, k: 0.0})
        return True
    except DesignError:
        return False


@pytest.mark.parametrize("name, k", LENGTHS, ids=[f"{n}-{k}" for n, k in LENGTHS])
def test_every_length_below_the_least_one_is_refused_naming_it(name, k):
    fam = FAMILIES[name]
    dims = fam.defaults
    zero = _zero_builds(fam, dims, k)  # (independently of the refusal: the constructor itself at 0)
    values = (1e-9, 1e-300, 0.999 * LEAST) if k in ("band", "cup_depth", "width", "diameter") else (1e-9,)
    for v in values:
        with pytest.raises(DesignError) as e:
            fam.func(**{**dims, k: v})
        m = REFUSAL.match(str(e.value))
        assert m, str(e.value)
        assert m.group(1) == k and float(m.group(2)) == v
        assert bool(m.group(3)) == zero, (str(e.value), zero)


@pytest.mark.parametrize("name", [n for n, f in FAMILIES.items() if "band" in f.params or "cup_depth" in f.params])
def test_a_band_and_cup_depth_of_the_least_length_build(name):
    """What the refusal offers builds: the least length itself (a compound cup's depth has its own
    range, ``test_input_ranges_inward.py``)."""
    fam = FAMILIES[name]
    for k in ("band", "cup_depth"):
        if k in fam.params and name != "compound_cup" or k == "band" and name == "compound_cup":
            t = fam.build(**{**fam.defaults, k: LEAST})
            assert t.volume() > 0.0 and t.volume() == t.volume()


def test_a_custom_outline_refuses_a_tiny_cup_depth_and_band():
    pts = [(5.0 * math.cos(t / 10), 3.0 * math.sin(t / 10)) for t in range(63)]  # a 10 x 6 mm ellipse
    with pytest.raises(DesignError, match=r"^band = 1e-09 mm is not allowed: must be at least 0\.001 mm"):
        outline_tablet(pts, band=1e-9, cup_depth=0.5)
    with pytest.raises(DesignError, match=r"^cup_depth = 1e-300 mm is not allowed: must be 0 or at least 0\.001 mm"):
        outline_tablet(pts, band=2.0, cup_depth=1e-300)
    assert outline_tablet(pts, band=2.0, cup_depth=0.0).volume() > 0.0  # (0 is what it offers: a flat face)
    assert outline_tablet(pts, band=LEAST, cup_depth=LEAST).volume() > 0.0


@pytest.mark.parametrize("family, dims, key, zero", [
    ("concave_round", dict(diameter=10.0, band=2.0, cup_depth=1.0), "band", False),
    ("concave_round", dict(diameter=10.0, band=2.0, cup_depth=1.0), "cup_depth", False),
    ("concave_round", dict(diameter=10.0, band=2.0, cup_depth=1.0), "land", True),
    ("capsule", dict(length=18.0, width=8.0, band=3.0, cup_depth=1.2), "cup_depth", True),
    ("thesis.shallow_convex_round", dict(diameter=10.0, thickness=3.0, band=2.0), "band", False),
])
def test_a_design_file_states_the_range_its_family_takes(tmp_path, capsys, family, dims, key, zero):
    """One line, exit 2, and "0 or" only where 0 builds: checked by building the design with 0."""
    p = tmp_path / "d.toml"
    text = f'[tablet]\nfamily = "{family}"\n' + "".join(f"{k} = {v!r}\n" for k, v in {**dims, key: 1e-9}.items())
    p.write_text(text, encoding="utf-8")
    assert main(["report", str(p)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: tablet.{key} = 1e-09 mm is not allowed: must be {'0 or ' if zero else ''}at least "
                   "0.001 mm (Tolerances.min_length: a smaller feature is below the tolerance the surface is "
                   "certified to)"], err
    try:
        Design.from_dict({"tablet": {"family": family, **dims, key: 0.0}}).build()
        built = True
    except DesignError:
        built = False
    assert built == zero


@pytest.mark.parametrize("name, k", LENGTHS, ids=[f"{n}-{k}" for n, k in LENGTHS])
def test_every_length_beyond_the_size_limit_is_refused_as_a_design_file_refuses_it(name, k):
    """The other end: a length beyond ``±Tolerances.max_length`` (1000 mm), the size limit a design file
    keeps, is refused by the constructor with the design file's words (``concave_round(diameter=5000)``
    had built a tablet 5 m across)."""
    fam = FAMILIES[name]
    for v in (1000.001, -5000.0, 1e300):
        with pytest.raises(DesignError) as e:
            fam.func(**{**fam.defaults, k: v})
        assert str(e.value) == f"{k} = {v:g} mm is not allowed: must be within ±1000 mm (size limit, Tolerances.max_length)" \
            or str(e.value).startswith(f"{k} = {v!r} mm is not allowed: must be within ±1000 mm"), str(e.value)


def test_a_round_of_the_size_limit_builds_from_python_as_from_a_design_file():
    t = FAMILIES["flat_face_round"].func(diameter=1000.0, thickness=3.0)
    lo, hi = t.bounds()
    assert hi[0] - lo[0] == pytest.approx(1000.0, rel=1e-12)
