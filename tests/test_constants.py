"""One value of g and of sea-level air density in the package: ``fdm_awe/constants.py`` holds
them (``G0``, ``RHO0``); no other module of ``fdm_awe`` writes them as a number (a scan of the
number tokens, so comments and docstrings may name them), and the ground-station definition
takes them from there."""

from __future__ import annotations

import io
import tokenize
from pathlib import Path

from fdm_awe import ROOT
from fdm_awe.constants import G0, RHO0
from fdm_awe.groundstation import load_ground_station

PACKAGE = Path(ROOT) / "fdm_awe"
#: the literals that would be a second g or a second sea-level density
LITERALS = {9.81, 9.80665, 9.8, 32.174, 32.17405, 1.225, 0.0023769, 0.00237689}


def _number_tokens(path: Path) -> list[tuple[int, str]]:
    src = path.read_text()
    out = []
    for tok in tokenize.generate_tokens(io.StringIO(src).readline):
        if tok.type == tokenize.NUMBER:
            try:
                v = float(tok.string)
            except ValueError:
                continue
            if v in LITERALS:
                out.append((tok.start[0], tok.string))
    return out


def test_g_and_rho_are_written_once():
    found = {}
    for p in sorted(PACKAGE.rglob("*.py")):
        if p.name == "constants.py" and p.parent == PACKAGE:
            continue
        hits = _number_tokens(p)
        if hits:
            found[str(p.relative_to(PACKAGE))] = hits
    assert not found, f"g or rho written outside fdm_awe/constants.py: {found}"
    assert {t[1] for t in _number_tokens(PACKAGE / "constants.py")} == {"9.80665", "1.225"}


def test_the_scan_finds_a_literal(tmp_path):
    p = tmp_path / "m.py"
    p.write_text('"""g is 9.81 in words"""\n# 1.225 in a comment\nx = 9.81 * 2\n')
    assert _number_tokens(p) == [(3, "9.81")]


def test_the_line_weighs_and_drags_with_the_package_constants():
    t = load_ground_station().tether
    assert t.gravity == G0 and t.air_density == RHO0
    assert G0 == 9.80665 and RHO0 == 1.225  # the ISA's and JSBSim's sea-level values
