"""Shared fixtures and settings for the tabletcad test suite.

Hypothesis: the ``tabletcad`` profile (loaded by default, override with the
``HYPOTHESIS_PROFILE`` environment variable) is derandomized and has no
deadline, so property-based tests give the same examples on every machine and
in CI.  Individual tests still set their own (small) ``max_examples``.

Core helpers (used by ``tests/test_core_*.py``) are exposed through the
session fixture :func:`kit`:

* ``TrigCurve``: a band-limited closed curve given by its Fourier coefficients,
  with exact derivatives (the patch's truncated series represents it exactly);
* ``ReversedCurve``: ``c(-v)``, the same point set traversed the other way;
* ``rotz(theta)``: the 3×3 rotation about the z axis;
* ``rebuild(tablet, fn)``: the same tablet with every boundary curve replaced
  by ``fn(curve)`` (shared curves stay shared: ``fn`` is applied once per
  object);
* ``gauss_area(patch, nu, nv)``: the area of a patch by our own tensor
  Gauss-Legendre/trapezoid rule, independent of :class:`~tabletcad.geometry.tablet.Tablet`.
"""

from __future__ import annotations

import math
import os
from types import SimpleNamespace

import numpy as np
import pytest

# --------------------------------------------------------------------------- CI: no skips
# In CI (the environment variable CI is set, as .ci/run does) nothing may be skipped:
# a missing library, freecadcmd or display is a failure there, whatever the test's own
# guard says.  Locally a skip stays a skip.
_CI = bool(os.environ.get("CI"))


def _fail_skip_in_ci(report) -> None:
    if _CI and report.skipped and not hasattr(report, "wasxfail"):
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
        report.outcome = "failed"
        report.longrepr = f"skipped in CI, which must run every test: {reason}"


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    _fail_skip_in_ci(outcome.get_result())


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    outcome = yield
    _fail_skip_in_ci(outcome.get_result())

# --------------------------------------------------------------------------- signal handlers
# A test (or a library it starts: gmsh's initialize sets SIGINT to SIG_DFL and never puts it back, a
# Jupyter client restores Python's handler) that leaves SIGINT or SIGTERM handled otherwise, or blocked
# in the main thread, changes what the Ctrl-C tests run after it in the same worker process see, which
# depends on the files xdist gave that worker: the state is put right and the test that left it fails.
_HELD_SIGNALS = ("SIGINT", "SIGTERM")


def _ctrl_c_as_at_a_terminal() -> None:
    """Python's own Ctrl-C handler, whoever started pytest: a shell starts a background job (``cmd &``,
    as the fresh-clone runs are started) with SIGINT ignored, and Python then keeps it ignored, so the
    Ctrl-C tests passed or failed with the worker that ran them (a Jupyter kernel client, run by an
    earlier test in the same worker, put Python's handler back)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread() and signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


_ctrl_c_as_at_a_terminal()


#: the handlers and main-thread signal mask this worker process started its tests with, and the last test run
_SIGNAL_STATE: dict = {}


def _signal_state():
    import signal

    return ({s: signal.getsignal(getattr(signal, s)) for s in _HELD_SIGNALS},
            frozenset(signal.pthread_sigmask(signal.SIG_BLOCK, [])))


def _restore_signal_state(state) -> None:
    import signal

    handlers, mask = state
    for s, handler in handlers.items():
        signal.signal(getattr(signal, s), handler)
    signal.pthread_sigmask(signal.SIG_SETMASK, mask)


@pytest.fixture(autouse=True)
def _signal_handlers_restored(request):
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    start = _SIGNAL_STATE.setdefault("start", _signal_state())
    found = _signal_state()
    if found != start:  # changed outside any test: a module- or session-scoped fixture, a module's import
        _restore_signal_state(start)
        raise AssertionError(f"signal handlers or mask changed since the worker's first test, after "
                             f"{_SIGNAL_STATE.get('last')}: {found} (was {start})")
    yield
    _SIGNAL_STATE["last"] = request.node.nodeid
    left = _signal_state()
    if left != start:
        _restore_signal_state(start)
        raise AssertionError(f"the test left signal handlers or mask changed: {left} (was {start})")


# --------------------------------------------------------------------------- core-only run
# .ci/test runs the suite a second time in .venv-oldest (the oldest numpy/scipy pyproject
# claims, no CAD, FE or Dask library) with TABLETCAD_CORE_ONLY=1: files whose module-level
# ``pytestmark`` names the cad, freecad, fe, sweep or tables marker are not collected, and tests so
# marked are deselected.  Everything else must pass there too.
_CORE_ONLY = bool(os.environ.get("TABLETCAD_CORE_ONLY"))
_CAD_MARKS = ("cad", "freecad", "fe", "sweep", "tables")


def _file_needs_cad(path) -> bool:
    import re

    text = path.read_text(encoding="utf-8")
    m = re.search(r"^pytestmark\s*=\s*(.+)$", text, re.MULTILINE)
    return bool(m) and any(f"mark.{name}" in m.group(1) for name in _CAD_MARKS)


def pytest_ignore_collect(collection_path, config):
    if _CORE_ONLY and collection_path.suffix == ".py" and collection_path.name.startswith("test_"):
        return _file_needs_cad(collection_path) or None
    return None


def pytest_collection_modifyitems(config, items):
    if not _CORE_ONLY:
        return
    keep, drop = [], []
    for item in items:
        (drop if any(item.get_closest_marker(m) for m in _CAD_MARKS) else keep).append(item)
    if drop:
        config.hook.pytest_deselected(items=drop)
        items[:] = keep


try:  # hypothesis is a test dependency, but keep collection working without it
    from hypothesis import HealthCheck, settings

    settings.register_profile(
        "tabletcad",
        deadline=None,
        derandomize=True,
        print_blob=True,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
    )
    settings.register_profile("tabletcad-dev", deadline=None, max_examples=200)
    settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "tabletcad"))
except ImportError:  # pragma: no cover
    pass


TWO_PI = 2.0 * math.pi


class TrigCurve:
    """``c(v) = a0 + Σ_{n=1}^{N} (a[n-1] cos nv + b[n-1] sin nv)`` (mm), exact derivatives."""

    def __init__(self, a0, a=(), b=()) -> None:
        self.a0 = np.asarray(a0, dtype=float).reshape(3)
        self.a = np.asarray(a, dtype=float).reshape(-1, 3)
        self.b = np.asarray(b, dtype=float).reshape(-1, 3)
        if self.a.shape != self.b.shape:
            raise ValueError("a and b must have the same number of modes")

    @property
    def modes(self) -> int:
        return self.a.shape[0]

    def evaluate(self, v, der: int = 0) -> np.ndarray:
        v = np.asarray(v, dtype=float).reshape(-1)
        out = np.zeros((v.size, 3))
        if der == 0:
            out += self.a0
        for k in range(self.modes):
            n = k + 1
            c, s = np.cos(n * v), np.sin(n * v)
            # d^der/dv^der of cos and sin
            dc, ds = [(c, s), (-s, c), (-c, -s), (s, -c)][der % 4]
            f = float(n) ** der
            out += f * (np.outer(dc, self.a[k]) + np.outer(ds, self.b[k]))
        return out

    def __call__(self, v):
        return self.evaluate(v)


class ReversedCurve:
    """The curve ``c(-v)``: same points, opposite direction of travel."""

    def __init__(self, base) -> None:
        self.base = base

    def evaluate(self, v, der: int = 0) -> np.ndarray:
        v = np.asarray(v, dtype=float).reshape(-1)
        return self.base.evaluate(-v, der) * (-1.0) ** der


def rotz(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rebuild(tablet, fn, **patch_kw):
    """``tablet`` with each boundary curve ``c`` replaced by ``fn(c)`` (same a, nodes, form, trim)."""
    from dataclasses import replace

    from tabletcad.geometry.patch import PDEPatch

    memo: dict[int, object] = {}

    def once(c):
        if id(c) not in memo:
            memo[id(c)] = fn(c)
        return memo[id(c)]

    patches = []
    for p in tablet.patches:
        kw = dict(a=p.a, u_nodes=p.u_nodes, form=p.form, tol=p.tol, name=p.name)
        kw.update(patch_kw)
        patches.append(PDEPatch(tuple(once(c) for c in p.data), **kw))
    return replace(tablet, patches=tuple(patches))


def gauss_area(patch, nu: int = 48, nv: int = 256) -> float:
    """∫∫ |X_u × X_v| du dv by Gauss-Legendre in u and the trapezoidal rule in v."""
    x, w = np.polynomial.legendre.leggauss(nu)
    u = 0.5 * (x + 1.0)
    wu = 0.5 * w
    v = np.arange(nv) * (TWO_PI / nv)
    n = np.cross(patch.evaluate_grid(u, v, du=1), patch.evaluate_grid(u, v, dv=1))
    return float(np.sum(wu[:, None] * np.linalg.norm(n, axis=-1)) * (TWO_PI / nv))


@pytest.fixture(scope="session")
def kit():
    """Helper classes and functions for the core tests (see module docstring)."""
    return SimpleNamespace(
        TrigCurve=TrigCurve, ReversedCurve=ReversedCurve, rotz=rotz, rebuild=rebuild, gauss_area=gauss_area
    )


@pytest.fixture(scope="session")
def family_tablet():
    """``family_tablet(name)``: the default tablet of a thesis shape (``tabletcad.families.thesis.THESIS_SHAPES``),
    built once per session."""
    from tabletcad.families.thesis import THESIS_SHAPES

    cache: dict[str, object] = {}

    def get(name: str):
        if name not in cache:
            cache[name] = THESIS_SHAPES[name].build()
        return cache[name]

    return get
