"""Errors raised by tabletcad.

Bad input raises :class:`DesignError` (a :class:`ValueError`) whose message is
one line naming the parameter, its value and the allowed range, e.g.
``diameter = -1 mm is not allowed: must be > 0``.  Domain failures that are
not the user's input (a fit that misses its tolerance, a sewing that leaves
free edges) raise :class:`GeometryError`, which carries the object that failed.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from typing import Any

__all__ = [
    "run_interruptibly",
    "TabletcadError",
    "DesignError",
    "GeometryError",
    "check_finite",
    "check_positive",
    "check_range",
    "format_bound",
    "is_number",
    "one_token",
    "reraise_interrupt",
]


def run_interruptibly(fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
    """``fn(*args, **kwargs)`` in a helper thread while the main thread waits on it, so that a Ctrl-C
    (or SIGTERM) is acted on at once.

    A long call into compiled code that releases the GIL (SuperLU's factorisation of an FE system:
    minutes on a fine mesh) keeps Python's signal handlers from running until it returns when it
    runs in the main thread; waiting on a thread instead, the main thread raises the interrupt within
    0.1 s.  One helper thread (a daemon) serves every call of the process: a new thread per call
    leaked OpenBLAS's per-thread buffers, about 16 MB a call (200 factorisations: 3.4 GB, and a test
    worker's fork was refused).  An abandoned call runs on in the helper until it ends (a later call
    waits for it), so it must own everything it touches.  Called from another thread, ``fn`` simply
    runs there.
    """
    import threading

    if threading.current_thread() is not threading.main_thread():
        return fn(*args, **kwargs)
    done = threading.Event()
    out: dict[str, Any] = {}
    _helper_queue().put((fn, args, kwargs, out, done))
    while not done.wait(0.1):
        pass
    if "error" in out:
        raise out["error"]
    return out["value"]


#: ``(process id, queue)`` of :func:`run_interruptibly`'s helper thread (a forked child makes its own)
_HELPER: list = [None]


def _helper_queue():
    import os
    import queue
    import threading

    hit = _HELPER[0]
    if hit is not None and hit[0] == os.getpid():
        return hit[1]
    jobs: queue.SimpleQueue = queue.SimpleQueue()

    def serve() -> None:
        while True:
            fn, args, kwargs, out, done = jobs.get()
            try:
                out["value"] = fn(*args, **kwargs)
            except BaseException as exc:  # noqa: BLE001 - handed to the caller's thread
                out["error"] = exc
            finally:
                del fn, args, kwargs  # (nothing of a finished call kept alive by this frame)
                done.set()

    threading.Thread(target=serve, name="tabletcad-helper", daemon=True).start()
    _HELPER[0] = (os.getpid(), jobs)
    return jobs


def reraise_interrupt(exc: BaseException) -> None:
    """Raise :class:`KeyboardInterrupt` (or the :class:`SystemExit` of a SIGTERM) if ``exc`` was
    caused by one.

    A Ctrl-C while an extension module initialises (OCP, gmsh) surfaces as
    ``ImportError: initialization failed`` caused by the KeyboardInterrupt;
    so does a SIGTERM, whose handler raises SystemExit (see
    :mod:`tabletcad.io.outputs`); code that treats an ImportError as
    "optional library absent" must not swallow the user's interrupt.
    """
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            raise KeyboardInterrupt from exc
        if isinstance(e, SystemExit) and e is not exc:
            raise SystemExit(e.code) from exc
        seen.add(id(e))
        e = e.__cause__ or e.__context__


class TabletcadError(Exception):
    """Base class of every error tabletcad raises on purpose."""


class DesignError(TabletcadError, ValueError):
    """Invalid user input: the message names the parameter, value and allowed range."""

    def __init__(self, parameter: str, value: Any, allowed: str, unit: str = "") -> None:
        self.parameter = one_token(parameter)
        self.value = value
        self.allowed = allowed
        self.unit = unit
        shown = _fmt(value)
        if unit and is_number(value) and not shown.startswith("an integer of"):  # not after text ('10 mm'), true/false, a list or None
            shown = f"{shown} {unit}"
        super().__init__(f"{self.parameter} = {shown} is not allowed: {allowed}")

    def __reduce__(self):  # pickled with its own arguments (a forked helper sends it back to the parent)
        return DesignError, (self.parameter, self.value, self.allowed, self.unit)

    def renamed(self, parameter: str) -> "DesignError":
        """The same error for another parameter name (e.g. with the design-file table it came from)."""
        return DesignError(parameter, self.value, self.allowed, self.unit)


class GeometryError(TabletcadError):
    """A geometric construction failed; ``obj`` is what failed (patch, face, shell...)."""

    def __init__(self, message: str, obj: Any = None) -> None:
        self.obj = obj
        super().__init__(message)

    def __reduce__(self):  # pickled without ``obj`` (an OCC shape cannot be): its message stays
        return GeometryError, (str(self),)


_WORD = re.compile(r"""'(?:[^'\\]|\\.)*'|"(?:[^"\\]|\\.)*"|\S+""")  # a quoted name (maybe a repr) or a word
_HEADER = re.compile(r"^\[\[?([^\[\]]+)\]\]?(.*)$")  # [table] or [[array]], maybe followed by .key
_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _quoted(word: str) -> str:
    """A quoted name (a Python ``repr`` or a plain quote) as a TOML key: bare if it can be, else in
    double quotes with backslash, quote, whitespace and control characters escaped (one token)."""
    import ast

    try:
        name = ast.literal_eval(word)
    except (ValueError, SyntaxError):
        name = word[1:-1]
    name = str(name)
    if _BARE_KEY.match(name):
        return name
    return '"' + "".join("\\\\" if c == "\\" else '\\"' if c == '"' else
                         f"\\u{ord(c):04X}" if c.isspace() or not c.isprintable() else c for c in name) + '"'


def one_token(parameter: str) -> str:
    """``parameter`` as one token, the key path of the design file, as the one-line error format
    ``error: <parameter> = <value> is not allowed: <range>`` shows it: table headers lose their
    brackets (an index after them goes in brackets), words join with ``.``, a number after a name
    becomes its index, and a quoted name is a bare key if it can be, else a TOML quoted key with its
    whitespace escaped (``[[tooling.score]] 0 depth_mm`` -> ``tooling.score[0].depth_mm``,
    ``[report] key 'weight'`` -> ``report.weight``, ``[sweep.vary] 'tablet.diameter' max`` ->
    ``sweep.vary."tablet.diameter".max``).  A token (``tablet.diameter``, ``patch[0].a``,
    ``--nodes``, ``v1.2``) is kept."""
    text = str(parameter).strip()
    if text.startswith("-"):  # a command-line option
        return text
    words = _WORD.findall(text)
    out: list[str] = []
    i = 0
    while i < len(words):
        w = words[i]
        if w in ("key", "item", "top-level") and i + 1 < len(words):  # "key 'name'", "item 3": the name, the index
            i += 1
            w = words[i]
            if w == "key" and i + 1 < len(words):  # "top-level key 'name'"
                i += 1
                w = words[i]
        header = _HEADER.match(w)
        if header:  # [[tooling.emboss]].0.stroke_angle_deg -> tooling.emboss[0].stroke_angle_deg
            w = header.group(1) + re.sub(r"\.(\d+)(?=[.\[]|$)", r"[\1]", header.group(2))
        elif len(w) >= 2 and w[0] in "'\"" and w[-1] == w[0]:
            w = _quoted(w)
        if w.isdigit() and out:
            out[-1] += f"[{w}]"
        elif w:
            out.append(w.lstrip(".") if out else w)
        i += 1
    return ".".join(out) or "?"


def is_number(value: Any) -> bool:
    """Whether ``value`` is a real number that a unit can follow (an int, float, numpy scalar,
    ``Fraction`` or ``Decimal``; never a boolean)."""
    import decimal
    import numbers

    return isinstance(value, (numbers.Real, decimal.Decimal)) and not isinstance(value, bool) and \
        type(value).__name__ != "bool_"


class _Missing(str):
    """The value of a parameter that was not given (:data:`MISSING`): equal to ``"missing"`` for code
    that compares, shown as ``(not given)`` in a refusal, not as a value the user could have typed."""

    __slots__ = ()

    def __repr__(self) -> str:
        return "(not given)"


#: the :class:`DesignError` value of a parameter that was not given
MISSING = _Missing("missing")


def _fmt(value: Any) -> str:
    if isinstance(value, _Missing):
        return "(not given)"
    if isinstance(value, bool):
        return "true" if value else "false"  # as TOML writes them
    if isinstance(value, float):
        return _short(value)
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**15:
        digits = int(value.bit_length() * math.log10(2))  # str() of a huge int may be refused
        digits += 10**digits <= abs(value)
        if digits <= 40:  # as given (--nodes 99999999999999999999, not 1e+20)
            return str(value)
        return f"{value:.6g}" if digits < 300 else f"an integer of {digits} digits"
    if isinstance(value, str):  # as given: its repr is one line (line breaks and control characters escaped)
        text = repr(value)  # (its spaces kept: text = "   " had been shown as ' ')
    else:
        text = " ".join(str(value).split())  # one line, whatever the value holds
    # whole up to 200 characters (a path in a temporary or nested folder), else its start and end
    return text if len(text) <= 200 else f"{text[:150]}...{text[-40:]}"


def _short(x: float) -> str:
    """``x`` to 6 significant digits, or as typed when those change it (1000.001, not 1000, refused
    by a limit of 1000) and it has at most 12 (a computed value keeps 6)."""
    for n in range(6, 13):
        text = f"{x:.{n}g}"
        if float(text) == x:
            return text
    return f"{x:.6g}"


def format_bound(x: float, upper: bool, digits: int = 6) -> str:
    """``x`` as the end of an allowed range in a refusal: exactly when at most 12 significant
    digits give it, else to ``digits`` digits rounded into the range (down for an upper end, up for
    a lower one), so that every value the stated range holds is accepted (a corner radius
    ``< 3.17543`` for a limit of 3.1754265 had refused 3.175428)."""
    text = _short(x)
    if not math.isfinite(x) or float(text) == x:
        return text
    step = 10.0 ** (math.floor(math.log10(abs(x))) - digits + 1)
    inward = math.floor(x / step) if upper else math.ceil(x / step)
    y = inward * step
    text = f"{y:.{digits}g}"
    if (float(text) > x) if upper else (float(text) < x):  # (the product's rounding)
        text = f"{(inward - 1 if upper else inward + 1) * step:.{digits}g}"
    return text


def check_finite(name: str, value: float, unit: str = "") -> float:
    """Return ``float(value)`` or raise :class:`DesignError` if it is not a finite number.

    Booleans are refused although Python's ``bool`` is a subclass of ``int``
    (a TOML ``true`` is never a length), and so are text (``"10"``) and integers too large
    for a float.
    """
    if isinstance(value, bool):
        raise DesignError(name, value, "must be a finite number, not a boolean", unit)
    if isinstance(value, (str, bytes)):  # a quoted "10" in a file, or "10" in a script: never a number here
        raise DesignError(name, value, "must be a finite number, not text", unit)
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise DesignError(name, value, "must be a finite number", unit) from None
    if not math.isfinite(x):
        raise DesignError(name, value, "must be a finite number", unit)
    return x


def check_positive(name: str, value: float, unit: str = "") -> float:
    """Return ``float(value)`` or raise unless it is finite and > 0."""
    x = check_finite(name, value, unit)
    if x <= 0.0:
        raise DesignError(name, value, "must be > 0", unit)
    return x


def check_range(
    name: str,
    value: float,
    lo: float | None = None,
    hi: float | None = None,
    unit: str = "",
    *,
    lo_open: bool = False,
    hi_open: bool = False,
) -> float:
    """Return ``float(value)`` or raise unless ``lo <=/< value <=/< hi``."""
    x = check_finite(name, value, unit)
    bad = (
        (lo is not None and (x < lo or (lo_open and x == lo)))
        or (hi is not None and (x > hi or (hi_open and x == hi)))
    )
    if bad:
        parts = []
        if lo is not None:
            parts.append(f"{'>' if lo_open else '>='} {format_bound(lo, upper=False)}")
        if hi is not None:
            parts.append(f"{'<' if hi_open else '<='} {format_bound(hi, upper=True)}")
        raise DesignError(name, value, "must be " + " and ".join(parts) + (f" {unit}" if unit else ""), unit)
    return x
