"""The ``fdm-awe`` command line.

Subcommands live in their own modules and are imported only when used, so ``fdm-awe --help``
and the start of a flight stay fast. Every command prints a human summary and writes optional
JSON with ``--json``.

Outputs: every output path is checked before any work starts (its folder exists and is
writable, its names fit the file system, it is a regular file or a new name, not an input of
the run, not the output of another option, compared after resolving links); files are written
under a temporary name and renamed when complete, so no reader ever sees a truncated file (the
temporary files of killed runs are removed by the next run); an ``--out`` folder is locked for
the run, a second run into it meanwhile is refused; JSON has no NaN: a NaN or infinite number is
written as ``null``.

Exit codes: 0 success; 1 the work ran but did not succeed (a failed optimisation, a flight
ended by an event, an incomplete sweep); 2 bad input (a one-line error naming the option or
file and the allowed range, before any work); 130 interrupted by Ctrl-C (SIGINT), without a
traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from typing import Callable, NoReturn, Sequence

from .errors import EXIT_INPUT, EXIT_INTERRUPTED, FdmAweError

EPILOG = ("exit codes: 0 success, 1 the work did not succeed, 2 bad input (one-line error, before any work), "
          "130 Ctrl-C. Outputs are checked before the work and written atomically; JSON writes NaN as null.")


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (``fdm-awe CMD: error: ...``), exit 2."""

    def error(self, message: str) -> "NoReturn":  # type: ignore[override]
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")

#: Order in which commands appear in ``--help`` (docs/design.md section 1); any other module in
#: :mod:`fdm_awe.commands` is listed after these.
ORDER = ("optimize", "fly", "compare", "sweep", "report", "info")


def discover_commands() -> dict[str, tuple[str, str]]:
    """name -> (module, one-line help) for every module in :mod:`fdm_awe.commands`.

    A command module defines ``HELP`` (one line), ``add_arguments(parser)`` and
    ``run(args) -> int`` (exit code), and keeps heavy imports inside ``run``.
    """
    import pkgutil

    from . import commands

    found = {}
    for info in pkgutil.iter_modules(commands.__path__):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{commands.__name__}.{info.name}")
        found[info.name] = (mod.__name__, getattr(mod, "HELP", ""))
    rank = {n: i for i, n in enumerate(ORDER)}
    return dict(sorted(found.items(), key=lambda kv: (rank.get(kv[0], len(ORDER)), kv[0])))


COMMANDS = discover_commands()


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="fdm-awe",
        description="Simulate, optimise and fly a ground-generation airborne wind energy system with a foldable-wing glider.",
        epilog=EPILOG,
    )
    from . import __version__

    parser.add_argument("--version", action="version", version=f"fdm-awe {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module, help_text) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text, epilog=EPILOG)
        p.set_defaults(_module=module)
        # Argument definitions are cheap; the module's heavy imports happen inside run().
        importlib.import_module(module).add_arguments(p)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; returns its exit code (see the module docstring)."""
    name = "fdm-awe"
    try:
        parser = build_parser()
        try:
            args = parser.parse_args(argv)
        except SystemExit as exc:  # --help, --version, or an argument error (one line, exit 2)
            return exc.code if isinstance(exc.code, int) else EXIT_INPUT
        if not getattr(args, "command", None):
            parser.print_help()
            return EXIT_INPUT
        name = f"fdm-awe {args.command}"
        run: Callable[[argparse.Namespace], int] = importlib.import_module(args._module).run
        return int(run(args) or 0)
    except FdmAweError as exc:
        print(f"{name}: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print(f"{name}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
