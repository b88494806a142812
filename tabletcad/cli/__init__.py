"""The ``tabletcad`` command line.

Each group of commands lives in its own module and is composed here.  Exit
status and stderr follow one contract:

* 0: success;
* 2: bad input (:class:`~tabletcad.errors.DesignError`, any other
  :class:`~tabletcad.errors.TabletcadError`, and click's usage errors): one
  line ``error: <parameter> = <value> is not allowed: <range>``, no traceback,
  no partial output left behind;
* 1: an internal error (any other exception, a bug): one line naming it and
  the log file that holds the traceback;
* 130: interrupted (Ctrl-C), also during start-up: one line ``interrupted``,
  nothing written (a build puts its outputs in place with SIGINT held back, so
  a Ctrl-C after that point finds a finished build: one line saying so, 0);
* other codes a command documents (``optimise``: 3 when it finds no optimum).

Nothing but the standard library is imported at module level, so that Ctrl-C
while click, numpy or the commands load is caught by :func:`main` too.
"""

from __future__ import annotations

import sys
__all__ = ["main", "cli"]

# modules whose COMMANDS list is composed into the group, in this order
_COMMAND_MODULES = (
    "tabletcad.cli.geometry",
    "tabletcad.cli.report",
    "tabletcad.cli.mechanics",
    "tabletcad.cli.optimise",
    "tabletcad.cli.fe",
    "tabletcad.cli.sweep",
)
_GROUP = None  # the click group, built by _group()


def _say(line: str) -> None:
    try:
        sys.stderr.write(line + "\n")
        sys.stderr.flush()
    except (OSError, ValueError):  # stderr closed
        pass


def _group():
    """The click group with every command (built once, on first use)."""
    global _GROUP
    if _GROUP is None:
        import importlib

        import click

        @click.group(context_settings={"help_option_names": ["-h", "--help"]})
        @click.version_option(package_name="tabletcad")
        def group() -> None:
            """Design pharmaceutical tablets and tooling; all lengths in mm, forces in N, stresses in MPa."""
            from tabletcad.io.timestamp import check_stamp

            check_stamp()  # a malformed SOURCE_DATE_EPOCH is refused before any command writes a file

        for name in _COMMAND_MODULES:
            for cmd in getattr(importlib.import_module(name), "COMMANDS", []):
                _one_line_params(cmd)
                group.add_command(cmd)
        _GROUP = group
    return _GROUP


def __getattr__(name: str):  # ``tabletcad.cli.cli``: the click group, built lazily
    if name == "cli":
        return _group()
    raise AttributeError(name)


# ---------------------------------------------------------------------- click errors -> one line
def _param_name(param) -> str:
    if param is None:
        return "argument"
    opts = [o for o in getattr(param, "opts", []) if o.startswith("--")] or list(getattr(param, "opts", []))
    if getattr(param, "param_type_name", "") == "option" and opts:
        return max(opts, key=len)
    return (param.human_readable_name or param.name or "argument").replace(" ", "_")


def _allowed(inner, exc) -> str:
    import click

    if isinstance(inner, (click.IntRange, click.FloatRange)):
        kind = "an integer" if isinstance(inner, click.IntRange) else "a number"
        return f"must be {kind} {inner._describe_range()}"
    if isinstance(inner, click.types.IntParamType):
        return "must be an integer"
    if isinstance(inner, click.types.FloatParamType):
        return "must be a number"
    if isinstance(inner, click.Choice):
        return "must be one of " + ", ".join(map(str, inner.choices))
    if isinstance(inner, click.Path):
        kind = "file" if not inner.dir_okay else "folder" if not inner.file_okay else "file or folder"
        text = f"must be {'an existing ' if inner.exists else 'a '}{kind} path"
        if inner.dir_okay != inner.file_okay:
            text += f", not an existing {'folder' if kind == 'file' else 'file'}"
        return text
    return " ".join(exc.format_message().split()).rstrip(".")


def _one_line_params(cmd) -> None:
    """Give every parameter of ``cmd`` (and its subcommands) a type whose conversion
    failures are :class:`DesignError` naming the option and the value given."""
    import click

    from tabletcad.errors import DesignError

    class OneLine(click.ParamType):
        def __init__(self, inner: click.ParamType) -> None:
            self.inner = inner
            self.name = inner.name
            self.envvar_list_splitter = inner.envvar_list_splitter

        def convert(self, value, param, ctx):
            try:
                return self.inner.convert(value, param, ctx)
            except click.BadParameter as exc:
                raise DesignError(_param_name(param), value, _allowed(self.inner, exc)) from None

        def get_metavar(self, *args, **kw):
            return self.inner.get_metavar(*args, **kw)

        def get_missing_message(self, *args, **kw):
            return self.inner.get_missing_message(*args, **kw)

        def to_info_dict(self):
            return self.inner.to_info_dict()

        def split_envvar_value(self, rv):
            return self.inner.split_envvar_value(rv)

        def shell_complete(self, *args, **kw):
            return self.inner.shell_complete(*args, **kw)

    for param in cmd.params:
        t = param.type
        if not getattr(t, "is_composite", False) and not isinstance(t, (OneLine, click.types.BoolParamType)) \
                and not getattr(param, "is_flag", False):
            param.type = OneLine(t)
    for sub in getattr(cmd, "commands", {}).values():
        _one_line_params(sub)


def _usage_line(exc) -> str:
    """One ``error:`` line for a click usage error not raised by a parameter's type."""
    import click

    from tabletcad.errors import MISSING, DesignError

    ctx = exc.ctx
    where = ctx.command_path if ctx is not None else "tabletcad"
    if isinstance(exc, click.NoSuchOption):
        opts = []
        if ctx is not None:
            for p in ctx.command.params:
                opts.extend(o for o in getattr(p, "opts", []) if o.startswith("--"))
        return str(DesignError("option", exc.option_name, f"{where} takes " + (", ".join(opts) or "no options")))
    if isinstance(exc, click.MissingParameter):
        return str(DesignError(_param_name(exc.param), MISSING, f"{where} needs it"))
    if isinstance(exc, click.BadOptionUsage):
        return str(DesignError(exc.option_name, MISSING, f"{exc.option_name} needs a value"))
    if isinstance(exc, click.BadParameter):
        return str(DesignError(_param_name(exc.param), "given", " ".join(exc.format_message().split()).rstrip(".")))
    msg = " ".join(exc.format_message().split()).rstrip(".")
    if msg.startswith("No such command"):  # the commands of the group it was given to (fe: diametral, punch, strength)
        group = ctx.command if ctx is not None and isinstance(ctx.command, click.Group) else _group()
        names = ", ".join(sorted(group.commands))
        return str(DesignError("command", msg.split("'")[1] if "'" in msg else msg, f"must be one of {names}"
                               + (f" (the commands of {where})" if group is not _group() else "")))
    if "unexpected extra argument" in msg:
        extra = msg[msg.find("(") + 1:msg.rfind(")")] if "(" in msg else msg
        return str(DesignError("argument", extra, f"{where} takes no further arguments (see {where} --help)"))
    return str(DesignError("arguments", where, msg))


# ---------------------------------------------------------------------- internal errors
def _log_internal(exc: BaseException) -> str:
    """Write the traceback of ``exc`` to a log file; return its path (or a note why not)."""
    import os
    import tempfile
    import time
    import traceback

    text = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    head = f"tabletcad {' '.join(sys.argv[1:])}\n{time.strftime('%Y-%m-%d %H:%M:%S')}\n\n"
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    for folder in (os.path.join(base, "tabletcad"), os.path.join(tempfile.gettempdir(), "tabletcad")):
        try:
            os.makedirs(folder, exist_ok=True)
            fd, path = tempfile.mkstemp(prefix=time.strftime("error-%Y%m%d-%H%M%S-"), suffix=".log", dir=folder)
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                f.write(head + text)
            return path
        except OSError:
            continue
    return "(no log written: no writable cache folder)"


def _run(argv: list[str] | None) -> int:
    import click

    from tabletcad.errors import DesignError, TabletcadError

    group = _group()
    args = list(sys.argv[1:] if argv is None else argv)
    _published().clear()
    try:
        with group.make_context("tabletcad", [str(a) for a in args]) as ctx:
            group.invoke(ctx)
    except click.exceptions.Exit as exc:  # --help, --version
        return exc.exit_code
    except click.UsageError as exc:
        if type(exc).__name__ == "NoArgsIsHelpError" and exc.ctx is not None:  # bare `tabletcad`: the help
            click.echo(exc.ctx.get_help())
            return 0
        _say("error: " + _usage_line(exc))
        return 2
    except click.exceptions.Abort:
        return _interrupted()
    except click.ClickException as exc:  # a command's own status (optimise: 3)
        exc.show()
        return exc.exit_code
    except DesignError as exc:
        # the file a command was given, named as its usage line names it
        usage = {"design_file": "DESIGN", "sweep.file": "SWEEP.toml", "problem.file": "PROBLEM.toml"}
        if exc.parameter in usage:
            exc = exc.renamed(usage[exc.parameter])
        # one line; its value's repr as given (text = "   " is not ' '), its line breaks joined
        _say(f"error: {' '.join(str(exc).splitlines())}")
        return 2
    except TabletcadError as exc:
        msg = " ".join(str(exc).split()) or type(exc).__name__
        _say(f"error: {msg}")
        return 2
    except OSError as exc:
        if exc.filename is None:
            import errno

            # the system refused a write with no file named: standard output on a full disk (``> /dev/full``),
            # or an open file's handle; the machine's state, not a bug in tabletcad
            if isinstance(exc, BrokenPipeError) or exc.errno not in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO):
                raise
            _say("error: " + str(DesignError("output", "(being written)", exc.strerror.lower())))
            return 2
        _say("error: " + str(DesignError("path", str(exc.filename), (exc.strerror or type(exc).__name__).lower())))
        return 2
    return 0


#: ``warning:`` lines of the running command, printed when it ends with a result (status 0 or 3): a
#: refusal is its one ``error:`` line (a design's warning had come before the error of a write to a
#: full disk, two lines for one refusal)
_PENDING_WARNINGS: list[str] = []
#: the process that runs :func:`main` (a forked helper, ``tabletcad.io.forked``, prints its warnings at once:
#: its copy of the held list ends with it)
_MAIN_PID = [0]


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning on the command line: one line, ``warning: <message>``, no source line (:func:`say_warning`)."""
    say_warning(str(message))


def say_warning(message: str) -> None:
    """``warning: <message>`` on one line, held until the command has its outcome (:data:`_PENDING_WARNINGS`),
    in the order the command's warnings arose, Python's and its own (``mesh`` had printed its volume's
    warning before the design's, raised first)."""
    import os

    text = "warning: " + " ".join(message.split())
    if os.getpid() == _MAIN_PID[0]:
        _PENDING_WARNINGS.append(text)
    else:
        _say(text)


def _say_warnings(status: int) -> None:
    """Print the held warnings after a result (status 0, or 3: ``optimise`` found no feasible optimum),
    drop them after a refusal, an internal error or an interruption (their one line is the outcome)."""
    lines = list(_PENDING_WARNINGS)
    _PENDING_WARNINGS.clear()
    if status in (0, 3):
        for line in lines:
            _say(line)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit status (see the module docstring)."""
    import os
    import warnings

    # one BLAS thread unless the user sets another number: tabletcad's matrices are small (a
    # patch's modes x samples), where a second thread costs more than it brings, and on a busy
    # machine much more (capsule report: 1.9 s with one thread, 5.0 s with two, 2 cores shared)
    for var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")

    if argv is None:  # run as the program: remember a Ctrl-C even if a library catches its KeyboardInterrupt
        import signal

        _SIGINT_SEEN[0] = False
        signal.signal(signal.SIGINT, _on_sigint)
        sys.unraisablehook = _unraisable_interrupt(sys.unraisablehook)
    _PENDING_WARNINGS.clear()
    _MAIN_PID[0] = os.getpid()
    try:
        try:
            with warnings.catch_warnings():
                warnings.showwarning = _show_warning
                # libraries' deprecation notes are for their callers' developers, not for the user of
                # a command (Python hides them outside __main__ too; pytest would show them)
                warnings.simplefilter("ignore", DeprecationWarning)
                warnings.simplefilter("ignore", PendingDeprecationWarning)
                status = _run(argv)
            _say_warnings(status)
            if argv is None:  # the program's outcome is decided: a Ctrl-C now would only break its exit
                import signal

                signal.signal(signal.SIGINT, signal.SIG_IGN)
                _finish(status)
            return status
        except (KeyboardInterrupt, SystemExit):
            raise
        except BrokenPipeError:  # the reader of stdout went away (``| head``): stop quietly
            import os

            try:
                os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            except (OSError, ValueError):
                pass
            return 141
        except RecursionError as exc:
            path = _log_internal(exc)
            _say(f"error: internal error (RecursionError); traceback in {path}")
            return 1
        except BaseException as exc:  # noqa: BLE001 - the one place that turns bugs into exit 1
            from tabletcad.errors import reraise_interrupt

            reraise_interrupt(exc)  # e.g. ImportError "initialization failed" from a Ctrl-C in OCP's import
            if _SIGINT_SEEN[0]:  # a library swallowed the Ctrl-C and failed over it (trimesh's lazy imports)
                raise KeyboardInterrupt from exc
            path = _log_internal(exc)
            msg = " ".join(str(exc).split())
            if len(msg) > 120:
                msg = msg[:117] + "..."
            _say(f"error: internal error ({type(exc).__name__}{': ' + msg if msg else ''}); traceback in {path}")
            return 1
    except KeyboardInterrupt:
        status = _interrupted()
        if argv is None:  # run as the program: end here
            _exit_now(status)
        return status


#: Whether this program has received a SIGINT (Ctrl-C): an internal error after one is an interruption.
_SIGINT_SEEN = [False]


def _on_sigint(signum, frame) -> None:
    """Python's own Ctrl-C (a :class:`KeyboardInterrupt`), remembered in :data:`_SIGINT_SEEN`.

    The program's last words are then ``interrupted``: the libraries' log records are turned off,
    for they only tell of the interruption itself (a sweep's Dask client, stopped while it waited,
    logged a ``NameError`` traceback from ``distributed.utils.sync`` and "Couldn't gather keys"
    in about one run in ten; distributed 2026.8.0)."""
    import logging

    _SIGINT_SEEN[0] = True
    logging.disable(logging.CRITICAL)
    raise KeyboardInterrupt


def _unraisable_interrupt(previous):
    """``sys.unraisablehook`` for the program: a Ctrl-C's KeyboardInterrupt raised where Python cannot raise
    it (a garbage-collector callback, ``__del__``: distributed's ``GCDiagnosis`` while a sweep's cluster
    started) was printed as "Exception ignored in ..." and lost, and the sweep ran on.  It is delivered
    again to the main thread instead, 50 ms later (:func:`_thread.interrupt_main` from a timer thread:
    called at once it would raise inside this hook, still in the callback), which raises it in the
    program's own code; any other unraisable exception goes to ``previous``."""

    def hook(unraisable) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            import _thread
            import threading

            again = threading.Timer(0.05, _thread.interrupt_main)
            again.daemon = True
            again.start()
            return
        previous(unraisable)

    return hook


def _published() -> list:
    """Output folders this process has published (:data:`tabletcad.io.outputs.published`)."""
    mod = sys.modules.get("tabletcad.io.outputs")
    return mod.published if mod is not None else []


def _interrupted() -> int:
    """Ctrl-C: ``interrupted`` and 130 with nothing written, or - when it came after the build
    had put its outputs in place - the finished build's folder and 0."""
    done = _published()
    if done:
        _say(f"interrupted after the build was complete: outputs in {done[-1]}/")
        return 0
    _say("interrupted")
    return 130


def _finish(status: int) -> None:
    """End the program with ``status`` once its work is done: as the interpreter's own exit, its
    non-daemon threads and thread pools are joined (``threading._shutdown``) and the exit handlers
    that libraries registered run (``atexit``: multiprocessing's children joined, logging flushed),
    then the process ends without tearing down its modules and objects one by one.
    That teardown only frees memory the system frees anyway, and after a tooling build, with
    OpenCascade's shapes and meshes alive, it took 0.5-0.6 s of the command's time (runs of the
    concave round bisect's build: 0.50-0.63 s from ``main`` returning to the process's end, on an
    idle and on a loaded machine; 0.06-0.08 s with this)."""
    import atexit
    import threading

    try:
        threading._shutdown()  # as the interpreter's own exit: non-daemon threads and thread pools joined
        atexit._run_exitfuncs()
    finally:
        _exit_now(status)


def _exit_now(status: int) -> None:
    """Flush and end the process with ``status`` at once.  Returning 130 was not enough: in about
    one run in three, a Ctrl-C that arrived while modules were importing ended the process by
    SIGINT (status -2) after ``interrupted`` had been printed and the KeyboardInterrupt caught
    (CPython 3.11; seen in tests/test_cli_contract.py)."""
    import os

    _release_semaphores()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass
    os._exit(status)


def _release_semaphores() -> None:
    """Unlink the named semaphores this process made, as its normal exit would: multiprocessing's exit-time
    finalizers (those of priority 0 and up; its ``atexit`` handler runs the same), when it was imported.

    ``os._exit`` skips them, and Python's resource tracker then reported every semaphore still registered:
    tqdm's write lock (made at a sweep's progress bar) is one wherever the start method is not ``fork``
    (macOS; Linux from Python 3.14): "resource_tracker: There appear to be 1 leaked semaphore objects to
    clean up at shutdown" after each Ctrl-C's ``interrupted``.
    """
    util = sys.modules.get("multiprocessing.util")
    if util is None:
        return
    try:
        util._run_finalizers(0)
    except BaseException:  # noqa: BLE001 - the process ends now whatever a finalizer does (a second Ctrl-C)
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
