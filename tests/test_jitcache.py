"""First use: a kernel that compiles (no cached copy) says so on the standard error while it
compiles, and how long it took; one loaded from the cache says nothing. A real numba kernel
compiled into a fresh cache folder, then loaded from it in a new process."""

from __future__ import annotations

import ast
import io
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fdm_awe import jitcache


class _Slow:
    def __init__(self, seconds: float) -> None:
        self.seconds = seconds

    def compile(self, sig) -> None:  # noqa: ANN001 - numba's signature
        time.sleep(self.seconds)


def test_a_slow_compile_is_announced_and_a_fast_load_is_silent(monkeypatch):
    """A kernel without a known cache (another numba) that takes longer than the notice time
    is announced; one that is quick is not."""
    monkeypatch.setattr(jitcache, "COMPILE_NOTICE_S", 0.2)
    out = io.StringIO()
    dt = jitcache.compile_with_notice(_Slow(0.6), None, "the test kernel", out)
    text = out.getvalue()
    assert dt >= 0.6
    assert "preparing the test kernel with numba" in text
    assert "the test kernel ready in" in text
    out = io.StringIO()
    jitcache.compile_with_notice(_Slow(0.0), None, "the test kernel", out)
    assert out.getvalue() == ""


KERNEL = '''
import sys, time
from fdm_awe import jitcache
jitcache.COMPILE_NOTICE_S = 600.0  # only the missing cache speaks
def add(a, b):
    return a + b * 2.0
k = jitcache.compile_cached(add, lambda nb: (nb.float64, nb.float64), (), (), "the test kernel")
assert k is not None and k(1.0, 2.0) == 5.0
'''


def test_a_real_kernel_announces_its_compile_once(tmp_path):
    """The first process compiles (the message), the second loads the cached kernel (none)."""
    if jitcache.jit_off():
        pytest.skip(f"nothing compiles here: {jitcache.jit_off()}")
    mod = tmp_path / "kern_mod.py"
    mod.write_text(KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=os.pathsep.join(
        [str(Path(__file__).resolve().parents[1]), str(tmp_path)]))
    runs = [subprocess.run([sys.executable, "-c", "import kern_mod"], env=env, capture_output=True, text=True,
                           timeout=120) for _ in range(2)]
    for r in runs:
        assert r.returncode == 0, r.stderr
    assert "compiling the test kernel with numba" in runs[0].stderr
    assert "the test kernel ready in" in runs[0].stderr
    assert "compiling" not in runs[1].stderr and "preparing" not in runs[1].stderr


# --- one switch: the jit module decides whether compiled code runs and compiles it -------------

PKG = Path(jitcache.__file__).resolve().parent

#: what compiles with numba: called or named only in the jit module
COMPILERS = ("njit", "jit", "register_jitable", "generated_jit", "vectorize", "guvectorize", "cfunc")


def _docstrings(tree: ast.AST) -> set[int]:
    """ids of the docstring constants of ``tree``'s module, classes and functions."""
    out = set()
    for n in ast.walk(tree):
        if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and n.body:
            first = n.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                out.add(id(first.value))
    return out


def _switch_reads_and_compilers(path: Path) -> tuple[list[int], list[int]]:
    """(lines where code names the switch, lines where code names a numba compiler) in ``path``:
    string constants holding ``FDM_AWE_JIT`` outside docstrings, and ``njit``/``register_jitable``/...
    as a name or an attribute."""
    tree = ast.parse(path.read_text())
    docs = _docstrings(tree)
    switch = [n.lineno for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)
              and jitcache.JIT_SWITCH in n.value and id(n) not in docs]
    comp = [n.lineno for n in ast.walk(tree)
            if (isinstance(n, ast.Name) and n.id in COMPILERS) or (isinstance(n, ast.Attribute) and n.attr in COMPILERS)
            or (isinstance(n, ast.alias) and n.name.rsplit(".", 1)[-1] in COMPILERS)]
    return switch, comp


def test_the_switch_is_read_and_code_compiled_in_one_module():
    """``FDM_AWE_JIT`` is named by code (not docs) in the jit module only, once, and only the jit
    module calls numba's compilers; every other module asks it."""
    found = {p.relative_to(PKG).as_posix(): _switch_reads_and_compilers(p) for p in sorted(PKG.rglob("*.py"))}
    switch = {m: s for m, (s, _) in found.items() if s}
    comp = {m: c for m, (_, c) in found.items() if c}
    assert list(switch) == ["jitcache.py"] and len(switch["jitcache.py"]) == 1, switch
    assert list(comp) == ["jitcache.py"], comp
    # the check sees what it must: a read of the switch and a compile in a module of their own
    probe = ast.parse("import os\nfrom numba import njit\n\ndef f():\n    '''FDM_AWE_JIT in a docstring'''\n"
                      "    return os.environ.get('FDM_AWE_JIT'), numba.njit(f)\n")
    assert len(_docstrings(probe)) == 1
    assert sum(isinstance(n, ast.Constant) and n.value == "FDM_AWE_JIT" for n in ast.walk(probe)) == 1


SWITCHED_OFF = '''
import math
import sys
from fdm_awe import jitcache
from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station, lumped, linemodels, substeps
from fdm_awe.sim import autopilot_kernel, kernel
from fdm_awe.sim.loop import CoSim
from fdm_awe.sixdof import JSBSimGlider, Stabilizer
from fdm_awe.sixdof.native import native_jsbsim

assert jitcache.jit_off() == "FDM_AWE_JIT=0"
assert substeps.compiled() is None and substeps.compiled_station() is None and all(k.compiled() is None for k in linemodels.LINE_MODELS)
assert kernel.compiled_kernel() is None and autopilot_kernel.compiled_autopilot_kernel() is None
assert lumped.compiled_function("relax_line") is lumped.relax_line
assert jitcache.compile_cached(abs, None, (), (), "x") is None and jitcache.compile_lazy(abs, (), ()) is abs
g = JSBSimGlider("glider_foldable", wind_ned=(14.0, 0.0, 0.0))  # a kite on 50 m of line at 80 deg
g.reset((50.0 * math.cos(1.396), 0.0, -50.0 * math.sin(1.396)), 14.0, gamma=0.0, psi=math.pi, alpha=0.104)
assert native_jsbsim(g.fdm, ["fcs/aileron-cmd-norm"], [])[1] == "FDM_AWE_JIT=0"
gs = GroundStation(load_ground_station(), tether="lumped:4", wind_ned=(14.0, 0.0, 0.0))
gs.reset(tether_length=50.0, reel_speed=0.0, mode="motor")
assert not gs.drivetrain.is_compiled
assert not gs.drivetrain.may_compile and gs.compiled_step_args(1.0 / 120.0) is None
sim = CoSim(g, gs, Stabilizer(g, alpha_cmd=0.104, winch=WinchCommand("motor", reel_speed_ref=0.0)))
res = sim.run(0.5)
assert res.steps == 60 and sim.loop == "python" and "FDM_AWE_JIT=0" in sim.loop_reason, (res.steps, sim.loop)
assert "numba" not in sys.modules, "numba imported although switched off"
print("python path")
'''


def test_switched_off_everything_runs_the_python_path():
    """``FDM_AWE_JIT=0`` (a fresh process): nothing compiles, numba is not even imported, and a
    co-simulation of the glider on a lumped line runs the Python loop and station."""
    env = dict(os.environ, FDM_AWE_JIT="0", JSBSIM_DEBUG="0", PYTHONPATH=os.pathsep.join(
        [str(PKG.parent)] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else [])))
    r = subprocess.run([sys.executable, "-c", SWITCHED_OFF], env=env, capture_output=True, text=True, timeout=120,
                       cwd=PKG.parent)
    assert r.returncode == 0 and "python path" in r.stdout, r.stderr[-3000:]
