"""Reports of optimisation runs: JSON-ready dicts and one-paragraph text summaries."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from tabletcad.optimise.problem import Problem, Result

__all__ = ["result_report", "summary", "to_json"]


def _clean(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        f = float(obj)
        return f if math.isfinite(f) else (None if math.isnan(f) else ("inf" if f > 0 else "-inf"))
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def result_report(result: Result, problem: Problem | None = None) -> dict:
    """The run as a dict: objective, x, constraints with slack, iterations, builds, time, status,
    history, the problem's extra figures and, when it has one, its published reference."""
    d = result.to_dict()
    d["units"] = {"x": {v.name: v.unit for v in problem.variables}} if problem is not None else {}
    if problem is not None:
        d["description"] = problem.description
        d["bounds"] = {v.name: [v.lower, v.upper] for v in problem.variables}
        if problem.reference:
            d["reference"] = problem.reference
    return _clean(d)


def to_json(report: dict) -> str:
    return json.dumps(_clean(report), indent=2, ensure_ascii=False) + "\n"


def summary(result: Result) -> str:
    """Several lines: status, objective, variables and the active / violated constraints."""
    u = f" {result.objective_unit}" if result.objective_unit else ""
    lines = [
        f"{result.problem} [{result.method}]: {result.status}; {result.objective_name} = {result.objective:.8g}{u} "
        f"({result.iterations} iterations, {result.nfev} builds, {result.wall_time_s:.2f} s)",
        "  x: " + ", ".join(f"{k} = {v:.6g}" for k, v in result.x.items()),
    ]
    for c in result.constraints:
        flag = "ok " if c.satisfied else "FAIL"
        cu = f" {c.unit}" if c.unit else ""
        lines.append(f"  [{flag}] {c.name}: {c.value:.10g}{cu} (slack {c.slack:.3g})")
    ex = result.extras
    if isinstance(ex.get("fe_breaking_force_fine_N"), float):  # the FE optimum's re-check on the default mesh
        lines.append(f"  re-check on the default FE mesh: {ex['fe_breaking_force_fine_N']:.5g} N "
                     f"({100 * ex['fe_fine_minus_coarse_relative']:+.1f} % from the coarse mesh)")
    if not result.success:
        lines.append("  " + result.message)
    return "\n".join(lines)
