"""Models compare as values (a scripting user's trial, session 33: two identical ``make`` calls gave unequal
models with different hashes, while their designs were equal)."""

import copy
import pickle

import tabletcad


def test_models_of_equal_designs_are_equal_and_hash_alike(tmp_path):
    kw = dict(length=14, width=8, end_radius=3, band=3, cup_depth=1)
    m = tabletcad.make("oval", **kw)
    m2 = tabletcad.make("oval", **dict(kw, cup_depth=1.0))  # 1 and 1.0 are one value, as in a design
    assert m == m2 and hash(m) == hash(m2) and len({m, m2}) == 1
    assert m == m.replace() and m != m.replace(band=3.1)
    assert pickle.loads(pickle.dumps(m)) == m and copy.deepcopy(m) == m
    bare = tabletcad.TabletModel(m.tablet)  # no design: equal only to itself
    assert bare == bare and bare != m and bare != tabletcad.TabletModel(m.tablet)
    assert m != m.tablet and (m == "oval") is False


def test_equal_tables_from_other_folders_are_other_models(tmp_path):
    """A design file's relative paths (an outline's points file) are read from its folder: equal tables in two
    folders may be two tablets."""
    text = '[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 3.0\ncup_depth = 1.0\n'
    for d in ("a", "b"):
        (tmp_path / d).mkdir()
        (tmp_path / d / "t.toml").write_text(text)
    a, b = (tabletcad.load(tmp_path / d / "t.toml") for d in ("a", "b"))
    assert a.design == b.design and a != b
    assert a == tabletcad.load(tmp_path / "a" / "t.toml")
