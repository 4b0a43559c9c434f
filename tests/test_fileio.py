"""Output files: checked before work, written atomically, JSON without NaN."""

from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest

from fdm_awe.errors import InputError
from fdm_awe.fileio import (atomic_path, atomic_write_text, check_output_dir, check_output_file, json_text,
                            write_json)


def test_check_output_file_accepts_a_new_file(tmp_path):
    assert check_output_file(tmp_path / "a.json", "--json") == tmp_path / "a.json"


@pytest.mark.parametrize("bad, what", [("/proc/x", "not writable"), ("{tmp}/no/such/a.json", "does not exist"),
                                       ("{tmp}", "is a folder")])
def test_check_output_file_refuses_unwritable_places(tmp_path, bad, what):
    with pytest.raises(InputError, match=what) as e:
        check_output_file(bad.format(tmp=tmp_path), "--json")
    assert "--json" in str(e.value) and "\n" not in str(e.value)


def test_check_output_file_refuses_an_input(tmp_path):
    ref = tmp_path / "ref.json"
    ref.write_text("{}")
    with pytest.raises(InputError, match="input of this run"):
        check_output_file(tmp_path / "." / "ref.json", "--json", inputs=[ref, None])


def test_check_output_dir_creates_and_refuses(tmp_path):
    assert check_output_dir(tmp_path / "x" / "y", "--out").is_dir()
    f = tmp_path / "f"
    f.write_text("")
    with pytest.raises(InputError, match="not a folder"):
        check_output_dir(f, "--out")
    with pytest.raises(InputError, match="--out"):
        check_output_dir("/proc/x", "--out")


def test_atomic_write_leaves_the_old_file_on_failure(tmp_path):
    p = tmp_path / "flight.csv"
    atomic_write_text(p, "old\n")
    with pytest.raises(KeyboardInterrupt):
        with atomic_path(p) as tmp:
            tmp.write_text("half a fi")
            raise KeyboardInterrupt
    assert p.read_text() == "old\n"
    assert os.listdir(tmp_path) == ["flight.csv"]  # no temporary file left behind


def test_atomic_path_keeps_the_ending_for_format_sniffing_writers(tmp_path):
    with atomic_path(tmp_path / "a.png") as tmp:
        assert tmp.suffix == ".png" and tmp.parent == tmp_path
        tmp.write_bytes(b"x")
    assert (tmp_path / "a.png").read_bytes() == b"x"


def test_json_never_contains_nan(tmp_path):
    doc = {"a": math.nan, "b": [1.0, math.inf, np.float64("nan")], "c": np.arange(2), "d": np.float32(1.5)}
    text = json_text(doc)
    assert json.loads(text) == {"a": None, "b": [1.0, None, None], "c": [0, 1], "d": 1.5}
    write_json(tmp_path / "x.json", doc)
    assert json.loads((tmp_path / "x.json").read_text())["a"] is None


def test_stale_temporary_files_are_only_those_of_dead_processes_of_this_host(tmp_path):
    """:func:`remove_stale_parts` removes this host's temporary files of processes that ended
    and nothing else: a live process's, another host's and files merely named alike stay."""
    import subprocess
    import sys

    from fdm_awe.fileio import _host, remove_stale_parts

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()  # its pid names no process now (reaped)
    host = _host()
    stale = tmp_path / f".flight.csv.{dead.pid}@{host}.a1b2c3d4.part.csv"
    live = tmp_path / f".flight.csv.{os.getpid()}@{host}.a1b2c3d4.part.csv"
    other_host = tmp_path / f".flight.csv.{dead.pid}@{host}x.a1b2c3d4.part.csv"
    probe = tmp_path / f".fdm-awe-probe.{dead.pid}@{host}.a1b2c3d4.part"
    alike = tmp_path / ".flight.csv.a1b2c3d4.part.csv"  # an older name without its writer
    for p in (stale, live, other_host, probe, alike):
        p.write_text("")
    assert sorted(remove_stale_parts(tmp_path)) == sorted([stale, probe])
    assert sorted(os.listdir(tmp_path)) == sorted(p.name for p in (live, other_host, alike))


def test_lock_folder_is_exclusive_and_leaves_nothing(tmp_path):
    from fdm_awe.fileio import LOCK_NAME, lock_folder

    with lock_folder(tmp_path, "--out"):
        assert (tmp_path / LOCK_NAME).read_text().strip() == str(os.getpid())
        with pytest.raises(InputError, match=f"--out .*another fdm-awe run \\(process {os.getpid()}\\)"):
            lock_folder(tmp_path, "--out")
    assert os.listdir(tmp_path) == []
    lock_folder(tmp_path, "--out").close()  # free again
