"""First use of a fresh install: a short flight does not wait for numba's compiler.

The choice (``fdm-awe fly --compiled``, :mod:`fdm_awe.sim.first_use`) from its rule; the stale-
copy check of the cache on a real kernel; the Python path of one flight leaves the process its
compiled kernels (``jitcache.compiled_once``, the switch restored); and a real flight of an empty
numba cache folder flies on the Python path, says so, and equals the compiled flight bit for bit.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from fdm_awe import jitcache
from fdm_awe.errors import InputError
from fdm_awe.groundstation.linemodels import parse_tether
from fdm_awe.sim import first_use

ROOT = Path(__file__).resolve().parents[1]
REF = ROOT / "tests" / "data" / "ref_physical_nominal_10mps_sized.json"


@pytest.fixture
def jit_on(monkeypatch):
    monkeypatch.delenv(jitcache.JIT_SWITCH, raising=False)
    monkeypatch.delenv(jitcache.JIT_WHY, raising=False)
    if jitcache.jit_off():
        pytest.skip(f"nothing compiles here: {jitcache.jit_off()}")


def test_the_choice_follows_its_rule(jit_on):
    """``no`` and ``yes`` as asked; ``auto`` loads cached kernels, compiles for a flight whose
    Python time exceeds its compiled time by more than the compile time, else the Python path
    with the reason; an unknown policy is a one-line error naming the option."""
    straight, lumped = parse_tether("straight"), parse_tether("lumped:30")
    assert first_use.choose("no", straight, 30.0) == first_use.LoopChoice(False, "--compiled no")
    assert first_use.choose("yes", straight, 30.0, cached=False).compiled
    assert first_use.choose("auto", straight, 30.0, cached=True).compiled
    short = first_use.choose("auto", straight, 30.0, cached=False)
    assert not short.compiled and "no compiled kernels cached" in short.why
    # the rule's edge, on either side, for a line whose Python step is slow
    cost = lumped.kind.python_cost(lumped.param)
    edge = first_use.COMPILE_S / (cost - first_use.COMPILED_COST)
    assert first_use.choose("auto", lumped, 1.05 * edge, cached=False).compiled
    assert not first_use.choose("auto", lumped, 0.95 * edge, cached=False).compiled
    # the lumped line's Python step costs more per simulated second than the straight line's, and
    # more segments more
    assert straight.kind.python_cost(0) < cost < lumped.kind.python_cost(60)
    with pytest.raises(InputError, match="--compiled: 'sometimes' .*auto, yes, no"):
        first_use.choose("sometimes", straight, 30.0)


def test_the_python_path_is_for_its_block_only(jit_on):
    """Inside ``python_path`` compiled code does not run, with the reason given; after it the
    switch is as before and the kernels' getters answer again (nothing kept from inside)."""
    from fdm_awe.sim import kernel

    with jitcache.python_path("a short flight"):
        assert jitcache.jit_off() == "a short flight"
        assert kernel.compiled_kernel() is None
    assert jitcache.jit_off() is None
    assert os.environ.get(jitcache.JIT_SWITCH) is None and os.environ.get(jitcache.JIT_WHY) is None
    assert kernel.compiled_kernel() is not None


STALE = '''
import sys
from fdm_awe import jitcache
import dep_mod
def add(a, b):
    return a + b * 2.0
print(jitcache.is_cached(add, (dep_mod,)))
k = jitcache.compile_cached(add, lambda nb: (nb.float64, nb.float64), (), (dep_mod,), "the test kernel")
print(jitcache.is_cached(add, (dep_mod,)))
'''


def test_a_stale_copy_is_not_a_cached_copy(tmp_path, jit_on):
    """``is_cached``: False before the first compile, True after it, False again once a source the
    kernel is tied to changed (numba would compile anew), True after that compile."""
    (tmp_path / "kern_mod.py").write_text(STALE)
    dep = tmp_path / "dep_mod.py"
    dep.write_text("X = 1\n")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=os.pathsep.join(
        [str(ROOT), str(tmp_path)]))

    def run() -> list[str]:
        r = subprocess.run([sys.executable, "-c", "import kern_mod"], env=env, capture_output=True, text=True,
                           timeout=120)
        assert r.returncode == 0, r.stderr
        return r.stdout.split()

    assert run() == ["False", "True"]
    assert run() == ["True", "True"]
    dep.write_text("X = 22\n")  # another size: another stamp
    assert run() == ["False", "True"]


def _fly(tmp: Path, env: dict, extra: list[str]) -> tuple[dict, str]:
    (tmp / "ref.json").write_bytes(REF.read_bytes())
    out = tmp / "fly.json"
    r = subprocess.run([sys.executable, "-m", "fdm_awe", "fly", "--reference", "ref.json", "--cycles", "1", "--quiet",
                        "--json", str(out)] + extra, cwd=tmp, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    return json.loads(out.read_text()), r.stderr


def test_a_short_first_flight_flies_python_and_equals_the_compiled_one(tmp_path, jit_on):
    """An empty numba cache folder: ``fly --cycles 1`` flies on the Python path and says why;
    ``--compiled no`` says nothing; the flight equals the compiled one of the suite's own cache
    (``--compiled yes``) in everything but the loop's description."""
    fresh = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "empty_cache"), JSBSIM_DEBUG="0",
                 PYTHONPATH=str(ROOT))
    fresh.pop(jitcache.JIT_SWITCH, None)
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "c").mkdir()
    first, said = _fly(tmp_path / "a", fresh, [])
    assert first["loop"]["loop"] == "python" and "no compiled kernels cached" in first["loop"]["reason"]
    assert "fdm-awe: flying on the Python path" in said and "--compiled yes" in said
    assert "fdm-awe: compiling" not in said
    asked, said_no = _fly(tmp_path / "b", fresh, ["--compiled", "no"])
    assert asked["loop"]["reason"] == "--compiled no" and "Python path" not in said_no
    own = dict(fresh)
    own.pop("NUMBA_CACHE_DIR")
    compiled, _ = _fly(tmp_path / "c", own, ["--compiled", "yes"])
    assert compiled["loop"]["loop"] == "compiled" and compiled["loop"]["autopilot_compiled_steps"] > 0
    for doc in (first, asked, compiled):
        for k in ("loop", "wall_s", "realtime_factor"):
            doc.pop(k)
    assert first == compiled and asked == compiled
