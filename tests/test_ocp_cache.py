"""On-disk NLP cache (fdm_awe/ocp/nlpcache.py): round trip, keys, damaged entries, switch."""

from __future__ import annotations

import time

import numpy as np
import pytest

from fdm_awe.ocp import nlpcache
from fdm_awe.ocp.guess import default_starts, loop_guess
from fdm_awe.ocp.problem import CycleProblem, Mesh
from fdm_awe.ocp.build import get_nlp
from fdm_awe.pointmass.model import wind_vector

MESH = Mesh(6, 4, 3)


@pytest.fixture
def cache_on(tmp_path, monkeypatch):
    monkeypatch.setenv(nlpcache.DIR_ENV, str(tmp_path))
    monkeypatch.setenv(nlpcache.SWITCH_ENV, "on")
    return tmp_path / "nlp"


def _entries(folder, timeout_s: float = 120.0, avoid: bytes | None = None):
    """The cache entries once one is there (a new NLP is written by a background process)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout_s:
        found = sorted(folder.glob("*.casadi")) if folder.is_dir() else []
        if found and (avoid is None or found[0].read_bytes() != avoid):
            return found
        time.sleep(0.1)
    return []


def _problem(**kw) -> CycleProblem:
    return CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=MESH, **kw)


def _solve(nlp, pr):
    wind = wind_vector(pr.wind_speed, pr.wind_from_deg)[:2]
    phases, k = loop_guess(pr, nlp.model, default_starts(pr)[0], wind)
    return nlp.solve(nlp.pack(phases), nlp.params(wind, 1.0, k), options={"ipopt.max_iter": 40})


def test_loaded_nlp_gives_the_same_iterates(cache_on):
    """A solve from the loaded NLP follows the freshly built one: same iteration count, same
    iterate within rounding (the same functions, serialised)."""
    pr = _problem()
    built, _ = get_nlp(pr, cache=False, disk_cache=True)
    files = _entries(cache_on)
    assert len(files) == 1 and not hasattr(built, "loaded_from")
    loaded, _ = get_nlp(pr, cache=False, disk_cache=True)
    assert getattr(loaded, "loaded_from", None) == str(files[0])
    for name in ("lbw", "ubw", "lbg", "ubg"):
        assert np.array_equal(getattr(built, name), getattr(loaded, name)), name
    assert loaded.nw == built.nw and loaded.g_names == built.g_names
    for a, b in zip(built.phases, loaded.phases):
        assert np.array_equal(a.idx_X, b.idx_X) and np.array_equal(a.idx_U, b.idx_U) and a.idx_T == b.idx_T
    ra, rb = _solve(built, pr), _solve(loaded, pr)
    assert ra.iterations == rb.iterations > 0
    assert np.allclose(ra.w, rb.w, rtol=1e-9, atol=1e-12)
    assert built.energies(ra.w, ra.params) == pytest.approx(loaded.energies(ra.w, ra.params), rel=1e-12)


def test_key_covers_the_structure_but_not_the_wind():
    pr = _problem()
    nlp, _ = get_nlp(pr, disk_cache=False)
    model = nlp.model
    assert nlpcache.entry_key(pr, model) == nlpcache.entry_key(pr.with_wind(5.0, 150.0), model)
    assert nlpcache.entry_key(pr, model) != nlpcache.entry_key(_problem(d_tf=260.0), model)
    assert nlpcache.entry_key(pr, model) != nlpcache.entry_key(CycleProblem(scenario="physical", config="nominal",
                                                                           mesh=Mesh(6, 4, 2)), model)


def test_damaged_entry_is_ignored_with_one_warning_and_rebuilt(cache_on, capsys):
    pr = _problem()
    get_nlp(pr, cache=False, disk_cache=True)
    (path,) = _entries(cache_on)
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF  # one damaged byte, the name (and its checksum) unchanged
    path.write_bytes(bytes(data))
    capsys.readouterr()
    nlp, _ = get_nlp(pr, cache=False, disk_cache=True)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unusable entry ignored and rebuilt" in err[0] and str(path) in err[0]
    assert not hasattr(nlp, "loaded_from")  # built again
    (again,) = _entries(cache_on, avoid=bytes(data))
    assert again.read_bytes() != bytes(data)
    loaded, _ = get_nlp(pr, cache=False, disk_cache=True)  # the rewritten entry loads
    assert getattr(loaded, "loaded_from", None) == str(again)


def test_truncated_entry_is_ignored(cache_on, capsys):
    pr = _problem()
    get_nlp(pr, cache=False, disk_cache=True)
    (path,) = _entries(cache_on)
    path.write_bytes(path.read_bytes()[:1000])
    capsys.readouterr()
    nlp, _ = get_nlp(pr, cache=False, disk_cache=True)
    assert not hasattr(nlp, "loaded_from")
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_switched_off_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.setenv(nlpcache.DIR_ENV, str(tmp_path))
    monkeypatch.setenv(nlpcache.SWITCH_ENV, "off")
    get_nlp(_problem(), cache=False, disk_cache=True)
    time.sleep(1.0)  # a background writer would have written a small NLP by now
    assert not list(tmp_path.rglob("*.casadi"))


def test_cache_folder_from_the_environment(tmp_path, monkeypatch):
    monkeypatch.delenv(nlpcache.DIR_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert nlpcache.cache_dir() == tmp_path / "fdm-awe" / "nlp"
    monkeypatch.setenv(nlpcache.DIR_ENV, str(tmp_path / "x"))
    assert nlpcache.cache_dir() == tmp_path / "x" / "nlp"
