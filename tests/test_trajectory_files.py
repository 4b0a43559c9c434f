"""Reference-trajectory files: every malformed file is refused with one line naming the file,
the field and the allowed range or form, before any flight starts; the stored references load.

The malformed files are built in ``tmp_path`` from a stored reference of ``tests/data/``.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.errors import InputError
from fdm_awe.ocp.result import CycleResult
from fdm_awe.trajectory import COLUMN_UNITS, read_reference, write_reference

DATA = Path(__file__).parent / "data"
SOURCE = DATA / "ref_physical_foldable_8mps_halfline.json"
STORED = sorted(DATA.glob("ref_*.json"))


def _doc() -> dict:
    return json.loads(SOURCE.read_text())


def _refused(path: Path, *words: str) -> str:
    """Both readers refuse ``path`` with one InputError line naming the file and ``words``."""
    for read in (read_reference, TrackingReference.from_ocp_file):
        with pytest.raises(InputError) as ei:
            read(path)
        msg = str(ei.value)
        assert "\n" not in msg, msg
        assert str(path) in msg, msg
        for w in words:
            assert w in msg, (w, msg)
    return msg


# ------------------------------------------------------------------ the stored references load


@pytest.mark.parametrize("path", STORED, ids=lambda p: p.name)
def test_stored_references_load_with_checked_metadata(path):
    raw = json.loads(path.read_text())["metadata"]
    ref = TrackingReference.from_ocp_file(path)
    assert ref.meta["config"] == raw["config"] in ("foldable", "nominal")
    assert ref.meta["scenario"] == raw["scenario"] in ("physical", "paper")
    assert ref.meta["wind_ned_mps"] == pytest.approx(raw["wind_ned_mps"], abs=1e-12)
    assert ref.period == pytest.approx(raw["T1_s"] + raw["T2_s"], rel=1e-12)
    assert ref.meta["tether_drag_scale"] == raw.get("tether_drag_scale", 1.0)
    assert np.all(np.diff(ref.t) > 0) and np.all(np.isfinite(ref.pos))


# ------------------------------------------------------------------ files that are not reference JSON


def test_missing_file_and_folder(tmp_path):
    _refused(tmp_path / "nope.json", "not found")
    d = tmp_path / "adir.json"
    d.mkdir()
    _refused(d, "folder")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
def test_not_a_regular_file(tmp_path):
    p = tmp_path / "fifo.json"
    os.mkfifo(p)
    _refused(p, "not a regular file")  # and does not block reading it


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root reads files whatever their mode")
def test_unreadable_file(tmp_path):
    p = tmp_path / "locked.json"
    p.write_text(SOURCE.read_text())
    p.chmod(0)
    try:
        _refused(p, "cannot read")
    finally:
        p.chmod(0o644)


@pytest.mark.skipif(not Path("/proc/self/mem").is_file(), reason="needs Linux /proc")
def test_file_that_cannot_be_read(tmp_path):
    """/proc/self/mem is a regular file whose plain read fails (EIO), whoever reads it."""
    _refused(Path("/proc/self/mem"), "cannot read")


RAW = {
    "empty": (b"", "empty file"),
    "blank": (b"  \n\t ", "empty file"),
    "binary": (bytes(range(256)) * 4, "binary content"),
    "gzip": (b"\x1f\x8b\x08\x00" + b"\x00" * 20, "binary content"),
    "latin1": ('{"format": "fdm-awe-reference-trajectory", "note": "d\u00e9j\u00e0 vu"}'.encode("latin-1"), "not UTF-8"),
    "truncated": (SOURCE.read_bytes()[:5000], "invalid JSON at line"),
    "garbage": (b"columns: t, x, y\n1, 2, 3\n", "invalid JSON"),
    "deep_list": (b"[" * 200_000 + b"]" * 200_000, "nested too deeply"),
    "deep_object": (b'{"a":' * 200_000 + b"1" + b"}" * 200_000, "nested too deeply"),
    "huge_int": (b'{"format": ' + b"9" * 10_000 + b"}", "invalid JSON"),
    "list": (b"[1, 2, 3]", "top level is a list"),
    "null": (b"null", "top level is null"),
    "string": (b'"fdm-awe-reference-trajectory"', "top level is a string"),
    "number": (b"42", "top level is a number"),
}


@pytest.mark.parametrize("case", list(RAW))
def test_malformed_bytes(tmp_path, case):
    data, words = RAW[case]
    p = tmp_path / f"{case}.json"
    p.write_bytes(data)
    _refused(p, words)


# ------------------------------------------------------------------ documents with bad fields


def _set(path: list, value):
    """A mutation setting ``doc[path...] = value`` (or deleting it for ``...``)."""

    def f(doc):
        d = doc
        for k in path[:-1]:
            d = d[k]
        if value is ...:
            del d[path[-1]]
        else:
            d[path[-1]] = value

    return f


def _col(name: str, fn):
    def f(doc):
        doc["columns"][name] = fn(doc["columns"][name])

    return f


def _rows(n: int):
    def f(doc):
        for k in doc["columns"]:
            doc["columns"][k] = doc["columns"][k][:n]

    return f


def _put(name: str, i: int, v):
    def f(doc):
        doc["columns"][name][i] = v

    return f


def _json_nan(doc):  # NaN written as the bare literal (Python's json writes and reads it)
    doc["columns"]["x"][7] = float("nan")


DOCS = {
    # top-level fields
    "no_format": (_set(["format"], ...), "format"),
    "other_format": (_set(["format"], "fdm-awe-flight"), "format"),
    "version_2": (_set(["version"], 2), "version"),
    "version_string": (_set(["version"], "1"), "version"),
    "version_true": (_set(["version"], True), "version"),
    "no_columns": (_set(["columns"], ...), "columns: missing"),
    "no_metadata": (_set(["metadata"], ...), "metadata: missing"),
    "columns_list": (_set(["columns"], [[0.0, 1.0]]), "columns: a list"),
    "columns_null": (_set(["columns"], None), "columns: null"),
    "metadata_string": (_set(["metadata"], "foldable"), "metadata: a string"),
    "metadata_list": (_set(["metadata"], []), "metadata: a list"),
    "units_list": (_set(["units"], ["s", "m"]), "units"),
    # columns
    "missing_column": (_set(["columns", "tension"], ...), "tension"),
    "column_string": (_col("x", lambda c: "150.0"), "columns.x: a string"),
    "column_number": (_col("y", lambda c: 3.0), "columns.y: a number"),
    "column_object": (_col("z", lambda c: {"0": c[0]}), "columns.z: an object"),
    "column_nested": (_col("V", lambda c: [[v] for v in c]), "columns.V[0]: a list"),
    "column_short": (_col("psi", lambda c: c[:-1]), "columns.psi"),
    "column_long": (_col("alpha", lambda c: c + [c[-1]]), "columns.alpha"),
    "column_empty": (_col("phi", lambda c: []), "columns.phi"),
    "element_string": (_put("tension", 3, "12"), "columns.tension[3]: a string"),
    "element_bool": (_put("fold", 3, True), "columns.fold[3]: a boolean"),
    "element_null": (_put("T", 5, None), "columns.T[5]: null"),
    "nan_position": (_json_nan, "columns.x[7]"),
    "inf_position": (_put("z", 9, float("-inf")), "columns.z[9]"),
    "overflow_position": (_put("y", 2, 1e999), "columns.y[2]"),
    "nan_t": (_put("t", 11, float("nan")), "columns.t[11]"),
    "inf_t": (_put("t", 321, float("inf")), "columns.t[321]"),
    "nan_thrust": (_put("T", 50, float("nan")), "columns.T[50]"),
    "nan_alpha": (_put("alpha", 60, float("nan")), "columns.alpha[60]"),
    "nan_tension": (_put("tension", 70, float("nan")), "columns.tension[70]"),
    "nan_power": (_put("p_thrust_W", 80, float("nan")), "columns.p_thrust_W[80]"),
    "nan_phase": (_put("phase", 90, float("nan")), "columns.phase[90]"),
    "t_reversed": (_col("t", lambda c: c[::-1]), "columns.t[1]"),
    "t_constant": (_col("t", lambda c: [5.0] * len(c)), "columns.t[1]"),
    "t_repeat_in_phase": (_put("t", 10, 0.0), "columns.t[10]"),
    "t_offset": (_col("t", lambda c: [v + 1.0 for v in c]), "columns.t[0]"),
    "one_row": (_rows(1), "columns.t: 1 row"),
    "no_rows": (_rows(0), "columns.t: 0 row"),
    "phase_other": (_put("phase", 5, 2.0), "columns.phase[5]"),
    "phase_back": (_put("phase", 300, 0.0), "columns.phase[300]"),
    "only_generation": (_col("phase", lambda c: [0.0] * len(c)), "columns.t[241]"),
    "airspeed_zero": (_put("V", 4, 0.0), "columns.V[4]"),
    "underground": (_put("z", 4, 3.0), "columns.z[4]"),
    "fold_two": (_put("fold", 4, 2.0), "columns.fold[4]"),
    "line_length_zero": (_put("tether_length", 4, 0.0), "columns.tether_length[4]"),
    "negative_thrust": (_put("T", 4, -1.0), "columns.T[4]"),
    # metadata
    "config_bogus": (_set(["metadata", "config"], "bogus"), "metadata.config"),
    "config_missing": (_set(["metadata", "config"], ...), "metadata.config: missing"),
    "config_number": (_set(["metadata", "config"], 1), "metadata.config"),
    "scenario_bogus": (_set(["metadata", "scenario"], "lab"), "metadata.scenario"),
    "scenario_missing": (_set(["metadata", "scenario"], ...), "metadata.scenario: missing"),
    "wind_huge": (_set(["metadata", "wind_mps"], 1e308), "metadata.wind_mps"),
    "wind_negative": (_set(["metadata", "wind_mps"], -1.0), "metadata.wind_mps"),
    "wind_nan": (_set(["metadata", "wind_mps"], float("nan")), "metadata.wind_mps"),
    "wind_string": (_set(["metadata", "wind_mps"], "8"), "metadata.wind_mps"),
    "wind_disagrees": (_set(["metadata", "wind_mps"], 3.0), "metadata.wind_mps"),
    "wind_vector_huge": (_set(["metadata", "wind_ned_mps"], [1e308, 0.0, 0.0]), "metadata.wind_ned_mps"),
    "wind_vector_short": (_set(["metadata", "wind_ned_mps"], [8.0, 0.0]), "metadata.wind_ned_mps"),
    "wind_vector_vertical": (_set(["metadata", "wind_ned_mps"], [8.0, 0.0, 1.0]), "metadata.wind_ned_mps"),
    "wind_direction_disagrees": (_set(["metadata", "wind_from_deg"], 90.0), "metadata.wind_from_deg"),
    "wind_all_missing": (lambda d: [d["metadata"].pop(k) for k in ("wind_mps", "wind_ned_mps")], "metadata.wind_mps"),
    "T1_negative": (_set(["metadata", "T1_s"], -5.0), "metadata.T1_s"),
    "T1_zero": (_set(["metadata", "T1_s"], 0.0), "metadata.T1_s"),
    "T1_missing": (_set(["metadata", "T1_s"], ...), "metadata.T1_s"),
    "T1_nan": (_set(["metadata", "T1_s"], float("nan")), "metadata.T1_s"),
    "T2_negative": (_set(["metadata", "T2_s"], -1.0), "metadata.T2_s"),
    "T2_inf": (_set(["metadata", "T2_s"], float("inf")), "metadata.T2_s"),
    "T1_off_the_time_column": (_set(["metadata", "T1_s"], 40.0), "T1_s"),
    "T2_off_the_time_column": (_set(["metadata", "T2_s"], 5.0), "T1_s + T2_s"),
    "period_disagrees": (_set(["metadata", "period_s"], 4.9), "metadata.period_s"),
    "drag_scale_high": (_set(["metadata", "tether_drag_scale"], 11.0), "metadata.tether_drag_scale"),
    "drag_scale_negative": (_set(["metadata", "tether_drag_scale"], -0.5), "metadata.tether_drag_scale"),
    "status_failed": (_set(["metadata", "status"], "failed"), "metadata.status"),
    "recovery_airframe": (_set(["metadata", "recovery_airframe"], "unfolded"), "metadata.recovery_airframe"),
    "propeller_bogus": (_set(["metadata", "propeller"], "jet"), "metadata.propeller"),
    "line_weight_string": (_set(["metadata", "line_weight"], "yes"), "metadata.line_weight"),
    "d_tf_below_d0": (_set(["metadata", "d_tf_m"], 100.0), "metadata.d_tf_m"),
    "nominal_folds": (_set(["metadata", "config"], "nominal"), "metadata.recovery_airframe"),
    "energies_list": (_set(["metadata", "energies"], [1.0]), "metadata.energies"),
    "energy_text": (_set(["metadata", "energies", "E_net_J"], "a lot"), "metadata.energies.E_net_J"),
    "energies_override_status": (_set(["metadata", "energies", "status"], "ok"), "metadata.energies.status"),
}


@pytest.mark.parametrize("case", list(DOCS))
def test_malformed_document(tmp_path, case):
    mutate, field = DOCS[case]
    doc = _doc()
    mutate(doc)
    p = tmp_path / f"{case}.json"
    p.write_text(json.dumps(doc))
    _refused(p, field)


@pytest.mark.parametrize("mutate,words", [
    (_set(["metadata", "wind_mps"], 1e308), "allowed 0 .. 25 m/s"),
    (_set(["metadata", "T1_s"], -5.0), "allowed > 0"),
    (_set(["metadata", "config"], "bogus"), "allowed nominal, foldable"),
    (_set(["metadata", "scenario"], "lab"), "allowed physical, paper"),
    (_set(["metadata", "tether_drag_scale"], 11.0), "allowed 0 .. 10"),
    (_put("t", 11, float("nan")), "not a finite number"),
    (_col("t", lambda c: c[::-1]), "strictly increasing"),
    (_put("fold", 4, 2.0), "allowed 0 .. 1"),
])
def test_messages_name_the_allowed_range(tmp_path, mutate, words):
    doc = _doc()
    mutate(doc)
    p = tmp_path / "ref.json"
    p.write_text(json.dumps(doc))
    _refused(p, words)


def test_nan_time_is_a_time_problem_not_a_throttle_one(tmp_path):
    doc = _doc()
    doc["columns"]["t"][100] = float("nan")
    p = tmp_path / "ref.json"
    p.write_text(json.dumps(doc))
    msg = _refused(p, "columns.t[100]")
    assert "throttle" not in msg and "Surfaces" not in msg


def test_nominal_reference_that_folds_is_refused(tmp_path):
    doc = json.loads((DATA / "ref_physical_nominal_8mps.json").read_text())
    doc["columns"]["fold"][300] = 1.0
    p = tmp_path / "ref.json"
    p.write_text(json.dumps(doc))
    _refused(p, "columns.fold[300]", "nominal")


def test_derived_metadata_is_filled_in_consistently(tmp_path):
    """A file with only the wind vector (or only speed and direction) gets the other form;
    an older file without tether_drag_scale flies the defined line (1)."""
    doc = _doc()
    for k in ("wind_mps", "wind_from_deg", "period_s", "tether_drag_scale"):
        doc["metadata"].pop(k)
    doc["metadata"]["wind_ned_mps"] = [0.0, -6.0, 0.0]  # blowing west: from the east (90 deg)
    p = tmp_path / "a.json"
    p.write_text(json.dumps(doc))
    md = read_reference(p).metadata
    assert md["wind_mps"] == pytest.approx(6.0) and md["wind_from_deg"] == pytest.approx(90.0)
    assert md["period_s"] == pytest.approx(md["T1_s"] + md["T2_s"], rel=1e-15)
    assert md["tether_drag_scale"] == 1.0
    doc = _doc()
    doc["metadata"].pop("wind_ned_mps")
    doc["metadata"].update(wind_mps=5.0, wind_from_deg=270.0)
    p.write_text(json.dumps(doc))
    assert TrackingReference.from_ocp_file(p).meta["wind_ned_mps"] == pytest.approx([0.0, 5.0, 0.0], abs=1e-12)


def test_in_memory_reference_gets_the_same_checks():
    ref = read_reference(SOURCE)
    ref.metadata["config"] = "bogus"
    with pytest.raises(InputError, match="metadata.config"):
        TrackingReference.from_ocp(ref)


# ------------------------------------------------------------------ writing


def _result_from(path: Path) -> CycleResult:
    ref = read_reference(path)
    md = ref.metadata
    return CycleResult(md["scenario"], md["config"], md["wind_mps"], md["wind_from_deg"], "ok", "Solve_Succeeded",
                       0.0, 0.0, 0, T1_s=md["T1_s"], T2_s=md["T2_s"], k_wrap=md["k_wrap"],
                       E_generated_J=1.0, E_thrust_J=2.0,
                       E_reel_in_J=0.5, columns={k: ref[k].copy() for k in COLUMN_UNITS})


def test_written_reference_reads_back_and_replaces_atomically(tmp_path):
    res = _result_from(SOURCE)
    p = tmp_path / "ref.json"
    p.write_text("an older file")
    assert write_reference(res, p) == p
    back = read_reference(p)
    for k in COLUMN_UNITS:
        np.testing.assert_array_equal(back[k], res.columns[k])
    assert back.metadata["config"] == "foldable" and back.metadata["T1_s"] == res.T1_s
    assert sorted(x.name for x in tmp_path.iterdir()) == ["ref.json"]  # no temporary file left


def test_a_reference_that_would_not_read_back_is_not_written(tmp_path):
    res = _result_from(SOURCE)
    res.columns["x"][3] = math.nan
    p = tmp_path / "ref.json"
    p.write_text("the previous reference")
    with pytest.raises(InputError, match=r"columns\.x\[3\]"):
        write_reference(res, p)
    assert p.read_text() == "the previous reference"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["ref.json"]


# ------------------------------------------------------------------ units, periodicity, continuity


def _write(tmp_path: Path, doc: dict, name: str = "ref.json") -> Path:
    p = tmp_path / name
    p.write_text(json.dumps(doc))
    return p


@pytest.mark.parametrize("mutate,words", [
    (_set(["units"], ...), ["units: missing"]),
    (_set(["units", "t"], "ms"), ["units.t", "'ms'", "expected 's'"]),
    (_set(["units", "V"], "km/h"), ["units.V", "expected 'm/s'"]),
    (_set(["units", "tension"], ...), ["units.tension: missing", "expected 'N'"]),
    (_set(["units", "psi"], "deg"), ["units.psi", "expected 'rad'"]),
], ids=["no_units", "t_in_ms", "V_in_kmh", "tension_unit_missing", "psi_in_deg"])
def test_units_block_is_required_with_the_units_the_package_writes(tmp_path, mutate, words):
    doc = _doc()
    mutate(doc)
    _refused(_write(tmp_path, doc), *words)


def _shifted_end(name: str, by: float):
    def f(doc):
        doc["columns"][name][-1] += by

    return f


def _ramp(name: str, total: float):
    """``total`` added to column ``name`` in proportion to the cycle time (nothing at the start)."""
    def f(doc):
        t = doc["columns"]["t"]
        doc["columns"][name] = [v + total * ti / t[-1] for v, ti in zip(doc["columns"][name], t)]

    return f


@pytest.mark.parametrize("mutate,words", [
    (_shifted_end("x", 100.0), ["columns.x[321]", "periodic", "allowed difference <= 0.0002 m"]),
    (_ramp("z", -80.0), ["columns.z[321]", "periodic", "-80 m"]),
    (_shifted_end("V", 0.01), ["columns.V[321]", "allowed difference <= 1e-05 m/s"]),
    (_shifted_end("psi", 0.5), ["columns.psi[321]", "k_wrap", "allowed difference <= 1e-06 rad"]),
    (_shifted_end("tether_length", 1.0), ["columns.tether_length[321]", "periodic"]),
], ids=["last_x_100m", "z_ramp_80m", "V_end", "psi_end", "line_length_end"])
def test_a_reference_that_is_not_one_periodic_cycle_is_refused(tmp_path, mutate, words):
    doc = _doc()
    mutate(doc)
    _refused(_write(tmp_path, doc), *words)


def test_periodicity_tolerance_is_what_the_optimiser_guarantees(tmp_path):
    """The allowed end-to-start differences are the optimiser's acceptance tolerance on its
    scaled periodicity rows; an end within them reads, one beyond them is refused."""
    from fdm_awe.ocp.assemble import VIOLATION_TOL
    from fdm_awe.ocp.layout import STATE_SCALE
    from fdm_awe.trajectory.schema import PERIODIC_TOL

    # rows: how many scaled rows (each within the tolerance) tie the end to the start; the line
    # length's start is the distance of a start point within it per coordinate (sqrt 3)
    for name, state, rows in (("x", "x", 2), ("y", "y", 2), ("z", "z", 2), ("tether_length", "l", 1 + math.sqrt(3)),
                              ("V", "V", 1), ("gamma", "gamma", 1), ("psi", "psi", 1)):
        assert PERIODIC_TOL[name] == pytest.approx(rows * VIOLATION_TOL * STATE_SCALE[state], rel=1e-12), name
    for name in ("x", "V", "psi"):
        tol = PERIODIC_TOL[name]
        doc = _doc()
        _shifted_end(name, 0.5 * tol)(doc)
        read_reference(_write(tmp_path, doc, f"{name}_in.json"))
        doc = _doc()
        _shifted_end(name, 2.0 * tol)(doc)
        _refused(_write(tmp_path, doc, f"{name}_out.json"), f"columns.{name}[321]")


@pytest.mark.parametrize("name,i,by", [("x", 100, 500.0), ("z", 250, -60.0), ("y", 7, 20.0)])
def test_a_jump_between_consecutive_points_is_refused(tmp_path, name, i, by):
    doc = _doc()
    doc["columns"][name][i] += by
    _refused(_write(tmp_path, doc), f"columns.{name}[{i}]", "the position moves", f"m from row {i - 1}",
             "largest airspeed", "allowed <=")


def test_stored_references_move_within_the_continuity_bound():
    """The margin is not what lets the stored references through: every step of theirs is
    within the bound without the factor (ground speed <= largest airspeed + wind)."""
    from fdm_awe.trajectory.schema import CONTINUITY_ATOL

    for path in STORED:
        ref = read_reference(path)
        pos = np.stack([ref["x"], ref["y"], ref["z"]], axis=1)
        dist = np.linalg.norm(np.diff(pos, axis=0), axis=1)
        bound = (ref["V"].max() + ref.metadata["wind_mps"]) * np.diff(ref["t"]) + CONTINUITY_ATOL
        assert np.all(dist <= bound), path.name
