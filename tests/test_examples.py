"""The notebooks of examples/ run, through the public API only, executed with nbclient.

Each notebook's cell tagged ``parameters`` is replaced by short settings (coarse meshes, one
cycle, one sweep point, fast pacing; the MAVLink ground station on 127.0.0.1), the notebook is
executed in a fresh kernel in a temporary working folder and its outputs are checked.
"""

from __future__ import annotations

import ast
import os
import re
import socket
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
EXAMPLES = REPO / "examples"


def _free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


#: notebook -> the settings its "parameters" cell gets in the test
SHORT = {
    # the coarsest mesh whose references both fly their cycle (coarser ones fly off the path)
    "01_optimise_and_fly.ipynb": 'WIND = 8.0\nMESH = "30,12,3"\nCYCLES = 1',
    "02_fly_an_example_reference.ipynb": 'EXAMPLE = "example:foldable-8"\nCYCLES = 1\nTURBULENCE = "light:1"',
    "03_compare_gliders.ipynb": 'SCENARIO = "paper"\nWINDS = (3.0,)\nMESH = "10,8,3"',
    "04_power_curve.ipynb": ('OUT = "sweep"\nWIND = "3"\nCONFIG = "nominal"\nSCENARIO = "paper"\nMESH = "10,8,3"\n'
                             'WORKERS = 1\nCOLD = True'),
    "05_mavlink_ground_station.ipynb": 'EXAMPLE = "example:nominal-8"\nCYCLES = 1\nREALTIME = 40.0\nPORT = {port}',
}
#: what the executed notebook must print (regular expressions on its text outputs)
PRINTS = {
    "01_optimise_and_fly.ipynb": [r" nominal: ok .*E_net", r"foldable: ok .*E_net", r" nominal: \w+, optimised net",
                                  r"foldable: \w+, optimised net", r"cycle 0: flown net"],
    "02_fly_an_example_reference.ipynb": [r"physical foldable 8.0 m/s", r"calm: ok", r"light:1: ok"],
    "03_compare_gliders.ipynb": [r"nominal +3 +ok", r"foldable +3 +ok"],
    "04_power_curve.ipynb": [r"1 of 1 points converged"],
    "05_mavlink_ground_station.ipynb": [r"ok - [1-9]\d* heartbeats, [1-9]\d* positions, [1-9]\d* winch reports; "
                                        r"WINCH_TLO = [0-9.]+ N"],
}


def test_every_notebook_is_tested_and_uses_only_the_public_api():
    assert sorted(p.name for p in EXAMPLES.glob("*.ipynb")) == sorted(SHORT)
    nbformat = pytest.importorskip("nbformat")
    public = {"optimize", "fly", "sweep", "load_reference"}
    for path in EXAMPLES.glob("*.ipynb"):
        nb = nbformat.read(path, as_version=4)
        nbformat.validate(nb)
        code = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
        tree = ast.parse(code)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                assert not (node.module or "").startswith("fdm_awe"), (path.name, node.module)
            if isinstance(node, ast.Import):
                assert all(a.name == "fdm_awe" or not a.name.startswith("fdm_awe") for a in node.names), path.name
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "fdm_awe":
                assert node.attr in public, (path.name, node.attr)
        assert [c for c in nb.cells if "parameters" in c.metadata.get("tags", [])], path.name
        assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), f"{path.name}: stored outputs"


@pytest.mark.timeout(300)
@pytest.mark.parametrize("name", sorted(SHORT))
def test_notebook_runs(name, tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(EXAMPLES / name, as_version=4)
    cell = next(c for c in nb.cells if "parameters" in c.metadata.get("tags", []))
    cell.source = SHORT[name].format(port=_free_udp_port())
    env_backup = dict(os.environ)
    os.environ.update(PYTHONPATH=os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")])),
                      MPLBACKEND="module://matplotlib_inline.backend_inline", JSBSIM_DEBUG="0")
    try:  # the kernel is this Python (ipykernel's own kernel spec) with this environment, plots inline
        client = nbclient.NotebookClient(nb, timeout=240, kernel_name="python3",
                                         resources={"metadata": {"path": str(tmp_path)}})
        client.execute()
    finally:
        os.environ.clear()
        os.environ.update(env_backup)
    text = "\n".join(o.get("text", "") if o.output_type == "stream" else str(o.get("data", {}).get("text/plain", ""))
                     for c in nb.cells if c.cell_type == "code" for o in c.outputs)
    for pattern in PRINTS[name]:
        assert re.search(pattern, text), (pattern, text[:3000])
    images = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs if "image/png" in o.get("data", {})]
    assert images, "no plot"
    assert sys.executable  # the kernel: ipykernel's native spec runs this interpreter
