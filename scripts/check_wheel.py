#!/usr/bin/env python3
"""Wheel check: the package as a user installs it, away from this checkout.

Steps (docs/design.md section 2), each timed, all in one temporary folder that is removed at
the end whatever happens (``--keep`` keeps it):

1. copy the checkout's files (tracked and untracked, not ignored) into ``src/``;
2. build the sdist from that copy (setuptools' own build backend), check that it holds
   ``setup.py``, ``pyproject.toml`` and every file of ``aircraft/``, ``engine/``, ``tether/``,
   ``tests/``, ``scripts/``, ``docs/`` and ``examples/`` (MANIFEST.in);
3. build the wheel from the sdist (``pip wheel --no-deps``), check that it holds every
   definition file as ``fdm_awe/data/...``, the example references as
   ``fdm_awe/data/examples/``, the project URLs, a long description without relative links,
   and nothing outside ``fdm_awe/`` and its metadata;
4. create a fresh virtual environment and install the wheel into it WITH its dependencies
   (not editable; pip's download cache makes a second run quick; ``--no-compile`` halves the
   install, Python compiles what it imports);
5. from a working directory outside the checkout: ``import fdm_awe`` resolves the package and
   its ``ROOT`` inside the new environment, and JSBSim loads every aircraft from there;
   ``fdm-awe info``; a short ``fdm-awe optimize`` (paper, nominal, 3 m/s, coarse mesh) with
   ``--json``; ``fdm-awe fly --cycles 1`` on a stored reference copied out of ``tests/data/``,
   four times: the first two find no compiled kernels and must fly on the Python path, say so and
   differ by at most :data:`FIRST_USE_MAX_S` (a short flight does not wait for the compiler,
   fdm_awe/sim/first_use.py); the third, with ``--compiled yes``, compiles numba's kernels and
   must say so; the fourth must load them and fly compiled without a word (the last lines print
   the four times);
   ``fdm-awe fly --cycles 1`` with no reference (it optimises its own, with the defaults);
   ``fdm-awe fly --cycles 1 --reference example:foldable-8`` (an example reference carried as
   package data); ``fdm-awe info --export DIR`` (every definition file); the Python API's
   ``fdm_awe.load_reference("example:nominal-8")``. Each must exit 0, report status ``ok`` in
   its JSON and write nothing but the files it was told to write. The wheel must carry the
   example references and the project URLs;
6. every command line of README.md that runs a program of the wheel (``fdm-awe``, ``rerun``), in
   the short variants of tests/test_docs_commands.py, from a folder outside the checkout: a
   line naming a file of ``tests/data/`` fails the check (the wheel carries its example
   references as ``example:NAME``). ``--no-readme`` skips this step.

Exit status 0 only if every step passed, 1 otherwise (the failing step's output is printed),
2 on bad options. The last line says ``wheel check: ok ...`` or ``wheel check: FAILED ...``.
scripts/run_tests.sh runs it before pytest (``FDM_AWE_WHEEL_CHECK=0`` skips it there).

usage: python scripts/check_wheel.py [--keep] [--python PY] [--no-readme]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import time
import zipfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
from fdm_awe import DEFINITION_FOLDERS  # noqa: E402  (the checkout's package: names only)
from fdm_awe.example_refs import EXAMPLES  # noqa: E402  (the example references the wheel carries)
#: Folders whose every file the sdist holds (MANIFEST.in).
SDIST_FOLDERS = (*DEFINITION_FOLDERS, "tests", "scripts", "docs", "examples")
#: Stored reference flown by the check (copied out of the checkout first).
REFERENCE = REPO / "tests" / "data" / "ref_physical_nominal_8mps.json"
#: Names never copied when the checkout is not a git work tree.
_SKIP = {".git", ".venv", "build", "dist", "runs", "out", "__pycache__", ".pytest_cache"}
#: Seconds any one step may take before the check fails (a fresh install downloads ~0.5 GB).
STEP_TIMEOUT_S = 1800.0


class CheckFailed(Exception):
    """One step of the check failed; the message says which and why."""


def source_files(repo: Path = REPO) -> list[Path]:
    """Files of the checkout a build sees, relative to ``repo``: git's tracked and untracked,
    not ignored files in a work tree, else every file outside build outputs and environments."""
    if (repo / ".git").exists() and shutil.which("git"):
        out = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                             cwd=repo, capture_output=True, check=True).stdout
        return sorted({Path(p) for p in out.decode().split("\0") if p and (repo / p).is_file()})
    files = []
    for path in repo.rglob("*"):
        rel = path.relative_to(repo)
        if path.is_file() and not any(part in _SKIP or part.endswith(".egg-info") for part in rel.parts):
            files.append(rel)
    return sorted(files)


def copy_source(dest: Path, repo: Path = REPO) -> int:
    """Copy the checkout's source files into ``dest``; returns how many."""
    files = source_files(repo)
    for rel in files:
        (dest / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(repo / rel, dest / rel)
    return len(files)


def definition_files(src: Path, folders: tuple[str, ...] = DEFINITION_FOLDERS) -> list[str]:
    """Every file below ``folders`` of ``src`` as POSIX paths relative to ``src``."""
    return sorted(p.relative_to(src).as_posix() for folder in folders
                  for p in (src / folder).rglob("*") if p.is_file() and "__pycache__" not in p.parts)


def check_sdist_members(sdist: Path, src: Path) -> None:
    """The sdist holds the build files, README and every file of ``src``'s definition folders,
    tests, scripts and docs (MANIFEST.in), so it builds the wheel and runs the tests (CheckFailed)."""
    with tarfile.open(sdist) as tar:
        names = {n.split("/", 1)[1] for n in tar.getnames() if "/" in n}
    want = ["setup.py", "pyproject.toml", "MANIFEST.in", "README.md", *definition_files(src, SDIST_FOLDERS)]
    missing = [n for n in want if n not in names]
    if missing:
        raise CheckFailed(f"sdist {sdist.name} lacks {len(missing)} file(s): {', '.join(missing[:5])}")


#: a Markdown link or image: (``!`` or empty, label, target)
LINK = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)\)")


def relative_links(text: str) -> list[str]:
    """The targets of ``text``'s Markdown links and images that are neither absolute URLs nor
    in-page anchors (they resolve against the repository only)."""
    return [t for _, _, t in LINK.findall(text) if not (re.match(r"^[a-z][a-z0-9+.-]*:", t, re.I) or t.startswith("#"))]


def check_wheel_members(wheel: Path, src: Path) -> None:
    """The wheel holds every definition file of ``src`` as ``fdm_awe/data/...`` and nothing
    outside ``fdm_awe/`` and its ``.dist-info`` (CheckFailed)."""
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
    missing = [n for n in definition_files(src) if f"fdm_awe/data/{n}" not in names]
    if missing:
        raise CheckFailed(f"wheel {wheel.name} lacks {len(missing)} definition file(s): {', '.join(missing[:5])}")
    missing = [n for n in EXAMPLES.values() if f"fdm_awe/data/examples/{n}" not in names]
    if missing:
        raise CheckFailed(f"wheel {wheel.name} lacks {len(missing)} example reference(s): {', '.join(missing[:5])}")
    meta = next((n for n in names if n.endswith(".dist-info/METADATA")), None)
    with zipfile.ZipFile(wheel) as zf:
        urls = [line for line in zf.read(meta).decode().splitlines() if line.startswith("Project-URL:")] if meta else []
    if not any(u.startswith("Project-URL: Homepage,") for u in urls):
        raise CheckFailed(f"wheel {wheel.name}: no project URLs in its metadata (Homepage, Documentation, Source)")
    with zipfile.ZipFile(wheel) as zf:
        rel = relative_links(zf.read(meta).decode()) if meta else []
    if rel:
        raise CheckFailed(f"wheel {wheel.name}: its long description (the package index page) has {len(rel)} relative "
                          f"link(s), which break there: {', '.join(rel[:3])}")
    stray = sorted(n for n in names if not n.startswith(("fdm_awe/", "fdm_awe-")))
    if stray:
        raise CheckFailed(f"wheel {wheel.name} installs files outside fdm_awe/: {', '.join(stray[:5])}")


def run(step: str, cmd: list[str], cwd: Path, env: dict[str, str] | None = None, *, merged: bool = False) -> str:
    """Run ``cmd`` in ``cwd``; its output (``merged``: stdout then stderr), or CheckFailed with
    the exit code and the output's tail."""
    try:
        proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, errors="replace",
                              timeout=STEP_TIMEOUT_S)
    except subprocess.TimeoutExpired as exc:
        raise CheckFailed(f"{step}: no result after {exc.timeout:.0f} s: {' '.join(cmd)}") from None
    if proc.returncode != 0:
        tail = "\n".join((proc.stdout + proc.stderr).strip().splitlines()[-25:])
        raise CheckFailed(f"{step}: exit {proc.returncode}: {' '.join(cmd)}\n{tail}")
    return proc.stdout + proc.stderr if merged else proc.stdout


def build_sdist(src: Path, dist: Path, python: str, tools: Path) -> Path:
    """Build the sdist of the source tree ``src`` into ``dist`` with setuptools' build backend
    (installed into ``tools`` by ``python``'s pip), without any warning of setuptools (deprecated
    configuration), and check its members; returns its path."""
    run("build tools", [python, "-m", "pip", "install", "-q", "--target", str(tools), "setuptools>=77"], cwd=dist)
    env = dict(user_env(), PYTHONPATH=str(tools))
    out = run("sdist", [python, "-c", "import sys; from setuptools import build_meta as b; print('sdist', b.build_sdist(sys.argv[1]))",
                        str(dist)], cwd=src, env=env, merged=True)
    # Python warnings of the build ("...DeprecationWarning: ...", "SetuptoolsWarning: ..."), not
    # distutils' notes on MANIFEST.in patterns that match nothing in this copy ("warning: no ...")
    warnings = [line.strip() for line in out.splitlines() if "Warning" in line or "deprecat" in line.lower()]
    if warnings:
        raise CheckFailed("sdist: the build warns: " + " | ".join(warnings[:5]))
    sdist = dist / next(line.split()[1] for line in out.splitlines() if line.startswith("sdist "))
    check_sdist_members(sdist, src)
    return sdist


def build_wheel(sdist: Path, dist: Path, python: str, src: Path) -> Path:
    """Build the wheel from ``sdist`` into ``dist`` (``pip wheel --no-deps``, isolated build) and
    check its members against the source tree ``src``; returns its path."""
    run("wheel from the sdist", [python, "-m", "pip", "wheel", "-q", "--no-deps", str(sdist), "-w", str(dist)], cwd=dist)
    (wheel,) = dist.glob("*.whl")
    check_wheel_members(wheel, src)
    return wheel


def json_status(step: str, path: Path) -> dict:
    """The JSON document a command wrote, which must say status ``ok`` (CheckFailed)."""
    if not path.is_file():
        raise CheckFailed(f"{step}: wrote no {path.name}")
    doc = json.loads(path.read_text())
    if doc.get("status") != "ok":
        raise CheckFailed(f"{step}: status {doc.get('status')!r} in {path.name} ({doc.get('message') or doc.get('reason')})")
    return doc


def only_files(step: str, work: Path, allowed: set[str]) -> None:
    """``work`` holds no file but ``allowed`` (CheckFailed naming the others)."""
    extra = sorted(p.name for p in work.iterdir() if p.name not in allowed)
    if extra:
        raise CheckFailed(f"{step}: wrote files it was not told to write: {', '.join(extra)}")


def user_env() -> dict[str, str]:
    """Environment of a user of the installed package: no path into this checkout."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "PYTHONSTARTUP")}
    env.update(JSBSIM_DEBUG="0", MPLBACKEND="Agg", PYTHONNOUSERSITE="1")
    return env


#: Run as ``python -c IMPORT_CHECK INSTALL_DIR``: the package and its ROOT lie inside INSTALL_DIR
#: (not in this checkout); JSBSim flies every aircraft from ROOT (the reset file included); every
#: definition file loads. Prints ROOT.
IMPORT_CHECK = """
import math, sys
from pathlib import Path
import fdm_awe
where = Path(sys.argv[1]).resolve()
for what, path in (("fdm_awe", Path(fdm_awe.__file__)), ("fdm_awe.ROOT", Path(fdm_awe.ROOT))):
    if not path.resolve().is_relative_to(where):
        sys.exit(f"{what} is {path}, not inside {where}")
from fdm_awe.sixdof.adapter import JSBSimGlider
for name in ("glider_unfolded", "glider_folded", "glider_foldable"):
    glider = JSBSimGlider(name)
    if not glider.fdm.load_ic("reset00", True):
        sys.exit(f"JSBSim cannot load {name}'s reset00 from {fdm_awe.ROOT}")
    glider.reset((0.0, 0.0, -100.0), 15.0 if name != "glider_folded" else 25.0)
    for _ in range(24):
        glider.step()
    if not glider.state().is_finite():
        sys.exit(f"{name} from {fdm_awe.ROOT}: non-finite state after 0.2 s")
from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.definitions.engine import load_electric_drive
from fdm_awe.groundstation.definitions import load_ground_station
from fdm_awe.autopilot.config import load_autopilot_definition
load_glider(), load_electric_drive(), load_ground_station(), load_autopilot_definition()
print(fdm_awe.ROOT)
"""


#: the steps of the first flight of the fresh install (no compiled kernels: the Python path, said),
#: the same flight again, the flight that compiles the kernels (``--compiled yes``, said) and the
#: flight that loads them from the install's cache
FIRST_FLY = f"fdm-awe fly --cycles 1 --reference ({REFERENCE.name}), first (Python path, nothing compiled yet)"
SECOND_FLY = f"fdm-awe fly --cycles 1 --reference ({REFERENCE.name}), second"
COMPILE_FLY = f"fdm-awe fly --cycles 1 --reference ({REFERENCE.name}) --compiled yes (numba compiles)"
CACHED_FLY = f"fdm-awe fly --cycles 1 --reference ({REFERENCE.name}), compiled kernels cached"
#: the first flight of a fresh install may take at most this much longer [s] than the second
FIRST_USE_MAX_S = 10.0


def _docs_test_module():
    """``tests/test_docs_commands.py`` of the checkout: its extraction and short variants of the
    documented command lines (needs pytest, a dev extra)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("_docs_commands", REPO / "tests" / "test_docs_commands.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # its dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


#: the programs of README lines the wheel provides (scripts, bash and MAVProxy are the checkout's)
WHEEL_PROGRAMS = ("fdm-awe", "rerun")


def readme_commands(readme: Path = REPO / "README.md") -> list[tuple[str, list[str], bool]]:
    """The README's command lines of the wheel's programs, as the docs test runs them (short
    variants): (``README.md:LINE``, argv with the program's name first, whether it reads other
    lines' outputs). A line that names a file of ``tests/data/`` is refused (CheckFailed): the
    wheel does not carry the tests, an example reference is ``example:NAME``. A stored reference
    that a variant flies instead of optimising is named as its example (or copied beside the run
    when it is none)."""
    mod = _docs_test_module()
    lines = mod._expand(mod.documented_commands((readme,), readme.parent))
    by_file = {f: n for n, f in EXAMPLES.items()}
    out = []
    for d, p in zip(lines, mod.plans(lines)):
        if p.how not in ("run", "variant") or Path(p.argv[0]).name not in WHEEL_PROGRAMS:
            continue
        where = f"{readme.name}:{d.lineno}"
        if "tests/data/" in d.text:
            name = next(w for w in d.text.split() if "tests/data/" in w)
            example = by_file.get(Path(name).name)
            raise CheckFailed(f"{where}: {name} is a file of the checkout, which the wheel does not carry"
                              + (f"; write example:{example}" if example else ""))
        argv = [Path(p.argv[0]).name]
        for a in p.argv[1:]:
            if a.startswith("tests/data/") and Path(a).name in by_file:
                a = f"example:{by_file[Path(a).name]}"
            argv.append(a)
        out.append((where, argv, p.late))
    return sorted(out, key=lambda w: w[2])  # lines that read other lines' outputs last


def run_readme(work: Path, bin_dir: Path, env: dict[str, str], readme: Path = REPO / "README.md") -> str:
    """Run :func:`readme_commands` of ``readme`` in ``work`` with the programs of ``bin_dir`` (the
    wheel's environment); a ``--mavlink`` line sends to a UDP socket here, which must receive
    frames."""
    import socket

    cmds = readme_commands(readme)
    for where, argv, _ in cmds:
        for a in argv:
            if a.startswith("tests/data/"):  # a stored reference standing in for an optimisation
                (work / a).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy(REPO / a, work / a)
        sock = None
        if any("{UDP_PORT}" in a for a in argv):
            sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            sock.bind(("127.0.0.1", 0))
            argv = [a.replace("{UDP_PORT}", str(sock.getsockname()[1])) for a in argv]
        try:
            run(where, [str(bin_dir / argv[0]), *argv[1:]], work, dict(env, JSBSIM_DEBUG="0", MPLBACKEND="Agg"))
            if sock is not None:
                sock.settimeout(0.2)
                try:
                    sock.recv(4096)
                except OSError:
                    raise CheckFailed(f"{where}: no MAVLink frame reached the ground station's socket") from None
        finally:
            if sock is not None:
                sock.close()
    return f"{len(cmds)} lines"


def wheel_check(tmp: Path, python: str, log=print, readme: bool = True) -> list[tuple[str, float]]:
    """Run every step in ``tmp``; returns (step, seconds) pairs, raises CheckFailed. ``readme``:
    also run the README's command lines of the wheel's programs (:func:`run_readme`)."""
    times: list[tuple[str, float]] = []

    def step(name: str, fn):
        t0 = time.perf_counter()
        try:
            out = fn()
        except CheckFailed:
            raise
        except Exception as exc:  # an unexpected output (missing file, malformed JSON, ...)
            raise CheckFailed(f"{name}: {type(exc).__name__}: {exc}") from exc
        times.append((name, time.perf_counter() - t0))
        log(f"wheel check: {name}: ok ({times[-1][1]:.1f} s){' ' + out if isinstance(out, str) and out else ''}")

    src, dist, tools, venv, work = (tmp / n for n in ("src", "dist", "tools", "venv", "work"))
    for d in (src, dist, work):
        d.mkdir()
    vpy = venv / ("Scripts" if os.name == "nt" else "bin") / "python"
    cli = vpy.parent / "fdm-awe"
    step("copy the checkout", lambda: f"{copy_source(src)} files")

    def sdist():
        run("virtual environment", [python, "-m", "venv", str(venv)], cwd=tmp)
        return build_sdist(src, dist, str(vpy), tools).name

    step("fresh environment and sdist", sdist)
    step("wheel", lambda: build_wheel(next(dist.glob("*.tar.gz")), dist, str(vpy), src).name)
    wheel_file = lambda: str(next(dist.glob("*.whl")))  # noqa: E731
    step("install the wheel with its dependencies",
         lambda: run("install", [str(vpy), "-m", "pip", "install", "-q", "--no-compile", wheel_file()], cwd=tmp) and "")
    env = user_env()
    step("import outside the checkout",
         lambda: "ROOT " + run("import", [str(vpy), "-c", IMPORT_CHECK, str(venv)], work, env).strip())
    step("fdm-awe info", lambda: run("fdm-awe info", [str(cli), "info"], work, env) and "")

    def optimize():
        run("fdm-awe optimize", [str(cli), "optimize", "--scenario", "paper", "--config", "nominal", "--wind", "3",
                                 "--mesh", "10,8,3", "--time-budget", "60", "--json", "opt.json"], work, env)
        doc = json_status("fdm-awe optimize", work / "opt.json")
        only_files("fdm-awe optimize", work, {"opt.json", "opt.trajectory.json"})
        return f"E_net {doc['E_net_J']:.0f} J"

    step("fdm-awe optimize (paper nominal 3 m/s, mesh 10,8,3)", optimize)

    def fly_reference(which: str):
        shutil.copy(REFERENCE, work / "ref.json")
        extra = ["--compiled", "yes"] if which == COMPILE_FLY else []
        out = run("fdm-awe fly", [str(cli), "fly", "--reference", "ref.json", "--cycles", "1", "--quiet", "--json",
                                  "fly.json"] + extra, work, env, merged=True)
        doc = json_status("fdm-awe fly", work / "fly.json")
        only_files("fdm-awe fly", work, {"opt.json", "opt.trajectory.json", "ref.json", "fly.json"})
        said_compile, said_python, loop = "fdm-awe: compiling" in out, "fdm-awe: flying on the Python path" in out, \
            doc["loop"]["loop"]
        if which in (FIRST_FLY, SECOND_FLY) and not (said_python and loop == "python" and not said_compile):
            raise CheckFailed(f"{which}: expected the Python path, said (no compiled kernels yet); loop {loop}, "
                              f"said Python path: {said_python}, said compiling: {said_compile}")
        if which == COMPILE_FLY and not (loop == "compiled" and said_compile):
            raise CheckFailed(f"{which}: expected numba to compile, said; loop {loop}, said compiling: {said_compile}")
        if which == CACHED_FLY and not (loop == "compiled" and not said_compile and not said_python):
            raise CheckFailed(f"{which}: expected the cached kernels, silently; loop {loop}, said compiling: "
                              f"{said_compile} (the numba cache of the install was not used)")
        return f"{len(doc['cycles'])} cycle, tracking RMS {doc['cycles'][0]['track_rms_m']:.2f} m, loop {loop}"

    for which in (FIRST_FLY, SECOND_FLY, COMPILE_FLY, CACHED_FLY):
        step(which, lambda which=which: fly_reference(which))
    t = dict(times)
    if t[FIRST_FLY] - t[SECOND_FLY] > FIRST_USE_MAX_S:
        raise CheckFailed(f"fdm-awe fly (first): {t[FIRST_FLY] - t[SECOND_FLY]:.0f} s longer than the second "
                          f"(at most {FIRST_USE_MAX_S:.0f} s; fdm_awe/sim/first_use.py)")

    def fly_plain():
        plain = work / "default"
        plain.mkdir()
        run("fdm-awe fly (defaults)", [str(cli), "fly", "--cycles", "1", "--quiet", "--json", "fly.json"], plain, env)
        doc = json_status("fdm-awe fly (defaults)", plain / "fly.json")
        only_files("fdm-awe fly (defaults)", plain, {"fly.json"})
        return f"{doc['config']} at {doc['wind_mps']:g} m/s, tracking RMS {doc['cycles'][0]['track_rms_m']:.2f} m"

    step("fdm-awe fly --cycles 1 (defaults: optimise, then fly)", fly_plain)

    def fly_example():
        ex = work / "example"
        ex.mkdir()
        run("fdm-awe fly (example)", [str(cli), "fly", "--reference", "example:foldable-8", "--cycles", "1", "--quiet",
                                      "--json", "fly.json"], ex, env)
        doc = json_status("fdm-awe fly (example)", ex / "fly.json")
        only_files("fdm-awe fly (example)", ex, {"fly.json"})
        return f"{doc['config']} at {doc['wind_mps']:g} m/s, net {doc['cycles'][0]['E_net_J']:.0f} J"

    step("fdm-awe fly --cycles 1 --reference example:foldable-8 (package data)", fly_example)

    def export():
        run("fdm-awe info --export", [str(cli), "info", "--export", "definitions"], work / "example", env)
        got = sorted(p.relative_to(work / "example" / "definitions").as_posix()
                     for p in (work / "example" / "definitions").rglob("*") if p.is_file())
        if got != definition_files(src):
            raise CheckFailed(f"fdm-awe info --export: wrote {len(got)} files, the package has {len(definition_files(src))}")
        return f"{len(got)} files"

    step("fdm-awe info --export DIR", export)
    step("the Python API from the wheel",
         lambda: run("api", [str(vpy), "-c", API_CHECK], work, env).strip())
    if readme:
        (work / "readme").mkdir()
        step("README command lines (fdm-awe, rerun; short variants as tests/test_docs_commands.py runs them)",
             lambda: run_readme(work / "readme", vpy.parent, env))
    return times


#: The API from outside the checkout: an example reference through ``fdm_awe.load_reference``.
API_CHECK = ("import fdm_awe; r = fdm_awe.load_reference('example:nominal-8'); "
             "assert fdm_awe.ROOT.name == 'data', fdm_awe.ROOT; "
             "print('load_reference(example:nominal-8):', r.metadata['config'], r.metadata['wind_mps'], 'm/s')")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--keep", action="store_true", help="keep the temporary folder (its path is printed)")
    ap.add_argument("--python", default=sys.executable,
                    help="interpreter that creates the fresh environment (default: this one)")
    ap.add_argument("--no-readme", action="store_true",
                    help="skip the README's command lines (the longest step, several minutes)")
    args = ap.parse_args(argv)
    if not REFERENCE.is_file():
        ap.error(f"no stored reference {REFERENCE}")
    t0 = time.perf_counter()
    tmp = Path(tempfile.mkdtemp(prefix="fdm-awe-wheel-check-"))
    try:
        times = wheel_check(tmp, args.python, readme=not args.no_readme)
    except CheckFailed as exc:
        print(f"wheel check: FAILED: {exc}", file=sys.stderr)
        print(f"wheel check: FAILED after {time.perf_counter() - t0:.0f} s", flush=True)
        return 1
    except KeyboardInterrupt:
        print("wheel check: interrupted", file=sys.stderr)
        return 130
    finally:
        if args.keep:
            print(f"wheel check: kept {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    t = dict(times)
    print(f"wheel check: first fly {t[FIRST_FLY]:.1f} s, second fly {t[SECOND_FLY]:.1f} s (first use costs "
          f"{t[FIRST_FLY] - t[SECOND_FLY]:.1f} s); --compiled yes {t[COMPILE_FLY]:.1f} s, then cached "
          f"{t[CACHED_FLY]:.1f} s (compiling costs {t[COMPILE_FLY] - t[CACHED_FLY]:.1f} s)", flush=True)
    print(f"wheel check: ok, {len(times)} steps in {time.perf_counter() - t0:.0f} s "
          f"(install {t['install the wheel with its dependencies']:.0f} s)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
