"""Command-line interface of the PMSM position-drive commissioning tool (one sub-command per task).

Installed as the console command ``pmsm-commission``; ``pmsm-commission`` runs the same. ``--help``
lists every sub-command of :data:`COMMANDS`, ``--version`` prints the installed version. Each
sub-command lives in its own module exposing ``add_arguments(parser)`` and ``run(args) -> int``.
Bad input exits with code 2 and one clear line on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import signal
import sys
import threading
from pathlib import Path
from typing import Any, NoReturn

#: sub-command → (module, help)
COMMANDS: dict[str, tuple[str, str]] = {
    "derive": ("pmsm_commissioning.app.cli.derive",
               "derive α_max, observer gains, profile, comparator gains, energies"),
    "design": ("pmsm_commissioning.app.cli.design",
               "design a clean setting for this drive and verify it by simulation"),
    "simulate": ("pmsm_commissioning.app.cli.simulate", "simulate the FDSMC and the conventional controller"),
    "export": ("pmsm_commissioning.app.cli.export", "write the drive parameter file, C controller, CSV or HTML report"),
    "table1": ("pmsm_commissioning.app.cli.table1", "Table-1 sweep of the friction saving over manoeuvre times"),
    "bench": ("pmsm_commissioning.app.cli.bench", "print speed figures of the simulation engine"),
    "serve": ("pmsm_commissioning.app.cli.serve", "start the commissioning web UI"),
    "bldc": ("pmsm_commissioning.app.cli.bldc", "sliding-mode speed control of a trapezoidal-EMF PMSM"),
    "log": ("pmsm_commissioning.app.cli.log",
            "import a drive log: overlay on the simulation, identify the motor and load"),
    "multiaxis": ("pmsm_commissioning.app.cli.multiaxis",
                  "axes that must finish together: common T_m, designs, energies"),
    "dutycycle": ("pmsm_commissioning.app.cli.duty",
                  "a duty cycle of moves with dwells: energy per cycle and per year"),
    "robustness": ("pmsm_commissioning.app.cli.robustness",
                   "Monte-Carlo robustness to plant values the controller does not know"),
    "import-drive": ("pmsm_commissioning.app.cli.import_drive",
                     "import a stock drive's file (ODrive, moteus, VESC) into a preset"),
}


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, exit 2
        from pmsm_commissioning.app.io.numbers import one_line

        sys.stderr.write(f"error: {one_line(message, 293)}\n")
        raise SystemExit(2)


def chosen_command(argv: list[str]) -> str | None:
    """Return the sub-command named on the command line (its first positional word), or None."""
    return next((a for a in argv if not a.startswith("-")), None)


#: Program name of the console command the wheel installs (``[project.scripts]`` of pyproject.toml).
CONSOLE_PROG = "pmsm-commission"
#: Program name when run as a module (``python -m pmsm_commissioning.app``).
MODULE_PROG = "python -m pmsm_commissioning.app"


def version() -> str:
    """Return the installed distribution's version (``pmsm-commissioning``), or "unknown" when not installed."""
    from importlib import metadata

    try:
        return metadata.version("pmsm-commissioning")
    except metadata.PackageNotFoundError:
        return "unknown"


def build_parser(command: str | None = None, prog: str = MODULE_PROG) -> argparse.ArgumentParser:
    """Build the argument parser with every sub-command.

    Only the module of ``command`` is imported (and its arguments added): a sub-command's module
    imports what it needs (numba kernels, scipy, plotly …), so importing all of them would make
    every call pay for the slowest. With ``command=None`` every module is imported; with an empty
    string (``pmsm-commission --help``) none is.
    """
    parser = _Parser(prog=prog, description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"%(prog)s {version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True, parser_class=_Parser)
    for name, (module, help_text) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        if command is None or command == name:
            mod = importlib.import_module(module)
            mod.add_arguments(p)
            p.set_defaults(_run=mod.run)
    return parser


def add_preset_arguments(p: argparse.ArgumentParser, default: str | None = None) -> None:
    """Add the PRESET positional and repeatable ``--set section.field=value`` options."""
    if default is None:
        p.add_argument("preset", metavar="PRESET", help="preset name (presets/NAME.yaml) or a YAML/JSON file path")
    else:
        p.add_argument("preset", metavar="PRESET", nargs="?", default=default, help="preset name or YAML/JSON path")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.FIELD=VALUE",
                   help="override a preset value, e.g. --set manoeuvre.T_m=1.4 or motor.L_d_mH=5.4")


def check_writable(path: str, option: str) -> None:
    """Raise ValueError unless ``path`` can be written (checked before any simulation runs)."""
    from pmsm_commissioning.app.io.atomic import target_problem

    target = Path(path)
    try:
        problem = target_problem(target)  # a device, FIFO, folder, read-only file, link loop
        parent = Path(os.path.realpath(target)).parent if problem is None else target.parent
        ok_dir = parent.is_dir() and os.access(parent, os.W_OK)
    except (OSError, ValueError) as exc:  # name too long, NUL byte …
        raise ValueError(f"{option} {path!r} cannot be written: {exc}") from None
    if problem is not None:
        raise ValueError(f"{option} {path!r} {problem}")
    if not ok_dir:
        raise ValueError(f"{option} {path!r}: the folder {str(parent)!r} does not exist or is not writable: "
                         "allowed a file in an existing, writable folder")


#: Commands run in a worker thread while the main thread only waits, so that Ctrl-C or SIGTERM is
#: answered within 1 s even while a compiled kernel runs (the kernels release the GIL). ``serve`` and
#: ``robustness`` keep the main thread (their servers and pools handle signals themselves).
THREADED = frozenset({"derive", "design", "simulate", "export", "import-drive", "table1", "bench", "bldc", "log",
                      "multiaxis", "dutycycle"})
#: Exit code after Ctrl-C or SIGTERM (128 + SIGINT, as a shell reports it).
INTERRUPTED = 130
#: Exit code when the output's reader went away (128 + SIGPIPE, as a shell reports a process it ended).
BROKEN_PIPE = 141


#: True while :func:`main` runs as the process itself (``pmsm-commission``, the console script).
_AS_PROCESS = False


def _raise_interrupt(signum: int, frame: Any) -> None:
    """Raise KeyboardInterrupt; while numba compiles on this thread, end the process at once instead.

    LLVM hands each compiled module to numba through a ctypes callback, the first Python code to
    run after a long code-generation step, so a signal that arrives then is handled inside that
    callback, and ctypes prints and drops what it raises ("Exception ignored on calling ctypes
    callback"): the run went on to its end with exit 0.
    """
    if _AS_PROCESS and _compiling_here():
        _end_child_processes()
        _stop_interrupted()
    raise KeyboardInterrupt


def _compiling_here() -> bool:
    """Return True when the calling thread holds numba's compiler lock (a kernel is being compiled)."""
    lock_module = sys.modules.get("numba.core.compiler_lock")
    return lock_module is not None and bool(lock_module.global_compiler_lock.is_locked())


def _end_child_processes() -> None:
    """Terminate this process's multiprocessing children (a pool's workers), which would outlive it.

    The study pools are ended first (:func:`sim.studies.runner.end_all_pools`): none starts anew.
    """
    runner = sys.modules.get("pmsm_commissioning.sim.studies.runner")
    if runner is not None:
        runner.end_all_pools()
    mp = sys.modules.get("multiprocessing")
    for child in mp.active_children() if mp is not None else []:
        child.terminate()


def _install_handlers() -> dict[int, Any]:
    """Route SIGTERM, SIGINT and SIGHUP (a closed terminal) to :func:`_raise_interrupt`.

    SIGINT and SIGHUP keep an ignored disposition (a background job, ``nohup``).
    """
    previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, _raise_interrupt)}
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        previous[signal.SIGINT] = signal.signal(signal.SIGINT, _raise_interrupt)
    if signal.getsignal(signal.SIGHUP) is signal.SIG_DFL:
        previous[signal.SIGHUP] = signal.signal(signal.SIGHUP, _raise_interrupt)
    return previous


def _run_in_thread(args: argparse.Namespace) -> int:
    """Run the command in a daemon thread; the main thread waits in short slices (signals stay prompt)."""
    box: dict[str, Any] = {}

    def target() -> None:
        try:
            box["rc"] = int(args._run(args) or 0)
        except BaseException as exc:  # noqa: BLE001 - handed to the main thread as it is
            box["exc"] = exc

    worker = threading.Thread(target=target, name=f"cli-{args.command}", daemon=True)
    worker.start()
    while worker.is_alive():
        worker.join(0.05)
    if "exc" in box:
        raise box["exc"]
    return int(box["rc"])


def _stop_interrupted() -> NoReturn:
    """Remove files being written, say so in one line, exit 130 at once (threads are not waited for)."""
    from pmsm_commissioning.app.cli.progress import bar_open
    from pmsm_commissioning.app.io.atomic import discard_partial

    discard_partial()
    # the pool's own threads fail as its workers go (broken pipes): a consequence of stopping, not news
    threading.excepthook = lambda _args: None
    _end_child_processes()  # a pool's workers (they would also end themselves, a moment later)
    try:
        sys.stdout.flush()
        # below a progress bar left open on the terminal (it stays as drawn last); plain progress lines are whole
        sys.stderr.write(("\n" if bar_open() else "") + "interrupted: stopped; no partial file was left\n")
        sys.stderr.flush()
    finally:
        os._exit(INTERRUPTED)


def main(argv: list[str] | None = None, prog: str = MODULE_PROG) -> int:
    """Run the CLI as ``prog``; returns the exit code (130 at once on Ctrl-C or SIGTERM, from a real process)."""
    global _AS_PROCESS
    in_main = threading.current_thread() is threading.main_thread()
    previous = _install_handlers() if in_main else {}
    _AS_PROCESS = in_main and argv is None
    try:
        return _main(sys.argv[1:] if argv is None else argv, prog)
    except KeyboardInterrupt:
        if argv is None:  # ``pmsm-commission``: end the process now, whatever threads still run
            _stop_interrupted()
        return INTERRUPTED
    except BrokenPipeError:  # the reader of the output went away (``… | head``): nothing more to say
        if argv is None:  # the interpreter's last flush of stdout would fail again: point it at /dev/null
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return BROKEN_PIPE
    finally:
        _AS_PROCESS = False
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _main(argv: list[str], prog: str) -> int:
    from pmsm_commissioning.app.threads import limit_blas_threads

    limit_blas_threads()  # before the sub-command imports numpy: then it costs nothing
    args = build_parser(chosen_command(argv) or "", prog).parse_args(argv)  # "": --help alone imports none
    try:
        if args.command in THREADED:
            return _run_in_thread(args)
        return int(args._run(args) or 0)
    except ValueError as exc:  # ParameterError, PresetError: bad input
        from pmsm_commissioning.app.io.numbers import one_line

        sys.stderr.write(f"error: {one_line(exc, 293)}\n")  # ≤ 300 characters with "error: "
        return 2


def entry() -> None:
    """Console entry point ``pmsm-commission …`` (installed by the wheel): :func:`main`, then exit."""
    sys.exit(main(prog=CONSOLE_PROG))
