"""JSON documents as strict JSON (RFC 8259): numpy values as Python ones, a non-finite number as null.

One writer for the geometry report (``report.json``) and the commands' ``--json`` documents (mechanics,
FE): Python's ``json`` writes ``Infinity`` and ``NaN``, which strict readers refuse (a Heckel fit with a
slope of 0 had printed ``"Py_MPa": Infinity``).
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

__all__ = ["json_text", "plain"]


def plain(o: Any) -> Any:
    """``o`` as JSON can hold it: dicts and sequences (tuples, numpy arrays) as dicts and lists, numpy
    scalars as Python ones, a non-finite number as None; anything else as it is."""
    if isinstance(o, dict):
        return {k: plain(v) for k, v in o.items()}
    if isinstance(o, (list, tuple, np.ndarray)):
        return [plain(v) for v in (o.tolist() if isinstance(o, np.ndarray) else o)]
    if isinstance(o, (np.bool_, bool)):
        return bool(o)
    if isinstance(o, (np.integer, int)):
        return int(o)
    if isinstance(o, (np.floating, float)):
        return float(o) if math.isfinite(o) else None
    return o


def json_text(payload: Any) -> str:
    """``payload`` as strict JSON text, indented by 2 (no final newline)."""
    return json.dumps(plain(payload), indent=2, allow_nan=False)
