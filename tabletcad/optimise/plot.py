"""Convergence picture of an optimisation run (``convergence.png``)."""

from __future__ import annotations

from pathlib import Path

from tabletcad.io.figures import save_figure
from tabletcad.optimise.problem import Result

__all__ = ["plot_convergence"]


def plot_convergence(result: Result, path: str | Path, *, dpi: int = 120) -> Path:
    """Objective and worst constraint violation per iteration, on two stacked axes.

    The violation is each constraint's violation divided by its solver scale
    (dimensionless), on a log axis; exact zeros are drawn at 1e-16.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    it = [h.iteration for h in result.history]
    obj = [h.objective for h in result.history]
    viol = [max(h.max_violation, 1e-16) for h in result.history]
    fig = Figure(figsize=(6.4, 5.6))
    FigureCanvasAgg(fig)  # its own canvas: the global backend is left alone
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    unit = f" ({result.objective_unit})" if result.objective_unit else ""
    ax1.plot(it, obj, "o-", color="tab:blue", ms=3)
    ax1.set_ylabel(f"{result.objective_name}{unit}")
    ax1.grid(True, alpha=0.3)
    # (no wall time: it is report.json's wall_time_s; the picture is the same for the same run)
    ax1.set_title(f"{result.problem}: {result.method}, {result.status} "
                  f"({result.iterations} it., {result.nfev} builds)", fontsize=9)
    ax2.semilogy(it, viol, "s-", color="tab:red", ms=3)
    ax2.axhline(1e-6, color="0.5", ls="--", lw=0.8, label="tolerance 1e-6")
    ax2.set_ylabel("max constraint violation (scaled, -)")
    ax2.set_xlabel("iteration (-)")
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    return save_figure(fig, Path(path), fmt="png", dpi=dpi)
