"""The sweep's point store: damaged files count as absent (one warning line naming the file, the
point is computed again and its files overwritten), nothing is deleted, writes are atomic.

The unit tests use real records and warm starts of the store's format; the last test runs a
real two-point sweep (Dask, IPOPT, coarse mesh) over a damaged store.
"""

from __future__ import annotations

import json
import pickle

import numpy as np
import pytest

from fdm_awe.ocp.problem import Mesh
from fdm_awe.sweep.runner import Warm, base_record
from fdm_awe.sweep.spec import Point, SweepSpec
from fdm_awe.sweep.store import PointStore

POINT = Point("physical", "nominal", 8.0, 200.0, 250.0, mesh=(6, 4, 3))
PID = POINT.id


def _record(status: str = "ok") -> dict:
    rec = base_record(POINT)
    rec.update(status=status, reason="Solve_Succeeded" if status == "ok" else "Infeasible_Problem_Detected",
               P_avg_W=-12.5 if status == "ok" else None, iterations=42)
    return rec


def _warm(n: int = 50) -> Warm:
    rng = np.random.default_rng(3)
    return Warm(PID, rng.normal(size=n), rng.normal(size=n), rng.normal(size=2 * n), -2)


@pytest.fixture
def store(tmp_path) -> PointStore:
    s = PointStore(tmp_path)
    s.write(_record(), _warm())
    return s


def _one_warning(capsys, path) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert str(path) in err[0] and err[0].startswith("warning:"), err[0]
    return err[0]


def test_written_point_reads_back_and_leaves_no_temporary_file(store, capsys):
    assert store.load(PID) == _record()
    w, ref = store.load_warm(PID), _warm()
    for k in ("w", "lam_x", "lam_g"):
        np.testing.assert_array_equal(getattr(w, k), getattr(ref, k))
    assert w.k_wrap == -2 and w.point_id == PID
    assert store.records([PID, "0" * 16]) == {PID: _record()}
    assert sorted(p.name for p in store.dir.iterdir()) == sorted([f"{PID}.json", f"{PID}.warm.npz"])
    assert capsys.readouterr().err == ""


def test_missing_warm_start_is_no_damage(tmp_path, capsys):
    s = PointStore(tmp_path)
    s.write(_record(), None)
    assert s.load_warm(PID) is None and s.records([PID]) == {PID: _record()}
    assert capsys.readouterr().err == ""


BAD_RECORDS = {
    "truncated": lambda: json.dumps(_record())[:50].encode(),
    "empty": lambda: b"",
    "binary": lambda: bytes(range(256)),
    "latin1": lambda: '{"id": "caf\u00e9"}'.encode("latin-1"),
    "deeply_nested": lambda: b"[" * 100_000 + b"]" * 100_000,
    "list": lambda: b"[1, 2, 3]",
    "null": lambda: b"null",
    "string": lambda: b'"ok"',
    "number": lambda: b"3.5",
    "empty_object": lambda: b"{}",
    "no_status": lambda: json.dumps({k: v for k, v in _record().items() if k != "status"}).encode(),
    "no_wind": lambda: json.dumps({k: v for k, v in _record().items() if k != "wind_mps"}).encode(),
    "wind_as_text": lambda: json.dumps({**_record(), "wind_mps": "8"}).encode(),
    "other_point": lambda: json.dumps({**_record(), "id": "0123456789abcdef"}).encode(),
    "status_unknown": lambda: json.dumps({**_record(), "status": "maybe"}).encode(),
    "ok_without_power": lambda: json.dumps({**_record(), "P_avg_W": None}).encode(),
    "energy_as_text": lambda: json.dumps({**_record(), "E_net_J": "a lot"}).encode(),
    "line_weight_as_number": lambda: json.dumps({**_record(), "line_weight": 1}).encode(),
}


@pytest.mark.parametrize("case", list(BAD_RECORDS))
def test_unusable_record_counts_as_absent_with_one_warning(store, capsys, case):
    p = store.json_path(PID)
    data = BAD_RECORDS[case]()
    p.write_bytes(data)
    assert store.records([PID]) == {}
    _one_warning(capsys, p)
    assert p.read_bytes() == data  # not deleted: overwritten only when the point is recomputed
    store.write(_record(), _warm())
    assert store.records([PID]) == {PID: _record()}


def _npz(**arrays) -> bytes:
    import io

    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _good_warm_bytes() -> bytes:
    w = _warm()
    return _npz(w=w.w, lam_x=w.lam_x, lam_g=w.lam_g, k_wrap=np.array(w.k_wrap))


BAD_WARM = {
    "truncated": lambda: _good_warm_bytes()[: len(_good_warm_bytes()) // 2],
    "cut_at_the_end": lambda: _good_warm_bytes()[:-30],
    "empty": lambda: b"",
    "text": lambda: b"not an archive\n",
    "array_missing": lambda: _npz(w=_warm().w, lam_x=_warm().lam_x, k_wrap=np.array(1)),
    "pickled_object": lambda: _npz(w=np.array([{"a": 1}], dtype=object), lam_x=_warm().lam_x, lam_g=_warm().lam_g,
                                   k_wrap=np.array(1)),
    "nan_in_w": lambda: _npz(w=np.r_[_warm().w[:-1], np.nan], lam_x=_warm().lam_x, lam_g=_warm().lam_g, k_wrap=np.array(1)),
    "matrix_w": lambda: _npz(w=_warm().w.reshape(5, 10), lam_x=_warm().lam_x, lam_g=_warm().lam_g, k_wrap=np.array(1)),
    "k_wrap_float": lambda: _npz(w=_warm().w, lam_x=_warm().lam_x, lam_g=_warm().lam_g, k_wrap=np.array(1.5)),
    "plain_pickle": lambda: pickle.dumps(_warm()),
}


@pytest.mark.parametrize("case", list(BAD_WARM))
def test_unusable_warm_start_makes_the_point_recomputed(store, capsys, case):
    p = store.warm_path(PID)
    data = BAD_WARM[case]()
    p.write_bytes(data)
    assert store.load_warm(PID) is None
    _one_warning(capsys, p)
    # an ok point whose warm start is unusable is computed again (its chain needs the warm start)
    assert store.records([PID]) == {}
    _one_warning(capsys, p)
    assert p.read_bytes() == data
    store.write(_record(), _warm())
    assert store.records([PID]) == {PID: _record()} and store.load_warm(PID) is not None


def test_failed_record_does_not_need_a_warm_start(tmp_path, capsys):
    s = PointStore(tmp_path)
    s.write(_record("failed"), None)
    s.warm_path(PID).write_bytes(b"junk")  # a failed point passes on its upstream's warm start, not this
    assert s.records([PID]) == {PID: _record("failed")}
    assert capsys.readouterr().err == ""


def test_sweep_over_a_damaged_store_recomputes_the_damaged_points(tmp_path, capsys):
    """A real two-point sweep (one warm-start chain 8 -> 9 m/s); then the first point's warm
    start is truncated and the second's record replaced by a JSON list: the rerun warns once
    per file, computes exactly those two points again and leaves a valid store."""
    from fdm_awe.sweep.execute import run_sweep

    spec = SweepSpec(winds=(8.0, 9.0), configs=("nominal",), mesh=Mesh(n_gen=6, n_rec=4, degree=3))
    first = run_sweep(spec, str(tmp_path), workers=1, progress=False)
    assert first.complete and first.n_computed == 2 and not first.errors
    ids = [p.id for p in spec.validate().points()]
    store = PointStore(tmp_path)
    by_wind = {store.load(pid)["wind_mps"]: pid for pid in ids}
    a, b = by_wind[8.0], by_wind[9.0]
    warm_a = store.warm_path(a)
    warm_a.write_bytes(warm_a.read_bytes()[:100])
    store.json_path(b).write_text("[1, 2]")
    capsys.readouterr()
    second = run_sweep(spec, str(tmp_path), workers=1, progress=False)
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("warning:")]
    assert any(str(warm_a) in ln for ln in err) and any(str(store.json_path(b)) in ln for ln in err), err
    assert second.complete and second.n_cached == 0 and sorted(second.computed_ids) == sorted(ids)
    assert set(store.records(ids)) == set(ids) and store.load_warm(a) is not None
    for pid in ids:  # the same cycles as before the damage (same cold anchor, same warm-start chain)
        r1, r2 = first.records[pid], second.records[pid]
        assert r2["status"] == r1["status"]
        if r1["status"] == "ok":
            assert r2["P_avg_W"] == pytest.approx(r1["P_avg_W"], rel=1e-6)
