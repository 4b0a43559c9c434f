"""Packaging: the definition folders ship in the sdist and the wheel, and an installed package
finds them (docs/design.md section 2).

The full check (install with dependencies into a fresh environment, commands run from outside
the checkout) is scripts/check_wheel.py, run by scripts/run_tests.sh; here the sdist and the
wheel are built from a copy of the checkout, the wheel is unpacked as pip would install it and
the package is imported from there, with this environment's dependencies.
"""

from __future__ import annotations

import ast
import importlib.util
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import fdm_awe

REPO = Path(__file__).resolve().parent.parent


def _check_wheel():
    spec = importlib.util.spec_from_file_location("check_wheel", REPO / "scripts" / "check_wheel.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


cw = _check_wheel()


def test_checkout_root_is_the_repository_with_its_definition_folders():
    assert fdm_awe.ROOT == REPO
    for folder in fdm_awe.DEFINITION_FOLDERS:
        assert (fdm_awe.ROOT / folder).is_dir(), folder
    assert not (REPO / "fdm_awe" / "data").exists(), "a copy of the definitions inside the source package would shadow them"


def test_setup_py_ships_the_package_definition_folders():
    tree = ast.parse((REPO / "setup.py").read_text())
    values = [ast.literal_eval(node.value) for node in ast.walk(tree)
              if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "DEFINITION_FOLDERS" for t in node.targets)]
    assert values == [fdm_awe.DEFINITION_FOLDERS]
    assert cw.DEFINITION_FOLDERS == fdm_awe.DEFINITION_FOLDERS


def _setup_module():
    """setup.py imported under another name than ``__main__`` (its ``setup()`` call is skipped)."""
    spec = importlib.util.spec_from_file_location("fdm_awe_setup", REPO / "setup.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_index_readme_has_absolute_links_to_files_of_the_repository():
    """The long description (README.md) with relative links made absolute: each link to the
    repository's main branch names a file or folder that exists in the checkout, images point
    at their raw files, absolute URLs and anchors stay as they were."""
    st = _setup_module()
    text = (REPO / "README.md").read_text(encoding="utf-8")
    assert cw.relative_links(text), "the README is expected to link the repository's files relatively"
    out = st.index_readme(text)
    assert cw.relative_links(out) == []
    targets = [t for t in cw.LINK.findall(out)]
    assert targets
    for bang, _, url in targets:
        for base in (st.BLOB_URL, st.RAW_URL):
            if url.startswith(base):
                assert (REPO / url[len(base):].split("#")[0]).exists(), url
                assert (base == st.RAW_URL) == bool(bang), url
    sample = "[a](docs/design.md) ![b](docs/cycle.png) [c](https://e.org/z) [d](#usage)"
    assert st.index_readme(sample) == (f"[a]({st.BLOB_URL}docs/design.md) ![b]({st.RAW_URL}docs/cycle.png) "
                                       "[c](https://e.org/z) [d](#usage)")


def test_pyproject_has_no_deprecated_setuptools_configuration():
    tomllib = pytest.importorskip("tomllib")
    doc = tomllib.loads((REPO / "pyproject.toml").read_text())
    assert isinstance(doc["project"]["license"], str)  # an SPDX expression, not the deprecated table
    assert any(r.replace(" ", "").startswith("setuptools>=") and int(r.split(">=")[1].split(".")[0]) >= 77
               for r in doc["build-system"]["requires"])  # SPDX license strings need setuptools 77
    # packages are found by setup.py (together with the mapped definition folders)
    assert "packages" not in doc.get("tool", {}).get("setuptools", {})


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """sdist and wheel built from a copy of the checkout: (source copy, sdist, wheel)."""
    tmp = tmp_path_factory.mktemp("packaging")
    src, dist, tools = tmp / "src", tmp / "dist", tmp / "tools"
    src.mkdir()
    dist.mkdir()
    cw.copy_source(src)
    sdist = cw.build_sdist(src, dist, sys.executable, tools)
    wheel = cw.build_wheel(sdist, dist, sys.executable, src)
    return src, sdist, wheel, tools


@pytest.mark.timeout(240)
def test_sdist_and_wheel_hold_every_definition_file(built):
    src, sdist, wheel, _ = built
    files = cw.definition_files(src)
    # the autopilot's gains and the JSBSim reset files are among them
    for f in ("aircraft/glider_foldable/autopilot.xml", "aircraft/glider_foldable/reset00.xml",
              "aircraft/glider_unfolded/glider_unfolded.xml", "engine/prop_9x5.xml", "tether/ground_station.xml"):
        assert f in files
    cw.check_sdist_members(sdist, src)
    cw.check_wheel_members(wheel, src)


@pytest.mark.timeout(240)
def test_unpacked_wheel_finds_its_definitions_and_jsbsim_flies_them(built, tmp_path):
    _, _, wheel, _ = built
    site = tmp_path / "site"
    with zipfile.ZipFile(wheel) as zf:
        zf.extractall(site)
    env = dict(os.environ, PYTHONPATH=str(site), JSBSIM_DEBUG="0", MPLBACKEND="Agg")
    work = tmp_path / "work"
    work.mkdir()
    proc = subprocess.run([sys.executable, "-c", cw.IMPORT_CHECK, str(site)], cwd=work, env=env,
                          capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert Path(proc.stdout.strip()) == site / "fdm_awe" / "data"
    assert list(work.iterdir()) == []


@pytest.mark.timeout(240)
def test_unpacked_wheel_carries_the_example_references_and_its_project_urls(built, tmp_path):
    _, _, wheel, _ = built
    site = tmp_path / "site"
    with zipfile.ZipFile(wheel) as zf:
        zf.extractall(site)
        meta = next(n for n in zf.namelist() if n.endswith(".dist-info/METADATA"))
        urls = [ln for ln in zf.read(meta).decode().splitlines() if ln.startswith("Project-URL:")]
    assert {u.split(",")[0] for u in urls} >= {"Project-URL: Homepage", "Project-URL: Documentation",
                                               "Project-URL: Source"}
    assert all("https://github.com/fdm-awe/fdm-awe" in u for u in urls)
    with zipfile.ZipFile(wheel) as zf:  # the index page's README: no link left relative
        assert cw.relative_links(zf.read(meta).decode()) == []
    env = dict(os.environ, PYTHONPATH=str(site), JSBSIM_DEBUG="0")
    code = ("import fdm_awe, fdm_awe.example_refs as e; r = fdm_awe.load_reference('example:foldable-8'); "
            "print(e.examples_folder()); print(r.metadata['config'], r.metadata['wind_mps'])")
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    folder, what = proc.stdout.strip().splitlines()
    assert Path(folder) == site / "fdm_awe" / "data" / "examples"
    assert what == "foldable 8.0"
    assert sorted(p.name for p in Path(folder).iterdir() if p.suffix == ".json") == sorted(cw.EXAMPLES.values())


@pytest.mark.timeout(240)
def test_a_deprecated_setuptools_configuration_fails_the_sdist_build(built, tmp_path):
    _, _, _, tools = built
    src = tmp_path / "src"
    src.mkdir()
    cw.copy_source(src)
    pyproject = src / "pyproject.toml"
    pyproject.write_text(pyproject.read_text().replace('license = "MIT"', 'license = { text = "MIT" }'))
    with pytest.raises(cw.CheckFailed, match="the build warns: .*license"):
        cw.build_sdist(src, tmp_path, sys.executable, tools)


#: a wheel's METADATA with the project URLs
_METADATA = "Metadata-Version: 2.4\nName: fdm-awe\nProject-URL: Homepage, https://github.com/fdm-awe/fdm-awe\n"


def _zip(path: Path, names: list[str]) -> Path:
    with zipfile.ZipFile(path, "w") as zf:
        for n in names:
            zf.writestr(n, _METADATA if n.endswith("/METADATA") else "<x/>")
    return path


def test_wheel_member_check_fails_on_a_missing_definition_or_a_stray_file(tmp_path):
    src = tmp_path / "src"
    for rel in ("aircraft/a/a.xml", "engine/e.xml", "tether/t.xml"):
        (src / rel).parent.mkdir(parents=True, exist_ok=True)
        (src / rel).write_text("<x/>")
    examples = [f"fdm_awe/data/examples/{n}" for n in cw.EXAMPLES.values()]
    full = ["fdm_awe/__init__.py", "fdm_awe/data/aircraft/a/a.xml", "fdm_awe/data/engine/e.xml",
            "fdm_awe/data/tether/t.xml", *examples, "fdm_awe-0.1.0.dist-info/RECORD",
            "fdm_awe-0.1.0.dist-info/METADATA"]
    cw.check_wheel_members(_zip(tmp_path / "ok.whl", full), src)
    with pytest.raises(cw.CheckFailed, match="lacks 1 example reference.*nominal_8mps_sized"):
        cw.check_wheel_members(_zip(tmp_path / "noex.whl", [n for n in full if "nominal_8mps_sized" not in n]), src)
    with pytest.raises(cw.CheckFailed, match="no project URLs"):
        cw.check_wheel_members(_zip(tmp_path / "nourl.whl", [n for n in full if not n.endswith("METADATA")]), src)
    with pytest.raises(cw.CheckFailed, match="lacks 1 definition file.*engine/e.xml"):
        cw.check_wheel_members(_zip(tmp_path / "missing.whl", [n for n in full if "engine" not in n]), src)
    with pytest.raises(cw.CheckFailed, match="outside fdm_awe/: aircraft/a/a.xml"):
        cw.check_wheel_members(_zip(tmp_path / "stray.whl", full + ["aircraft/a/a.xml"]), src)


def test_a_failing_step_fails_the_check_loudly(tmp_path):
    with pytest.raises(cw.CheckFailed, match=r"exit 3: .*\n.*boom"):
        cw.run("step", [sys.executable, "-c", "import sys; print('boom'); sys.exit(3)"], tmp_path)
    (tmp_path / "out.json").write_text('{"status": "failed", "message": "no cycle"}')
    with pytest.raises(cw.CheckFailed, match="status 'failed'.*no cycle"):
        cw.json_status("step", tmp_path / "out.json")
    with pytest.raises(cw.CheckFailed, match="not told to write: out.json"):
        cw.only_files("step", tmp_path, set())


def test_readme_lines_from_the_wheel_name_example_references_not_test_files(tmp_path):
    """The wheel check runs the README's fdm-awe and rerun lines (short variants): a line naming a
    file of tests/data fails it with the example to write instead; a stored reference a variant
    flies instead of optimising is named as its example; scripts stay the checkout's."""
    readme = tmp_path / "README.md"
    readme.write_text("# x\n\n```bash\n.venv/bin/fdm-awe info\n"
                      ".venv/bin/fdm-awe fly --reference example:foldable-8 --cycles 3 --out runs/f\n"
                      ".venv/bin/python scripts/wind_grid.py\n.venv/bin/rerun runs/f/flight.rrd\n```\n\n"
                      "Or `fdm-awe fly --scenario physical --config nominal --wind 8 --cycles 3`.\n")
    got = cw.readme_commands(readme)
    assert [w for w, _, _ in got] == ["README.md:4", "README.md:5", "README.md:10", "README.md:7"]
    assert got[1][1] == ["fdm-awe", "fly", "--reference", "example:foldable-8", "--out", "runs/f", "--cycles", "1"]
    assert got[2][1][-4:] == ["--reference", "example:nominal-8", "--cycles", "1"]
    assert got[3] == ("README.md:7", ["rerun", "rrd", "verify", "runs/f/flight.rrd"], True)
    readme.write_text("```bash\n.venv/bin/fdm-awe fly --reference tests/data/ref_paper_foldable_3mps.json\n```\n")
    with pytest.raises(cw.CheckFailed, match=r"README.md:2: tests/data/ref_paper_foldable_3mps.json .* write "
                                             r"example:paper-foldable-3"):
        cw.readme_commands(readme)
