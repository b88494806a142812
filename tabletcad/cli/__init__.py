"""The ``tabletcad`` command line.

Each group of commands lives in its own module and is registered here.  Every
command reports bad input as one line on stderr and exits with status 2; no
traceback is printed and no partial output file is left behind.
"""

from __future__ import annotations

import importlib
import sys

import click

from tabletcad.errors import TabletcadError

__all__ = ["main", "cli"]

# (module, attribute) of each command or command group; modules are imported lazily
# so that a missing optional dependency only affects the commands that need it.
_COMMAND_MODULES = [
    "tabletcad.cli.geometry",
    "tabletcad.cli.report",
    "tabletcad.cli.mechanics",
    "tabletcad.cli.optimise",
    "tabletcad.cli.fe",
    "tabletcad.cli.sweep",
]


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="tabletcad")
def cli() -> None:
    """Design pharmaceutical tablets and tooling; all lengths in mm, forces in N, stresses in MPa."""


for _name in _COMMAND_MODULES:
    _mod = importlib.import_module(_name)
    for _cmd in getattr(_mod, "COMMANDS", []):
        cli.add_command(_cmd)


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the CLI, mapping tabletcad errors to exit status 2."""
    try:
        cli.main(args=argv, prog_name="tabletcad", standalone_mode=False)
    except click.exceptions.Abort:
        click.echo("aborted", err=True)
        return 1
    except click.ClickException as exc:
        exc.show()
        return 2 if isinstance(exc, click.UsageError) else exc.exit_code
    except (TabletcadError, ValueError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        click.echo(f"error: {msg}", err=True)
        return 2
    except OSError as exc:
        click.echo(f"error: {exc}", err=True)
        return 2
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
