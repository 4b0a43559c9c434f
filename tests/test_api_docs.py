"""The API documentation builds from the docstrings with sphinx, warnings as errors."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


@pytest.mark.timeout(180)
def test_api_docs_build_without_warnings(tmp_path):
    pytest.importorskip("sphinx")
    out = tmp_path / "html"
    env = dict(os.environ, PYTHONPATH=str(REPO))
    proc = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                           "-d", str(tmp_path / "doctrees"), str(REPO / "docs" / "api"), str(out)],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=170)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    html = (out / "index.html").read_text()
    for name in ("fdm_awe.api.optimize", "fdm_awe.api.fly", "fdm_awe.api.sweep", "fdm_awe.api.load_reference",
                 "fdm_awe.api_results.OptimizeResult", "fdm_awe.api_results.FlightResult",
                 "fdm_awe.api_results.SweepResult"):
        assert f'id="{name}"' in html, name
    # the parameters with their units, from the numpy-style docstrings
    assert "Wind speed [m/s]" in html and "Co-simulation step [s]" in html
    assert not list((REPO / "docs" / "api").glob("_build"))  # nothing written into the checkout
