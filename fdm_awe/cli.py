"""The ``fdm-awe`` command line.

Subcommands live in their own modules and are imported only when used, so ``fdm-awe --help``
and the start of a flight stay fast. Every command prints a human summary, writes optional
JSON with ``--json`` and exits 0 only on success; bad input exits 2 with a one-line error.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from typing import Callable, Sequence

from .errors import FdmAweError

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
    parser = argparse.ArgumentParser(
        prog="fdm-awe",
        description="Simulate, optimise and fly a ground-generation airborne wind energy system with a foldable-wing glider.",
    )
    from . import __version__

    parser.add_argument("--version", action="version", version=f"fdm-awe {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module, help_text) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        p.set_defaults(_module=module)
        # Argument definitions are cheap; the module's heavy imports happen inside run().
        importlib.import_module(module).add_arguments(p)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return 2
    run: Callable[[argparse.Namespace], int] = importlib.import_module(args._module).run
    try:
        return int(run(args) or 0)
    except FdmAweError as exc:
        print(f"fdm-awe {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"fdm-awe {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
