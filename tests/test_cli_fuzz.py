"""Every option of every command, given a bad value, is refused before any work: exit 2, one
line on stderr naming the option, within a few seconds, nothing written.

The options are enumerated from the argparse parsers (:func:`fdm_awe.cli.build_parser`), so a
new option is covered without touching this file. The bad values depend only on what argparse
knows of the option: a number type gets NaN, infinities, huge and negative numbers, an empty
string, text; an option with choices a name outside them; a flag an explicit value; a path
option (metavar ``FILE``, ``DIR``, ``OTHER_DIR``) a 300-character name, a name in a folder that
does not exist, a folder where a file is needed (a file where a folder is), character devices
(private copies of ``/dev/null``, and for options that are not read, ``/dev/full`` and
``/dev/zero``: an unchecked read of those would never end) and a FIFO; every other text option
an empty string, ``nan``, a negative number, a 300-character string and a malformed form.

The work is replaced by spies that fail the test when called (``no_work``), each case runs
in-process under a 10 s alarm (a check that blocks, on a FIFO say, fails instead of hanging),
and the folder holding the devices must be unchanged after every case (a device or a FIFO is
never replaced by a file).
"""

from __future__ import annotations

import argparse
import os
import signal
import stat
import time
from pathlib import Path

import pytest

from fdm_awe.cli import build_parser, main

DATA = Path(__file__).parent / "data"
REF = DATA / "ref_physical_nominal_8mps.json"

#: per-case limits: the checks take milliseconds, the work would take seconds or more
CASE_WALL_S = 5.0
CASE_ALARM_S = 10

#: metavars of path options: a file (input or output) or a folder
FILE_METAVARS = ("FILE",)
DIR_METAVARS = ("DIR", "OTHER_DIR")
#: file options whose file is read: they get no endless device (/dev/full, /dev/zero)
READ_FILES = ("reference", "mavlink_key", "params")

#: the rest of a valid command line of each command (``{tmp}``: the case's own folder), so that
#: the option under test is the only bad one
BASE = {"sweep": ["--out", "{tmp}/sweep_out", "--wind", "8", "--config", "nominal"]}
#: options that only apply together with others
NEEDS = {("fly", "--mavlink-key"): ["--mavlink", "udpout:127.0.0.1:14550"],
         ("sweep", "--compare"): [],
         ("fly", "--allow-mismatch"): ["--reference", str(REF)]}

#: (command, option, value) cases known not to be refused yet (strict xfail: an entry that passes
#: fails the run, so that it is removed); none today
XFAIL: dict[tuple[str, str, str], str] = {}
#: bad values of particular options, beyond those their kind gets: an address this machine cannot
#: listen on (TEST-NET-1, RFC 5737), line models outside 2..200 segments
EXTRA = {("fly", "--mavlink"): ["udpin:192.0.2.1:14550", "tcpin:192.0.2.1:14550"],
         ("fly", "--tether"): ["lumped:1", "lumped:201"]}

#: (command, option, value) cases that are valid by design: ``--stop-after N`` counts points and
#: ``--fly-stop-after N`` flights, without upper limit (a huge N never stops the sweep)
VALID = {("sweep", "--stop-after", str(10**30)), ("sweep", "--fly-stop-after", str(10**30))}


def _commands() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    raise AssertionError("no subcommands")


def _bad_values(action: argparse.Action) -> list[str]:
    """Bad values of ``action`` (see the module docstring); ``@name`` stands for a path the case
    prepares (:func:`_path_value`); None: a flag (``--flag=VALUE``)."""
    if action.nargs == 0:
        return ["1"]
    if action.choices is not None:
        return ["bogus", ""]
    if action.type is float:
        return ["nan", "inf", "-inf", "1e999", "-1e9", "1e9", "", "abc", "1,5"]
    if action.type is int:
        return ["-1", "nan", "1.5", "", "abc", str(10**30)]
    if action.metavar in FILE_METAVARS:
        endless = [] if action.dest in READ_FILES else ["@full", "@zero"]
        return ["@long", "@missing_folder", "@folder", "@null", *endless, "@fifo"]
    if action.metavar in DIR_METAVARS:
        return ["@long", "@regular_file", "@null", "@fifo"]
    return ["", "nan", "-1", "x" * 300, "bogus:bogus:bogus"]


def _cases() -> list:
    cases = []
    for name, sub in _commands().items():
        for action in sub._actions:
            if isinstance(action, (argparse._HelpAction, argparse._VersionAction)) or not action.option_strings:
                continue
            option = action.option_strings[0]
            for value in _bad_values(action) + EXTRA.get((name, option), []):
                if (name, option, value) in VALID:
                    continue
                marks = ()
                why = XFAIL.get((name, option, value))
                if why is not None:
                    marks = (pytest.mark.xfail(strict=True, reason=why),)
                shown = value if len(value) < 20 else f"{value[:6]}...({len(value)})"
                cases.append(pytest.param(name, option, tuple(action.option_strings), value, marks=marks,
                                          id=f"{name} {option}={shown}"))
    return cases


CASES = _cases()


@pytest.fixture(scope="module")
def devices(tmp_path_factory) -> Path:
    """A folder holding character devices (private copies of ``/dev/null``, ``/dev/full`` and
    ``/dev/zero``, else links to the system's when this user cannot replace those), a FIFO, a
    regular file and a folder."""
    d = tmp_path_factory.mktemp("devices")
    for name, minor in (("null", 3), ("full", 7), ("zero", 5)):
        try:
            os.mknod(d / name, stat.S_IFCHR | 0o666, os.makedev(1, minor))
        except OSError:
            if os.access("/dev", os.W_OK):
                pytest.skip("cannot make a private device node and /dev is writable: no device to test safely")
            os.symlink(f"/dev/{name}", d / name)  # a run of this user cannot replace the device itself
    os.mkfifo(d / "fifo")
    (d / "regular_file").write_text("not a folder\n")
    (d / "folder").mkdir()
    return d


def _path_value(value: str, devices: Path, tmp: Path) -> str:
    kind = value[1:]
    if kind == "long":
        return str(tmp / ("n" * 300))
    if kind == "missing_folder":
        return str(tmp / "no_such_folder" / "x.json")
    return str(devices / kind)


def _snapshot(d: Path) -> dict[str, int]:
    return {p.name: os.lstat(p).st_mode for p in d.iterdir()}


class _Alarm(Exception):
    pass


def _on_alarm(signum, frame):
    raise _Alarm(f"no answer within {CASE_ALARM_S} s (a check blocks)")


def test_every_option_has_bad_values():
    """The enumeration reaches every command and a few hundred cases (a broken enumeration
    would make the fuzz test below pass vacuously)."""
    names = {c.values[0] for c in CASES}
    assert {"info", "optimize", "compare", "fly", "sweep"} <= names
    options = {(c.values[0], c.values[1]) for c in CASES}
    for must in [("fly", "--params"), ("fly", "--mavlink-key"), ("fly", "--reference"), ("optimize", "--trajectory"),
                 ("sweep", "--out"), ("sweep", "--compare"), ("info", "--json"), ("compare", "--report")]:
        assert must in options, must
    assert len(CASES) > 300, len(CASES)


@pytest.mark.parametrize("command,option,names,value", CASES)
def test_bad_value_of_every_option_is_refused_before_work(command, option, names, value, devices, tmp_path,
                                                         no_work, capsys):
    if value.startswith("@"):
        value = _path_value(value, devices, tmp_path)
    base = [a.replace("{tmp}", str(tmp_path)) for a in BASE.get(command, [])]
    if command == "sweep" and option == "--out":
        base = base[2:]
    if command == "sweep" and option == "--compare":  # --out is then an input: an existing folder
        base = ["--out", str(tmp_path)]
    argv = [command, *base, *NEEDS.get((command, option), []), f"{option}={value}"]
    before = _snapshot(devices)
    old = signal.signal(signal.SIGALRM, _on_alarm)
    signal.alarm(CASE_ALARM_S)
    t0 = time.monotonic()
    try:
        rc = main(argv)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    wall = time.monotonic() - t0
    err = capsys.readouterr().err.strip()
    assert rc == 2, (rc, err)
    assert "\n" not in err and "error:" in err, err
    assert any(n in err for n in names), err
    assert wall < CASE_WALL_S, wall
    assert _snapshot(devices) == before  # no device, FIFO or file replaced
    assert list(tmp_path.iterdir()) == []  # nothing written, no folder created
