"""``tabletcad optimise PROBLEM.toml --out DIR``: design optimisation (thesis chapter 6)."""

from __future__ import annotations

from pathlib import Path

import click

from tabletcad.cli.outputs import out_folder

__all__ = ["COMMANDS"]

EXIT_FAILED = 3


class OptimisationFailed(click.ClickException):
    """The run finished without a certified feasible optimum (exit status 3): one ``error:`` line."""

    exit_code = EXIT_FAILED

    def show(self, file=None) -> None:
        click.echo(f"error: {self.format_message()}", err=True)


def raise_starts(starts: str, method: str) -> None:
    """``--starts`` with a single-start method: refused rather than ignored."""
    from tabletcad.errors import DesignError

    raise DesignError("--starts", starts, f"is read by --method multistart only (this run: {method})")


@click.command("optimise")
@click.argument("problem_file", metavar="PROBLEM.toml", type=click.Path(path_type=Path))
@click.option("--out", "out_dir", required=True, type=out_folder(), help="Output folder.")
@click.option("--method", default=None,
              help="Solver: SLSQP, trust-constr, multistart or differential_evolution (default: the file's "
                   "[problem] method, else SLSQP).")
@click.option("--starts", default=None,
              help="Sobol starts for multistart besides the initial point (integer; 0: the initial point alone).")
@click.option("--maxiter", default=None, help="Iteration limit (integer).")
@click.option("--quiet", is_flag=True, help="No progress display.")
def optimise_cmd(problem_file: Path, out_dir: Path, method: str | None, starts: str | None, maxiter: str | None,
                 quiet: bool) -> None:
    """Optimise PROBLEM.toml; write optimum.toml, report.json, convergence.png (and tablet/ outputs) to OUT.

    Exit status 0 on a converged feasible optimum, 3 when the run fails (report.json
    says which constraint failed and by how much), 2 on bad input (nothing written).
    """
    from tabletcad.optimise.files import SOLVER_KEYS, choice, load_problem
    from tabletcad.optimise.problem import METHODS

    # options are checked here (one line, exit 2) rather than by click (three lines of usage text)
    if method is not None:
        choice("--method", method, METHODS)

    problem, default_method, opts = load_problem(problem_file)
    for key, value in (("starts", starts), ("maxiter", maxiter)):
        if value is not None:  # the same limits as the file's [solver] table
            opts[key] = SOLVER_KEYS[key](f"--{key}", int(value) if value.strip().lstrip("+-").isdigit() else value)
    # the rest only once the input is known to be valid (a bad file is refused without loading them)
    from tabletcad.pipeline.design import Design
    from tabletcad.errors import TabletcadError
    from tabletcad.io.atomic import atomic_write_text
    from tabletcad.optimise.plot import plot_convergence
    from tabletcad.optimise.report import result_report, summary, to_json
    from tabletcad.optimise.solvers import solve
    from tabletcad.geometry.tablet import Tablet

    from tabletcad.io.outputs import OPTIMISE_MANIFEST, check_replaceable, publish, staging_folder

    # the folder may hold only this command's earlier, unchanged results where it writes: checked before the
    # solve (minutes for an FE problem); a build's files or anyone else's are never replaced
    from tabletcad.pipeline.build import build_outputs, cad_available

    # (the optimum's build writes what `tabletcad build` of it would: its CAD files too when it can)
    check_replaceable(out_dir, ["report.json", "convergence.png", "optimum.toml", "last_point.toml"]
                      + [f"tablet/{n}" for n in build_outputs(cad_available())], manifest=OPTIMISE_MANIFEST)
    method = method or default_method
    if starts is not None and method != "multistart":
        raise_starts(starts, method)
    build_error = ""
    result = solve(problem, method, progress=not quiet, **opts)

    with staging_folder(out_dir) as staging:  # all or nothing, on out_dir's file system; the folder's manifest
        report = result_report(result, problem)
        report["problem_file"] = str(problem_file)
        written = []
        if result.design is not None and problem.to_toml is not None:
            text = problem.to_toml(result.x, result.design)
            name = "optimum.toml" if result.success else "last_point.toml"
            atomic_write_text(staging / name, text)
            written.append(name)
            if result.success:
                # rebuild from the written file with default settings: what `tabletcad build` will see
                written_design = Design.from_toml(staging / name)
                tablet = getattr(result.design, "tablet", result.design)
                if isinstance(tablet, Tablet):
                    from tabletcad.pipeline.build import build_design

                    try:
                        rep = build_design(written_design, staging / "tablet", progress=not quiet, parallel=True)
                        report["built_design"] = dict(folder="tablet", volume_mm3=rep.get("volume_mm3"),
                                                      surface_area_mm2=rep.get("surface_area_mm2"))
                        written.append("tablet/")
                    except TabletcadError as exc:  # the optimum is reported even if an output stage fails
                        build_error = str(exc).splitlines()[0]
                        report["built_design"] = dict(error=build_error)
        plot_convergence(result, staging / "convergence.png")
        written.append("convergence.png")
        atomic_write_text(staging / "report.json", to_json(report))
        written.append("report.json")
        # printed before the files are moved into place: a refused standard output (a full disk) leaves none
        click.echo(summary(result))
        click.echo(f"-> {out_dir}/ ({', '.join(written)})")
        publish(staging, out_dir, OPTIMISE_MANIFEST)  # replaces only its earlier run's unchanged files
    if not result.success:  # the reason is the summary's last line
        raise OptimisationFailed(f"optimisation {result.status}: no certified optimum (see above; report.json "
                                 "holds every constraint's value)")
    if build_error:
        raise OptimisationFailed(f"optimum found but its tablet outputs failed: {build_error}")


COMMANDS = [optimise_cmd]
