"""Dependencies follow the architecture: the autopilot defines its vehicle interface, parameters
and modes, and the MAVLink package adapts to them (never the other way round); the recordings
take the phase names from the trajectory module, not from the autopilot; the trajectory module
(the reference file, its phases and its sampler) depends on neither.

Two views: every import statement of a package's files (also those inside functions, read from
the source), and the modules a fresh interpreter has loaded after importing each module of a
package (what the imports pull in transitively).
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import fdm_awe

PKG = Path(fdm_awe.__file__).resolve().parent
REPO = PKG.parent

#: package (module name prefix) -> the packages it must never import
RULES = {
    "fdm_awe.autopilot": ("fdm_awe.mavlink", "fdm_awe.recording", "fdm_awe.commands"),
    "fdm_awe.recording": ("fdm_awe.autopilot", "fdm_awe.mavlink", "fdm_awe.commands"),
    "fdm_awe.trajectory": ("fdm_awe.autopilot", "fdm_awe.mavlink", "fdm_awe.recording", "fdm_awe.commands",
                           "fdm_awe.sim.flight", "fdm_awe.sweep"),
}


#: The layers of docs/architecture.md, bottom up: a unit imports only units of a LOWER layer or
#: its own (units are the sub-packages and the top-level modules of fdm_awe; the package's own
#: ``__init__`` (ROOT, version) sits below everything).
LAYERS: tuple[tuple[str, ...], ...] = (
    ("errors", "units", "defaults", "constants", "slots"),
    ("fileio", "jitcache", "progress", "turbulence", "example_refs", "mode_table"),
    ("definitions",),
    ("pointmass", "sixdof"),
    ("wind",),
    ("groundstation",),
    ("trajectory",),
    ("ocp",),
    ("autopilot",),
    ("sim",),
    ("mavlink", "recording", "sweep"),
    ("commands",),
    ("cli",),
    ("api_results",),
    ("api", "__main__"),
)
RANK = {unit: i for i, layer in enumerate(LAYERS) for unit in layer}


def _unit(module: str) -> str:
    """``fdm_awe.X...`` -> ``X`` (the unit), ``fdm_awe`` -> ``""`` (the package's own __init__)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def test_every_unit_has_a_layer() -> None:
    units = {p.stem if p.is_file() else p.name for p in PKG.iterdir()
             if (p.suffix == ".py" and p.stem != "__init__") or (p.is_dir() and (p / "__init__.py").exists())}
    assert units == set(RANK), (sorted(units - set(RANK)), sorted(set(RANK) - units))


def test_imports_point_down_the_layers() -> None:
    """Every import statement of the package (also those inside functions) names a module of its
    own unit, of a lower layer, or the package's own __init__: no cycles between units."""
    bad = []
    for path in sorted(PKG.rglob("*.py")):
        module = ".".join(("fdm_awe", *path.relative_to(PKG).with_suffix("").parts)).removesuffix(".__init__")
        own = _unit(module)
        for name in _imports(module):
            if not name.startswith("fdm_awe"):
                continue
            unit = _unit(name)
            if unit in ("", own) or unit not in RANK:  # the package itself; a name imported from it
                continue
            if RANK[unit] >= RANK[own]:
                bad.append(f"{module} imports {name} (layer {RANK[unit]} >= {RANK[own]})")
    assert not bad, "\n".join(bad)


def _modules(prefix: str) -> list[str]:
    """Module names of the package (or module) ``prefix``."""
    rel = Path(*prefix.split(".")[1:])
    if (PKG / rel).is_dir():
        return sorted(".".join(("fdm_awe", *p.relative_to(PKG).with_suffix("").parts)).removesuffix(".__init__")
                      for p in (PKG / rel).rglob("*.py"))
    return [prefix]


def _source(module: str) -> Path:
    rel = Path(*module.split(".")[1:])
    return PKG / rel / "__init__.py" if (PKG / rel).is_dir() else (PKG / rel).with_suffix(".py")


def _imports(module: str) -> set[str]:
    """Every module named by an import statement of ``module``'s source (relative imports resolved)."""
    path = _source(module)
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            out.add(name)
            out.update(f"{name}.{a.name}" for a in node.names)  # ``from pkg import module``
    return out


def _hits(names: set[str], forbidden: tuple[str, ...]) -> list[str]:
    return sorted(n for n in names if any(n == f or n.startswith(f + ".") for f in forbidden))


@pytest.mark.parametrize("layer", sorted(RULES))
def test_import_statements_follow_the_layers(layer: str) -> None:
    modules = _modules(layer)
    assert modules, layer
    bad = {m: _hits(_imports(m), RULES[layer]) for m in modules}
    assert not {m: h for m, h in bad.items() if h}, bad


def test_loaded_modules_follow_the_layers() -> None:
    """Import each module of a layer in a fresh interpreter: nothing forbidden gets loaded."""
    probe = (
        "import importlib, json, sys\n"
        "mods = json.loads(sys.argv[1])\n"
        "before = set(sys.modules)\n"
        "for m in mods:\n"
        "    importlib.import_module(m)\n"
        "print(json.dumps(sorted(set(sys.modules) - before)))\n"
    )
    env = dict(os.environ, JSBSIM_DEBUG="0", MPLBACKEND="Agg")
    env["PYTHONPATH"] = str(REPO) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    for layer, forbidden in RULES.items():
        mods = _modules(layer)
        res = subprocess.run([sys.executable, "-c", probe, json.dumps(mods)], cwd=REPO, env=env,
                             capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr[-2000:]
        loaded = set(json.loads(res.stdout.strip().splitlines()[-1]))
        assert set(mods) <= loaded, (layer, set(mods) - loaded)
        assert not _hits(loaded, forbidden), (layer, _hits(loaded, forbidden))


def test_the_mavlink_package_adapts_to_the_autopilot() -> None:
    """The link's vocabulary is the autopilot's own objects: the package's public face offers
    them, and no module of the link defines its own parameter store, vehicle interface or mode
    table."""
    import fdm_awe.mavlink as link
    from fdm_awe import mode_table
    from fdm_awe.autopilot import params, vehicle
    from fdm_awe.mavlink import vehicle as link_vehicle

    assert link.ParamStore is params.ParamStore and link.Param is params.Param
    assert link.MODE_NUMBERS is mode_table.MODE_NUMBERS and link.MODE_NAMES is mode_table.MODE_NAMES
    assert link.Waypoint is vehicle.Waypoint and link.VehicleInterface is vehicle.VehicleInterface
    own = {n for m in _modules("fdm_awe.mavlink") for n in _top_level_definitions(m)}
    assert not own & {"ParamStore", "Param", "MODE_NUMBERS", "MODE_NAMES", "Waypoint", "VehicleInterface", "PHASES"}
    assert tuple(link_vehicle.PHASE_CODES) == vehicle.PHASES  # a wire number for every vehicle phase


def _top_level_definitions(module: str) -> set[str]:
    """The names ``module`` defines at its top level (functions, classes, assignments)."""
    tree = ast.parse(_source(module).read_text())
    out: set[str] = set()
    for st in tree.body:
        if isinstance(st, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            out.add(st.name)
        elif isinstance(st, (ast.Assign, ast.AnnAssign)):
            for t in (st.targets if isinstance(st, ast.Assign) else [st.target]):
                out.update(n.id for n in ast.walk(t) if isinstance(n, ast.Name))
    return out


def test_one_phase_table() -> None:
    """The autopilot, the optimiser's result and the recordings use the trajectory's phase names:
    none of them defines its own."""
    from fdm_awe import trajectory
    from fdm_awe.autopilot import auto_mode
    from fdm_awe.recording import series

    assert trajectory.PHASE_NAMES == ("generation", "recovery")
    assert (trajectory.GENERATION, trajectory.RECOVERY) == (0, 1)
    assert vars(auto_mode)["PHASE_NAMES"] is vars(series)["PHASE_NAMES"] is trajectory.PHASE_NAMES
    for unit in ("fdm_awe.autopilot", "fdm_awe.ocp", "fdm_awe.recording", "fdm_awe.sim"):
        own = {m: _top_level_definitions(m) & {"PHASE_NAMES", "GENERATION", "RECOVERY"} for m in _modules(unit)}
        assert not {m: n for m, n in own.items() if n}, own
