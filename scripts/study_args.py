"""Command-line pieces the study scripts share (``generator_gap.py``, ``activity_tradeoff.py``):
a comma list of allowed names, and the ``--json`` / ``--report`` outputs checked before any work."""

from __future__ import annotations

import argparse

from fdm_awe.errors import InputError


def choice_list(text: str, option: str, allowed: tuple[str, ...] | list[str]) -> list[str]:
    """The comma list ``text`` of ``option``, each item one of ``allowed`` (InputError otherwise)."""
    items = [c.strip() for c in text.split(",")]
    if not items or any(c not in allowed for c in items):
        raise InputError(f"{option} {text}: allowed {', '.join(allowed)} (comma list)")
    return items


#: the configurations a study compares
CONFIGS = ("nominal", "foldable")


def add_configs(ap: argparse.ArgumentParser) -> None:
    """``--config LIST``: the configurations, default both."""
    ap.add_argument("--config", default=",".join(CONFIGS), help="configurations (default nominal,foldable)")


def configs(args: argparse.Namespace) -> list[str]:
    """The checked ``--config`` list."""
    return choice_list(args.config, "--config", CONFIGS)


def add_outputs(ap: argparse.ArgumentParser) -> None:
    """``--json FILE`` (the rows) and ``--report FILE`` (the markdown table)."""
    ap.add_argument("--json", default=None, help="write the rows as JSON")
    ap.add_argument("--report", default=None, help="write the markdown table")


def check_outputs(args: argparse.Namespace) -> None:
    """Each output given can be written (InputError naming the option otherwise)."""
    from fdm_awe.fileio import check_output_file

    for opt, path in (("--json", args.json), ("--report", args.report)):
        if path is not None:
            check_output_file(path, opt)
