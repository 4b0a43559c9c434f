"""``--aircraft NAME|DIR`` (issues 31 and 32): a user's copy of the glider, written by
``fdm-awe info --export DIR`` and changed in one quantity (10 % more mass), is what ``info``
shows, what ``optimize`` optimises (and its reference records) and what ``fly`` flies; a folder
that lacks a file is refused before any work in one line naming the option and the file."""

from __future__ import annotations

import contextlib
import io
import json
import math
import re
from pathlib import Path

import pytest

from conftest import WorkStarted
from fdm_awe.cli import main

DATA = Path(__file__).parent / "data"
REF = DATA / "ref_physical_nominal_8mps.json"
#: the three forms' files of the exported copy (the package's glider, prefix ``glider``)
FORMS = ("glider_foldable", "glider_unfolded", "glider_folded")
FACTOR = 1.1


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def _form(root: Path, name: str) -> Path:
    return root / "aircraft" / name / f"{name}.xml"


def _heavier(root: Path, factor: float = FACTOR) -> float:
    """Raise the glider's total mass in the copy ``root`` by ``factor``: the same added mass on
    the empty weight of each form (the morphing form's fold masses stay); returns the new mass [kg]."""
    from fdm_awe.definitions.aircraft import load_glider

    m = load_glider().unfolded.mass.mass
    add = (factor - 1.0) * m
    for name in FORMS:
        p = _form(root, name)
        text = p.read_text()
        new, n = re.subn(r'(<emptywt unit="KG">)\s*([0-9.]+)\s*(</emptywt>)',
                         lambda g: f"{g.group(1)} {float(g.group(2)) + add:.6g} {g.group(3)}", text)
        assert n == 1, p
        p.write_text(new)
    return factor * m


@pytest.fixture(scope="module")
def heavy(tmp_path_factory) -> Path:
    """An exported copy of the glider with 10 % more mass."""
    root = tmp_path_factory.mktemp("aircraft") / "heavy"
    code, out, err = _run(["info", "--export", str(root)])
    assert code == 0, err
    _heavier(root)
    return root


def test_info_shows_the_copy_s_mass_and_stall_speed(heavy, tmp_path):
    code, out0, err = _run(["info", "--json", str(tmp_path / "stock.json")])
    assert code == 0, err
    code, out1, err = _run(["info", "--aircraft", str(heavy), "--json", str(tmp_path / "heavy.json")])
    assert code == 0, err
    stock, mine = (json.loads((tmp_path / f).read_text()) for f in ("stock.json", "heavy.json"))
    assert stock["aircraft"]["name"] == "glider" and mine["aircraft"]["directory"] == str(heavy.resolve())
    assert mine["aircraft"]["sha256"] != stock["aircraft"]["sha256"]
    for form in ("unfolded", "folded"):
        m0, m1 = stock[form]["mass_kg"], mine[form]["mass_kg"]
        assert m1 == pytest.approx(FACTOR * m0, rel=1e-6)
        # stall speed sqrt(2 m g / (rho S CLmax)) and the best-glide speed grow with sqrt(m)
        assert mine[form]["stall_speed_mps"] == pytest.approx(math.sqrt(FACTOR) * stock[form]["stall_speed_mps"], rel=1e-6)
        assert mine[form]["glide"]["V_mps"] == pytest.approx(math.sqrt(FACTOR) * stock[form]["glide"]["V_mps"], rel=1e-6)
        assert mine[form]["glide"]["L_over_D"] == pytest.approx(stock[form]["glide"]["L_over_D"], rel=1e-9)
    assert f"mass {FACTOR * stock['unfolded']['mass_kg']:.4g} kg" in out1 and str(heavy.resolve()) in out1
    assert f"stall speed {mine['unfolded']['stall_speed_mps']:.3f} m/s" in out1


def test_fly_flies_the_heavier_copy(heavy, tmp_path):
    """The same stored reference flown by the package's glider and by the copy: the copy's
    report records it and its mass, a warning names the reference's (unrecorded) glider, and
    the heavier glider needs more thrust energy on the same path (about 7 % measured; > 3 %)."""
    docs = {}
    for tag, extra in (("stock", []), ("heavy", ["--aircraft", str(heavy)])):
        js = tmp_path / f"{tag}.json"
        code, out, err = _run(["fly", "--reference", str(REF), "--cycles", "1", "--quiet", "--json", str(js), *extra])
        assert code == 0, err
        docs[tag] = (json.loads(js.read_text()), err)
    (stock, err0), (mine, err1) = docs["stock"], docs["heavy"]
    assert "warning" not in err0 and "records no aircraft" in err1 and str(heavy.resolve()) in err1
    assert stock["aircraft"]["name"] == "glider" and mine["aircraft"]["directory"] == str(heavy.resolve())
    assert mine["aircraft"]["mass_kg"] == pytest.approx(FACTOR * stock["aircraft"]["mass_kg"], rel=1e-6)
    c0, c1 = stock["cycles"][0], mine["cycles"][0]
    assert c0["complete"] and c1["complete"]
    assert c1["E_thrust_J"] > 1.03 * c0["E_thrust_J"]


def test_optimize_takes_the_copy_and_its_reference_records_it(heavy, tmp_path, monkeypatch, capsys):
    """``optimize`` (the API's keyword) of the copy on a coarse mesh: the NLP's airframes are
    the copy's, the reference records the folder and its hash; ``fly`` of that reference with
    the package's glider warns (before any work) that it was optimised for another aircraft."""
    import fdm_awe
    import fdm_awe.sim.flight as flight
    from fdm_awe.ocp.build import get_nlp
    from fdm_awe.trajectory import write_reference

    res = fdm_awe.optimize(config="nominal", wind=8.0, mesh="20,12,3", aircraft=heavy)
    assert res.ok
    problem = res.result.problem
    assert problem.aircraft.root == heavy.resolve()
    model = get_nlp(problem)[0].model
    assert model.gen_airframe.mass.mass == pytest.approx(FACTOR * 0.738, rel=1e-6)
    assert str(model.gen_airframe.source).startswith(str(heavy.resolve()))
    path = write_reference(res.result, tmp_path / "heavy_ref.json")
    rec = json.loads(path.read_text())["metadata"]["aircraft"]
    assert rec["directory"] == str(heavy.resolve()) and len(rec["sha256"]) == 64

    def spy(*a, **kw):
        raise WorkStarted("fly was called")

    monkeypatch.setattr(flight, "fly", spy)
    capsys.readouterr()
    with pytest.raises(WorkStarted):  # checked, warned, then the flight would start
        main(["fly", "--reference", str(path), "--cycles", "1", "--quiet"])
    err = capsys.readouterr().err
    assert f"optimised for the aircraft {heavy.resolve()}" in err and "flying glider" in err


def test_optimize_cli_on_a_coarse_mesh(heavy, tmp_path):
    js = tmp_path / "opt.json"
    code, out, err = _run(["optimize", "--config", "nominal", "--wind", "8", "--mesh", "20,12,3",
                           "--aircraft", str(heavy), "--json", str(js)])
    assert code == 0, err
    assert f"aircraft {heavy.resolve()}" in out
    md = json.loads((tmp_path / "opt.trajectory.json").read_text())["metadata"]
    assert md["aircraft"]["directory"] == str(heavy.resolve())


def test_sweep_points_carry_the_copy(heavy):
    """A sweep of the copy: new point ids (the folder and its hash are part of them), the
    points' problems optimise the copy; the package's glider keeps its ids and spec document."""
    from fdm_awe.cli import build_parser
    from fdm_awe.commands import sweep as S
    from fdm_awe.sweep.runner import point_problem

    def spec(*extra):
        args = build_parser().parse_args(["sweep", "--out", "x", "--wind", "8", "--config", "nominal", *extra])
        S.check_args(args)
        return S.build_spec(args)

    stock, mine = spec(), spec("--aircraft", str(heavy))
    p0, p1 = stock.points()[0], mine.points()[0]
    assert p0.aircraft is None and "aircraft" not in stock.to_dict()
    assert p1.aircraft == str(heavy.resolve()) and len(p1.aircraft_sha256) == 64 and p1.id != p0.id
    assert point_problem(p1).aircraft.root == heavy.resolve() and point_problem(p0).aircraft.builtin


def _broken(tmp_path: Path, heavy: Path, name: str) -> Path:
    import shutil

    root = tmp_path / name
    shutil.copytree(heavy, root)
    return root


@pytest.mark.parametrize("command", [["info"], ["optimize", "--mesh", "20,12,3"], ["sweep", "--out", "SWEEP"],
                                     ["fly", "--reference", str(REF)]])
def test_a_folder_missing_a_file_is_refused_before_any_work(command, heavy, tmp_path, no_work, capsys):
    cases = [
        (lambda r: _form(r, "glider_unfolded").unlink(), "glider_unfolded.xml missing", "unfolded form"),
        (lambda r: (r / "engine" / "prop_9x5.xml").unlink(), "prop_9x5.xml missing", "propeller"),
        (lambda r: (r / "aircraft" / "glider_foldable" / "autopilot.xml").unlink(), "autopilot.xml missing", "autopilot"),
        (lambda r: (r / "aircraft" / "glider_foldable").rename(r / "aircraft" / "other"), "P_foldable missing",
         "morphing aircraft"),
    ]
    argv = [a.replace("SWEEP", str(tmp_path / "sweep")) for a in command]
    for i, (damage, *words) in enumerate(cases):
        root = _broken(tmp_path, heavy, f"broken{i}")
        damage(root)
        code = main([*argv, "--aircraft", str(root)])
        err = capsys.readouterr().err.strip()
        assert code == 2 and "\n" not in err and "--aircraft" in err, err
        for w in words:
            assert w in err, (w, err)
    code = main([*argv, "--aircraft", str(tmp_path / "nowhere")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "--aircraft" in err and "nor a folder" in err


def test_forms_of_different_mass_are_refused(heavy, tmp_path, capsys):
    root = _broken(tmp_path, heavy, "unequal")
    p = _form(root, "glider_folded")
    p.write_text(re.sub(r'(<emptywt unit="KG">)\s*[0-9.]+', r"\1 0.5", p.read_text()))
    assert main(["info", "--aircraft", str(root)]) == 2
    err = capsys.readouterr().err.strip()
    assert "glider_folded.xml" in err and "mass_balance" in err and "morphing form" in err


def test_export_refuses_a_non_empty_folder_unless_forced(tmp_path):
    dest = tmp_path / "defs"
    dest.mkdir()
    (dest / "notes.txt").write_text("mine")
    code, out, err = _run(["info", "--export", str(dest)])
    assert code == 2 and "not empty" in err and "--force" in err and not (dest / "engine").exists()
    code, out, err = _run(["info", "--export", str(dest), "--force"])
    assert code == 0, err
    assert (dest / "notes.txt").read_text() == "mine" and (dest / "tether" / "ground_station.xml").is_file()
    _heavier(dest)
    code, out, err = _run(["info", "--export", str(dest), "--force"])  # the copy's files replaced
    assert code == 0 and "0.738 kg" in _run(["info", "--aircraft", str(dest)])[1]
    assert _run(["info", "--force"])[0] == 2


def test_a_folder_changed_between_two_solves_is_a_new_nlp(heavy, tmp_path):
    """The optimiser's caches key on the aircraft's files (their hash), not only on its folder."""
    import shutil

    from fdm_awe.ocp.build import structure_key
    from fdm_awe.ocp.problem import CycleProblem

    root = tmp_path / "edited"
    shutil.copytree(heavy, root)
    before = CycleProblem(config="nominal", aircraft=str(root))
    _heavier(root, 1.05)
    after = CycleProblem(config="nominal", aircraft=str(root))
    assert before.aircraft == after.aircraft and before.aircraft.sha256 != after.aircraft.sha256
    assert structure_key(before) != structure_key(after)
    assert structure_key(CycleProblem(config="nominal")) == structure_key(CycleProblem(config="nominal", aircraft="glider"))
