"""One table of defaults (fdm_awe/defaults.py): every command's ``--help`` shows its values, the
commands parse to them and the Python API's keywords default to them."""

from __future__ import annotations

import contextlib
import inspect
import io
import re

import pytest

from fdm_awe import api
from fdm_awe import defaults as D
from fdm_awe.cli import build_parser, main

COMMANDS = ("optimize", "fly", "compare", "sweep")
#: the sweep's axes are lists: its own rows of the table
SWEEP_TABLE = {"--wind": D.SWEEP_WINDS, "--config": D.SWEEP_CONFIGS, "--tether-range": f"{D.D0_M:g}:{D.D_TF_M:g}"}


def _subparsers() -> dict:
    parser = build_parser()
    return next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction").choices


def _help(command: str) -> str:
    """The command's ``--help`` as printed, whitespace folded (argparse wraps lines)."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main([command, "--help"]) == 0
    return " ".join(out.getvalue().split())


def _shown(value: object) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _option_help(sub, text: str, option: str) -> str:
    """The help text of ``option`` as ``--help`` prints it (``text``, whitespace folded)."""
    action = next(a for a in sub._actions if option in a.option_strings)
    h = " ".join((action.help or "").split())
    assert h[:40] in text, (option, "not in --help")
    return h


@pytest.mark.parametrize("command", COMMANDS)
def test_every_command_help_shows_the_table_default(command):
    text = _help(command)
    sub = _subparsers()[command]
    options = {o for a in sub._actions for o in a.option_strings}
    checked = 0
    table = {**D.TABLE, **SWEEP_TABLE} if command == "sweep" else D.TABLE
    for option, value in table.items():
        if option not in options:
            continue
        h = _option_help(sub, text, option)
        assert f"default {_shown(value)}" in h or f"else {_shown(value)}" in h, (command, option, h)
        checked += 1
    assert checked >= 4, command


@pytest.mark.parametrize("command", ("optimize", "compare"))
def test_commands_parse_to_the_table(command):
    args = _subparsers()[command].parse_args([])
    for option, value in D.TABLE.items():
        attr = option.lstrip("-").replace("-", "_")
        if hasattr(args, attr):
            assert getattr(args, attr) == value, (command, option)


def test_one_default_wind_for_every_command_and_the_api():
    subs = _subparsers()
    assert subs["optimize"].parse_args([]).wind == D.WIND_MPS
    assert subs["compare"].parse_args([]).wind == D.WIND_MPS
    from fdm_awe.commands import _fly_optimise as fly_ref

    assert fly_ref.DEFAULT_WIND_MPS == D.WIND_MPS and fly_ref.DEFAULT_CONFIG == D.CONFIG == "nominal"
    assert fly_ref.reference_problem(subs["fly"].parse_args([]).__class__(
        **{**vars(subs["fly"].parse_args([])), "scenario": D.SCENARIO, "config": D.CONFIG})).wind_speed == D.WIND_MPS
    sig = inspect.signature(api.optimize).parameters
    assert (sig["wind"].default, sig["config"].default, sig["scenario"].default) == (D.WIND_MPS, D.CONFIG, D.SCENARIO)
    assert sig["flyable"].default is False
    assert inspect.signature(api.fly).parameters["cycles"].default == D.CYCLES == subs["fly"].parse_args([]).cycles


def test_api_optimize_keywords_default_to_the_optimize_command():
    """Every keyword of fdm_awe.optimize that is an option of ``fdm-awe optimize`` has its default."""
    args = _subparsers()["optimize"].parse_args([])
    compared = 0
    for name, p in inspect.signature(api.optimize).parameters.items():
        if hasattr(args, name):
            assert p.default == getattr(args, name), name
            compared += 1
    assert compared >= 20


def test_flyable_margins_are_fly_s():
    from fdm_awe.commands._fly_optimise import flyable_bounds
    from fdm_awe.commands.optimize import problem_from_args

    opt = _subparsers()["optimize"]
    b = problem_from_args(opt.parse_args(["--flyable"])).bounds
    f = flyable_bounds()
    assert (b.cl_margin, b.phi_max) == (f.cl_margin, f.phi_max) == (D.FLYABLE_CL_MARGIN, D.FLYABLE_PHI_MAX)
    plain = problem_from_args(opt.parse_args([])).bounds
    assert plain.cl_margin == 1.0 and plain.phi_max == 1.0  # Table 3's
