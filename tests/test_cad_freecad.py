"""FreeCAD (its own Python and OCCT) reads our STEP and rebuilds our B-spline data, under each
FreeCAD (Debian's 0.20 and 1.0 from the .ci/freecad1 root, ``tests/freecads.py``).

Each FreeCAD reads the three stand-ins' STEP files and rebuilds their surfaces in one ``freecadcmd``
process (:func:`support.readback.freecad_batch`; twelve processes had each started FreeCAD for one of
them), and each STEP file is written once for both FreeCADs."""


import numpy as np
import pytest



pytest.importorskip("OCP")

from tabletcad.cad.export import export  # noqa: E402
import freecads  # noqa: E402
from support.readback import freecad_batch  # noqa: E402
from tabletcad.cad.solid import build_solid, mass_properties  # noqa: E402
from support.standins import cylinder, ring, sphere  # noqa: E402

pytestmark = [pytest.mark.cad, pytest.mark.freecad]


@pytest.fixture(scope="module", params=freecads.params())
def fc(request) -> freecads.FreeCADInstall:
    return request.param

STANDINS = [sphere(2.5), cylinder(2.5, 3.0), ring(1.5, 3.0, 2.0)]



#: the (u, v) the rebuilt surfaces are evaluated at
_RNG = np.random.default_rng(3)
U, V = _RNG.random(40), _RNG.random(40) * 2 * np.pi


@pytest.fixture(scope="module")
def solids(tmp_path_factory) -> dict:
    """Each stand-in, its solid and its STEP file (built and written once for both FreeCADs)."""
    out = {}
    for k, s in enumerate(STANDINS):
        ts = build_solid(s.patches, 1e-4, name=s.name.replace(" ", "_"))
        out[s.name] = (s, ts, export(ts, tmp_path_factory.mktemp(f"standin{k}") / "p.step"))
    return out


@pytest.fixture(scope="module", params=STANDINS, ids=lambda s: s.name)
def built(request, solids):
    s, ts, _ = solids[request.param.name]
    return s, ts


@pytest.fixture(scope="module")
def freecad_results(solids):
    """``results(fc)``: ``{stand-in name: (read_step's result, build_bspline's result)}`` of that FreeCAD,
    from one ``freecadcmd`` process per FreeCAD (asked once each, whatever order the tests run in)."""
    cache: dict = {}

    def results(fc: freecads.FreeCADInstall) -> dict:
        if fc.version not in cache:
            names = list(solids)
            read, rebuilt = freecad_batch([solids[n][2] for n in names],
                                          [(solids[n][1].surfaces, U, V) for n in names], freecadcmd=fc.cmd)
            cache[fc.version] = {n: (r, b) for n, r, b in zip(names, read, rebuilt)}
        return cache[fc.version]

    return results


def test_freecad_reads_step(fc, built, freecad_results):
    s, ts = built
    r = freecad_results(fc)[s.name][0]
    assert r["n_solids"] == 1 and r["valid"] and r["solids_valid"] == [True] and r["solids_closed"] == [True]
    assert r["labels"] == [ts.name]
    # FreeCAD's Shape.Volume is OCCT's *default* integration: identical to ours with
    # eps=None, and within ~1e-3 relative of the adaptive (accurate) value.
    assert r["volume"] == pytest.approx(mass_properties(ts.shape, eps=None).volume, rel=1e-9)
    assert r["volume"] == pytest.approx(ts.volume, rel=1e-3)


def test_build_from_poles_mults_knots_is_the_same_surface(fc, built, freecad_results):
    s, ts = built
    u, v = U, V
    r = freecad_results(fc)[s.name][1]
    for k, surf in enumerate(ts.surfaces):
        np.testing.assert_allclose(np.array(r["values"][k]), surf.evaluate(u, v), atol=1e-13)
        back = r["readback"][k]
        np.testing.assert_array_equal(np.array(back["poles"]), surf.poles)
        np.testing.assert_array_equal(back["u_knots"], surf.u_knots)
        np.testing.assert_array_equal(back["v_mults"], surf.v_mults)
        assert back["v_periodic"] and not back["u_periodic"]
    assert all(r["faces_valid"]) and r["n_shells"] == 1 and r["shell_closed"] and r["valid"]
    # same faces -> same (default-integration) volume in FreeCAD's OCCT and in OCP (the B-spline faces sewn
    # here: ts.shape's flat caps are planes, tabletcad.cad.planes)
    from tabletcad.cad.faces import face_of, make_geom_surface
    from tabletcad.cad.solid import _make_solid, sew_faces

    names = [f"s{k}" for k in range(len(ts.surfaces))]
    shell = sew_faces([face_of(make_geom_surface(s)) for s in ts.surfaces], names, ts.sew_tolerance)
    same = _make_solid(shell, "same faces", float("nan"))
    assert r["volume"] == pytest.approx(mass_properties(same, eps=None).volume, rel=1e-12)
