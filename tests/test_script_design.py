"""The Design value: a design file as checked data, separate from the tablet it builds, with one
TOML reader and writer (round trips through tomllib, a second reader)."""

from __future__ import annotations

import datetime
import math
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tabletcad.pipeline.design import Design, design_to_toml, load_design, toml_text
from tabletcad.pipeline.designreport import ReportOptions
from tabletcad.errors import DesignError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
DESIGNS = sorted(p for p in ROOT.joinpath("samples").rglob("*.toml") if "[tablet]" in p.read_text(encoding="utf-8"))


@pytest.mark.parametrize("path", DESIGNS, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_sample_round_trips_through_toml(path):
    d = Design.from_toml(path)
    text = d.to_toml()
    assert tomllib.loads(text) == d.to_dict()
    again = Design.from_dict(tomllib.loads(text))
    assert again == d and again.name == d.name == (d.tablet.get("name") or path.stem)
    if path.parent.name in ("samples", "families"):  # the plain designs: same tablet, same figures
        assert again.build().volume() == load_design(path).volume()


def test_the_design_owns_its_tables_and_is_separate_from_the_tablet():
    data = {"tablet": {"family": "concave_round", "diameter": 10.0, "band": 3.0, "cup_depth": 1.0},
            "tooling": {"clearance_mm": 0.02}}
    d = Design.from_dict(data, default_name="cr10")
    data["tablet"]["diameter"] = 99.0
    d.to_dict()["tablet"]["band"] = 1.0
    assert d.tablet["diameter"] == 10.0 and d.tablet["band"] == 3.0 and d.name == "cr10"
    assert d.family == "concave_round" and d.tooling == {"clearance_mm": 0.02} and d.report is None
    t = d.build()
    assert t.params["diameter"] == 10.0 and not hasattr(t, "extras")  # the tablet is geometry only
    assert d.tooling_spec.clearance_mm == 0.02 and d.report_options == ReportOptions()


def test_the_tables_are_read_only_and_the_design_hashes_by_them():
    """A new user changed ``m.design.tablet["diameter"]`` in place: the model's volume stayed at the old
    tablet and ``m.replace(band=2)`` (the same band) built a 20 mm one; ``hash(design)`` raised."""
    import pickle

    import tabletcad

    m = tabletcad.make("concave_round", diameter=10.0, band=2.0, cup_depth=1.0,
                       tooling={"score": [{"depth_mm": 0.3}]})
    d = m.design
    for change in (lambda: d.tablet.__setitem__("diameter", 20.0), lambda: d.tablet.update(diameter=20.0),
                   lambda: d.tablet.pop("band"), lambda: d.tooling["score"].append({}),
                   lambda: d.tooling["score"][0].__setitem__("depth_mm", 9.0)):
        with pytest.raises(TypeError, match="read-only"):
            change()
    assert d.tablet["diameter"] == 10.0 and m.replace(band=2.0).volume == pytest.approx(m.volume, rel=1e-12)
    copy = d.to_dict()  # plain, changeable copies
    copy["tablet"]["diameter"] = 11.0
    copy["tooling"]["score"].append({"depth_mm": 0.2, "direction_deg": 90.0})
    assert type(copy["tablet"]) is dict and type(copy["tooling"]["score"]) is list
    assert Design.from_dict(copy).tablet["diameter"] == 11.0 and d.tablet["diameter"] == 10.0
    same = Design.from_dict({"tooling": d.to_dict()["tooling"], "tablet": dict(reversed(list(d.tablet.items())))})
    assert same == d and hash(same) == hash(d) and len({d, same, Design.from_dict(copy)}) == 2
    # equal designs hash alike whatever the numbers' types and zeros' signs (a review: 10 against 10.0)
    ints = Design.from_dict({"tablet": {"family": "concave_round", "diameter": 10, "band": 2, "cup_depth": 1},
                             "trim": {"v": [-0.0, 3.0]}})
    floats = Design.from_dict({"tablet": {"family": "concave_round", "diameter": 10.0, "band": 2.0, "cup_depth": 1.0},
                               "trim": {"v": [0.0, 3.0]}})
    assert ints == floats and hash(ints) == hash(floats) and len({ints, floats}) == 1
    import copy as copying

    for dup in (copying.copy(d), copying.deepcopy(d)):  # a copy is the same read-only value
        assert dup == d
        with pytest.raises(TypeError, match="read-only"):
            dup.tablet["diameter"] = 12.0
    back = pickle.loads(pickle.dumps(d))  # (sweeps send designs to their workers)
    assert back == d and isinstance(back.tablet, dict) and back.build().volume() == pytest.approx(m.volume, rel=1e-15)
    with pytest.raises(TypeError, match="read-only"):
        back.tablet["band"] = 1.0


def test_an_old_family_name_is_read_as_the_new_one():
    with pytest.warns(FutureWarning):
        d = Design.from_dict({"tablet": {"family": "spherical", "diameter": 5.0}})
    assert d.family == "thesis.spherical" and "thesis.spherical" in d.to_toml()


def test_checks_before_geometry_name_the_parameter():
    with pytest.raises(DesignError) as e:
        Design.from_dict({"tablet": {"family": "capsule"}, "colour": {}})
    assert e.value.parameter == "colour"
    with pytest.raises(DesignError) as e:
        Design.from_dict({"tablet": {"family": "no_such"}})
    assert e.value.parameter == "tablet.family"
    d = Design.from_dict({"tablet": {"family": "capsule", "length": "long"}})  # dimensions: checked by build
    with pytest.raises(DesignError) as e:
        d.build()
    assert e.value.parameter == "tablet.length"


def test_family_design_text_is_the_one_writer():
    text = design_to_toml("concave_round", {"diameter": 9.5, "band": 2.8, "cup_depth": 0.9}, name="opt")
    assert text == '[tablet]\nname = "opt"\nfamily = "concave_round"\ndiameter = 9.5\nband = 2.8\ncup_depth = 0.9\n'
    assert Design.from_dict(tomllib.loads(text)).build().params["diameter"] == 9.5


_keys = st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=8)
_scalars = st.one_of(
    st.booleans(), st.integers(-(2**63), 2**63 - 1), st.floats(allow_nan=False),
    st.text(st.characters(blacklist_categories=("Cs",)), max_size=12),
    # TOML's dates and times (a drawing's unquoted date = 2026-12-01), local and at an offset
    st.dates(), st.times(), st.datetimes(), st.datetimes(timezones=st.just(datetime.timezone.utc)))
_values = st.recursive(_scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                         st.dictionaries(_keys, inner, max_size=3)), max_leaves=12)
_tables = st.dictionaries(_keys, _values, max_size=4)


@given(st.dictionaries(_keys, st.one_of(_tables, st.lists(_tables, min_size=1, max_size=3), _values), max_size=4))
def test_toml_text_round_trips_through_tomllib(data):
    assert tomllib.loads(toml_text(data)) == data


def test_non_finite_numbers_are_written_as_toml_special_floats():
    back = tomllib.loads(toml_text({"t": {"a": math.inf, "b": -math.inf, "c": math.nan}}))
    assert back["t"]["a"] == math.inf and back["t"]["b"] == -math.inf and math.isnan(back["t"]["c"])


def test_a_design_made_directly_is_checked_when_built():
    with pytest.warns(FutureWarning):
        t = Design({"family": "spherical", "diameter": 5.0}).build()
    assert t.family == "thesis.spherical" and t.name == "tablet"
    with pytest.raises(DesignError) as e:
        Design({"family": "no_such", "name": "x"}).build()
    assert e.value.parameter == "tablet.family"


def test_writer_takes_numpy_scalars_and_refuses_what_toml_cannot_hold():
    import numpy as np

    text = toml_text({"tablet": {"d": np.float64(1.5), "n": np.int64(3)}}, comment="made by\x00 a test\x7f")
    assert tomllib.loads(text) == {"tablet": {"d": 1.5, "n": 3}}
    with pytest.raises(DesignError):
        toml_text({"tablet": {1: 2.0}})
    with pytest.raises(DesignError):
        toml_text({"tablet": {"x": object()}})


def test_an_emboss_svg_is_found_beside_the_design_file(tmp_path, monkeypatch):
    """A relative svg path starts in the design file's folder, whatever the current folder; the file
    keeps the relative name (the design round-trips unchanged)."""
    folder = tmp_path / "designs"
    folder.mkdir()
    (folder / "logo.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg"><rect width="1" height="1"/></svg>')
    text = ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.0\ncup_depth = 0.8\n\n'
            '[[tooling.emboss]]\nsvg = "logo.svg"\nheight_mm = 3.0\n')
    (folder / "d.toml").write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    d = Design.from_toml(folder / "d.toml")
    assert d.tooling_spec.emboss[0].svg == str(folder / "logo.svg")
    assert d.tooling["emboss"][0]["svg"] == "logo.svg" and Design.from_dict(d.to_dict(), folder=folder) == d
    (folder / "logo.svg").unlink()
    with pytest.raises(DesignError, match=r"svg = 'logo.svg' is not allowed: .*relative paths start in the design's folder"):
        Design.from_toml(folder / "d.toml")


def test_a_boxs_corners_and_size_compute_as_build123d_vectors():
    """``bounding_box()``'s ``min``, ``max``, ``size`` and ``center()`` read as build123d's ``Vector`` and now compute
    as it does: a tuple's ``+`` had joined two of them into a 6-tuple, its ``*`` repeated them, ``max - min`` was a
    TypeError.  They stay tuples otherwise (unpacking, equality)."""
    import tabletcad

    bb = tabletcad.make("flat_face_round", diameter=10.0, thickness=4.0).bounding_box()
    size = bb.max - bb.min
    assert size == bb.size and tuple(size) == pytest.approx((10.0, 10.0, 4.0), rel=1e-9)
    assert tuple(bb.size * 2) == tuple(2 * bb.size) == pytest.approx((20.0, 20.0, 8.0), rel=1e-9)
    assert tuple(bb.size / 2) == pytest.approx((5.0, 5.0, 2.0), rel=1e-9)
    assert tuple(bb.center() + (1, 0, 0)) == pytest.approx((1.0, 0.0, 2.0), abs=1e-9)
    assert tuple((0, 0, 1) - bb.center()) == pytest.approx((0.0, 0.0, -1.0), abs=1e-9)
    assert tuple(-bb.max) == tuple(-x for x in bb.max)
    assert size.length == pytest.approx(bb.diagonal, rel=1e-15) == pytest.approx(math.sqrt(216.0), rel=1e-9)
    x, y, z = bb.size
    assert (x, y, z) == bb.size and bb.size[2] == bb.size.Z
    with pytest.raises(TypeError):
        bb.size + (1.0, 2.0)  # (not a 3-vector)
    with pytest.raises(TypeError):
        bb.size * bb.size  # (build123d's * of two vectors is a dot product; here neither is guessed)


@pytest.mark.parametrize("name", ["x.png", "x.svg", "x.pdf", "x.PNG"])
def test_a_picture_is_written_in_the_format_its_name_asks_for(tmp_path, name):
    """``plot_tablet(m, "x.pdf")`` had written PNG bytes under any name; PNG, SVG and PDF are written as named."""
    import tabletcad
    from tabletcad.pipeline.plot import plot_tablet, plot_tablets

    m = tabletcad.make("flat_face_round", diameter=10.0, thickness=4.0)
    magic = {".png": b"\x89PNG", ".svg": b"<?xml", ".pdf": b"%PDF"}[Path(name).suffix.lower()]
    assert plot_tablet(m.tablet, tmp_path / name).read_bytes().startswith(magic)
    assert plot_tablets([m, m], tmp_path / f"two{Path(name).suffix}").read_bytes().startswith(magic)


def test_a_picture_under_another_suffix_is_refused_and_nothing_is_written(tmp_path):
    import tabletcad
    from tabletcad.pipeline.plot import plot_tablet

    with pytest.raises(DesignError, match=r"^path = '.*x\.jpg' is not allowed: must end in \.png, \.svg or \.pdf$"):
        plot_tablet(tabletcad.make("flat_face_round", diameter=10.0, thickness=4.0).tablet, tmp_path / "x.jpg")
    assert list(tmp_path.iterdir()) == []


def test_an_outline_point_with_a_third_coordinate_is_refused():
    """The outline lies in the plan: a segment's point [x, y, z] had been read as [x, y], its z dropped in silence
    (the same 229.25 mm³ as the plan's)."""
    import tabletcad

    half = math.pi
    segs = [["line", [-2.5, -3.5, 7.0], [2.5, -3.5]], ["arc", [2.5, 0.0], 3.5, -half / 2, half],
            ["line", [2.5, 3.5], [-2.5, 3.5]], ["arc", [-2.5, 0.0], 3.5, half / 2, half]]
    with pytest.raises(DesignError, match=r"^tablet\.segments\[0\]\[1\] = \[-2.5, -3.5, 7.0\] is not allowed: must be a point "):
        tabletcad.make("custom_outline", segments=segs, band=2.0, cup_depth=0.5)
    segs[0][1] = [-2.5, -3.5]
    segs[2][2] = [-2.5, 3.5, 0.0, 1.0]
    with pytest.raises(DesignError, match=r"segments\[2\]\[2\] = \[-2.5, 3.5, 0.0, 1.0\] is not allowed"):
        tabletcad.make("custom_outline", segments=segs, band=2.0, cup_depth=0.5)
    segs[2][2] = [-2.5, 3.5]
    assert tabletcad.make("custom_outline", segments=segs, band=2.0, cup_depth=0.5).tablet.volume() > 0.0
