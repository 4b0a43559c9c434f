"""First use: a kernel that compiles (no cached copy) says so on the standard error while it
compiles, and how long it took; one loaded from the cache says nothing. A real numba kernel
compiled into a fresh cache folder, then loaded from it in a new process."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import time
from pathlib import Path

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
