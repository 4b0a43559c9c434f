"""Output paths that must be refused before any work (issue 28, items 4-10): an input as an
output, a device or a FIFO as an output, two options naming one file through a symbolic link,
an explicit output on a name ``--out`` writes, a parameter file that would block or go into a
folder that does not exist, names longer than the file system allows; and what a run leaves
for the next: temporary files of killed runs are removed, a second run into an ``--out``
folder that a running one holds is refused.

Each refusal is ``main(argv) == 2`` with one line naming the option, before any work (the work
functions are spies that fail the test when called, ``no_work``), under a 10 s alarm (a check
that blocks fails instead of hanging).
"""

from __future__ import annotations

import os
import shutil
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import WorkStarted
from fdm_awe.cli import main

DATA = Path(__file__).parent / "data"
REF = DATA / "ref_physical_nominal_8mps.json"
ROOT = Path(__file__).resolve().parents[1]
MAVLINK = ["--mavlink", "udpout:127.0.0.1:14550"]
#: the lock file of an ``--out`` folder (:data:`fdm_awe.fileio.LOCK_NAME`)
LOCK_NAME = ".fdm-awe.lock"


def _alarm(signum, frame):
    raise TimeoutError("no answer within 10 s (a check blocks)")


def _refused(argv: list[str], capsys, *words: str) -> str:
    """``main(argv)`` returns 2 within 10 s with one error line holding ``words``."""
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(10)
    t0 = time.monotonic()
    try:
        rc = main(argv)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    err = capsys.readouterr().err.strip()
    assert rc == 2, (argv, err)
    assert time.monotonic() - t0 < 10.0
    assert "\n" not in err and "error:" in err, err
    for w in words:
        assert w in err, (w, err)
    return err


def _device(folder: Path, name: str = "full", minor: int = 7) -> Path:
    """A character device in ``folder`` (a private copy of ``/dev/<name>``), or a link to the
    system's when this user cannot make one and cannot replace the system's either."""
    p = folder / name
    try:
        os.mknod(p, stat.S_IFCHR | 0o666, os.makedev(1, minor))
    except OSError:
        if os.access("/dev", os.W_OK):
            pytest.skip("cannot make a private device node and /dev is writable: no device to test safely")
        os.symlink(f"/dev/{name}", p)
    return p


# -- 4. an input is never an output ------------------------------------------------------------

def test_4_key_file_is_an_input(tmp_path, no_work, capsys):
    key = tmp_path / "k.txt"
    key.write_text("correct horse battery staple\n")
    _refused(["fly", "--reference", str(REF), *MAVLINK, "--mavlink-key", str(key), "--json", str(key)], capsys,
             "--json", "input")
    _refused(["fly", "--reference", str(REF), *MAVLINK, "--mavlink-key", str(key), "--out", str(tmp_path / "o"),
              "--rrd", str(key)], capsys, "--rrd", "input")
    # --params is written back on PARAM_SET: never onto the reference or the key
    ref = tmp_path / "ref.json"
    shutil.copy(REF, ref)
    _refused(["fly", "--reference", str(ref), "--params", str(ref)], capsys, "--params", "input")
    _refused(["fly", "--reference", str(REF), *MAVLINK, "--mavlink-key", str(key), "--params", str(key)], capsys,
             "--params", "input")
    assert key.read_text() == "correct horse battery staple\n"
    assert ref.read_bytes() == REF.read_bytes()
    assert sorted(os.listdir(tmp_path)) == ["k.txt", "ref.json"]


# -- 5. outputs are regular files or new names -------------------------------------------------

@pytest.mark.parametrize("kind", ["character device", "FIFO"])
def test_5_a_device_or_fifo_is_never_replaced_by_an_output(kind, tmp_path, no_work, capsys):
    if kind == "FIFO":
        node = tmp_path / "fifo"
        os.mkfifo(node)
    else:
        node = _device(tmp_path)
    mode = os.stat(node).st_mode
    for argv, option in [(["info", "--json", str(node)], "--json"),
                         (["fly", "--reference", str(REF), "--rrd", str(node)], "--rrd"),
                         (["optimize", "--trajectory", str(node)], "--trajectory"),
                         (["compare", "--report", str(node)], "--report")]:
        _refused(argv, capsys, option, "not a regular file")
        assert os.stat(node).st_mode == mode, argv  # still the device or the FIFO
    assert os.listdir(tmp_path) == [node.name]  # no temporary file left


# -- 6. resolved paths ---------------------------------------------------------------------------

def test_6_two_outputs_through_a_linked_folder_are_one_file(tmp_path, no_work, capsys):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "alias").symlink_to(real, target_is_directory=True)
    _refused(["optimize", "--json", str(real / "a.json"), "--trajectory", str(tmp_path / "alias" / "a.json")], capsys,
             "--trajectory", "--json")
    _refused(["fly", "--reference", str(REF), "--json", str(real / "x"), "--rrd", str(tmp_path / "alias" / "x")],
             capsys, "--rrd", "--json")
    # a file --out writes, named through the link
    _refused(["fly", "--reference", str(REF), "--out", str(real), "--json", str(tmp_path / "alias" / "flight.csv")],
             capsys, "--json", "--out")
    # two names of one existing file (a hard link)
    (real / "h1").write_text("")
    os.link(real / "h1", real / "h2")
    _refused(["optimize", "--json", str(real / "h1"), "--trajectory", str(real / "h2")], capsys, "--trajectory",
             "--json")
    assert sorted(os.listdir(real)) == ["h1", "h2"]


# -- 7. a name --out writes is --out's ---------------------------------------------------------

def test_7_an_output_named_inside_out_that_out_writes_is_refused(tmp_path, no_work, capsys):
    d = tmp_path / "D"
    _refused(["fly", "--reference", str(REF), "--out", str(d), "--rrd", str(d / "flight.rrd")], capsys,
             "--rrd", "--out")
    _refused(["optimize", "--out", str(d), "--rrd", str(d / "cycle.rrd")], capsys, "--rrd", "--out")
    _refused(["optimize", "--out", str(d), "--json", str(d / "cycle.md")], capsys, "--json", "--out")
    _refused(["sweep", "--wind", "8", "--out", str(d), "--json", str(d / "points" / "x.json")], capsys, "--json",
             "points")
    assert not d.exists()
    # another name inside --out is fine: the run goes as far as its work
    with pytest.raises(WorkStarted):
        main(["optimize", "--out", str(d), "--rrd", str(d / "other.rrd")])
    assert os.listdir(d) == []  # the lock is released, its file removed


# -- 8. the parameter file ---------------------------------------------------------------------

def test_8_params_that_would_block_or_need_a_new_folder_are_refused(tmp_path, no_work, capsys):
    fifo = tmp_path / "params.fifo"
    os.mkfifo(fifo)
    _refused(["fly", "--reference", str(REF), "--params", str(fifo)], capsys, "--params", "FIFO")
    _refused(["fly", "--reference", str(REF), "--params", str(tmp_path / "no_such" / "p.json")], capsys,
             "--params", "does not exist")
    _refused(["fly", "--reference", str(REF), "--params", str(tmp_path)], capsys, "--params", "folder")
    assert not (tmp_path / "no_such").exists()
    # a new name in an existing folder is a new parameter file: the flight starts
    with pytest.raises(WorkStarted):
        main(["fly", "--reference", str(REF), "--params", str(tmp_path / "p.json")])


# -- 9. names longer than the file system allows -----------------------------------------------

LONG_CASES = [
    (["fly", "--reference", str(REF), "--json", "{long}"], "--json"),
    (["fly", "--reference", str(REF), "--out", "{long}"], "--out"),
    (["fly", "--reference", str(REF), "--rrd", "{long}"], "--rrd"),
    (["fly", "--reference", str(REF), "--params", "{long}"], "--params"),
    (["fly", "--reference", str(REF), *MAVLINK, "--mavlink-key", "{long}"], "--mavlink-key"),
    (["fly", "--reference", "{long}"], "--reference"),
    (["optimize", "--trajectory", "{long}"], "--trajectory"),
    (["optimize", "--json", "{long}"], "--json"),
    (["compare", "--report", "{long}"], "--report"),
    (["sweep", "--wind", "8", "--out", "{long}"], "--out"),
    (["sweep", "--wind", "8", "--out", "{tmp}/s", "--json", "{long}"], "--json"),
    (["info", "--json", "{long}"], "--json"),
]


@pytest.mark.parametrize("argv,option", LONG_CASES, ids=[f"{a[0]} {o}" for a, o in LONG_CASES])
@pytest.mark.parametrize("where", ["name", "folder"])
def test_9_a_300_character_name_is_one_line_exit_2(argv, option, where, tmp_path, no_work, capsys):
    long = tmp_path / ("n" * 300) if where == "name" else tmp_path / ("f" * 300) / "x.json"
    argv = [a.replace("{long}", str(long)).replace("{tmp}", str(tmp_path)) for a in argv]
    _refused(argv, capsys, option, "too long", "255")
    assert os.listdir(tmp_path) == []


def test_9_a_target_name_of_255_bytes_is_written(tmp_path):
    """The longest name the file system allows is written: the temporary name beside it is
    shorter than the target's."""
    from fdm_awe.fileio import write_json

    name = "é" * 120 + "a" * 10 + ".json"  # 255 bytes in UTF-8
    assert len(os.fsencode(name)) == 255
    write_json(tmp_path / name, {"a": 1})
    assert os.listdir(tmp_path) == [name]


# -- 10. what runs leave for the next ----------------------------------------------------------

KILLED_WRITER = """
import os, sys, time
from fdm_awe.fileio import atomic_path
with atomic_path(sys.argv[1]) as tmp:
    print(tmp.name, flush=True)
    time.sleep(60)
"""


def test_10_temporary_files_of_a_killed_run_are_removed_by_the_next(tmp_path):
    target = tmp_path / "info.json"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-c", KILLED_WRITER, str(target)], stdout=subprocess.PIPE, text=True,
                            env=env)
    try:
        part = tmp_path / proc.stdout.readline().strip()
        assert part.name.endswith(".part.json") and part.exists()
        # a live writer's temporary file stays
        assert main(["info", "--json", str(target)]) == 0
        assert part.exists()
    finally:
        proc.kill()
        proc.wait()
    assert part.exists()  # SIGKILL: the writer could not remove it
    # another process's file in the folder, named like one but not ours, stays
    other = tmp_path / ".notes.txt.part"
    other.write_text("x")
    assert main(["info", "--json", str(target)]) == 0
    assert sorted(os.listdir(tmp_path)) == [".notes.txt.part", "info.json"]


def test_10_out_folder_is_locked_while_a_run_writes_into_it(tmp_path, monkeypatch, capsys):
    """A second run into the ``--out`` of a running one is refused (one line naming ``--out``,
    exit 2); once the first ends, the folder is free again and the lock file gone."""
    import fdm_awe.ocp.solve as solve
    import fdm_awe.sim.flight as flight
    import fdm_awe.sweep.execute as execute

    d = tmp_path / "D"
    inner: list[tuple[int, str]] = []

    def second_run(argv):
        def work(*a, **kw):
            capsys.readouterr()  # the first run's lines so far
            inner.append((main(argv), capsys.readouterr().err.strip()))
            raise WorkStarted("the first run's work")
        return work

    for module, name, argv in [
        (solve, "solve_cycle", ["optimize", "--out", str(d)]),
        (flight, "fly", ["fly", "--reference", str(REF), "--out", str(d)]),
        (execute, "run_sweep", ["sweep", "--wind", "8", "--config", "nominal", "--out", str(d)]),
    ]:
        monkeypatch.setattr(module, name, second_run(argv))
        inner.clear()
        with pytest.raises(WorkStarted):
            main(argv)
        (rc, err), = inner
        assert rc == 2, err
        assert "\n" not in err and "--out" in err and "another fdm-awe run" in err and str(os.getpid()) in err, err
        assert not (d / LOCK_NAME).exists()  # released and removed when the first run ended
    from fdm_awe import fileio

    assert fileio.LOCK_NAME == LOCK_NAME


HOLDER = """
import sys, time
from fdm_awe.fileio import lock_folder
lock = lock_folder(sys.argv[1], "--out")
print("locked", flush=True)
time.sleep(60)
"""


def test_10_lock_of_a_killed_run_is_free(tmp_path, no_work, capsys):
    d = tmp_path / "D"
    d.mkdir()
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-c", HOLDER, str(d)], stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert proc.stdout.readline().strip() == "locked"
        _refused(["optimize", "--out", str(d)], capsys, "--out", "another fdm-awe run", f"process {proc.pid}")
    finally:
        proc.kill()
        proc.wait()
    assert (d / LOCK_NAME).exists()  # SIGKILL left the file; the kernel released the lock
    with pytest.raises(WorkStarted):
        main(["optimize", "--out", str(d)])
    assert os.listdir(d) == []
