"""What the operator sees: the glider mesh, the force arrows and their scale, the attitude, flow
angle, control-surface and force series, the event log in the layout, and plots whose legends
sit off the data, whose labels are not clipped and whose power panel ignores the start-up spike.

The flight is the 3 s circle of test_recording.py (its fixtures, imported).
"""

from __future__ import annotations

import numpy as np
import pytest
from test_recording import DT, _synthetic_result, circle, flight  # noqa: F401 - fixtures

from fdm_awe.recording import flight_forces, record_flight, rrd_entities, rrd_values, rrd_views
from fdm_awe.recording.scene import glider_shape
from fdm_awe.recording.series import STARTUP_S, flight_series

G0 = 9.80665


@pytest.fixture(scope="module")
def recording(flight, circle, tmp_path_factory):  # noqa: F811 - the imported fixtures
    return record_flight(flight, circle, tmp_path_factory.mktemp("rec") / "flight.rrd")


def test_recording_holds_mesh_arrows_series_and_event_log(recording):
    ent = rrd_entities(recording)
    for e in ("/world/glider/airframe/body", "/world/glider/airframe/wing"):
        assert {"Mesh3D:vertex_positions", "Mesh3D:triangle_indices"} <= set(ent[e].components), e
    for name in ("lift", "drag", "tether", "thrust"):
        assert {"Arrows3D:vectors", "Arrows3D:origins"} <= set(ent[f"/world/forces/{name}"].components), name
        assert ent[f"/world/forces/{name}"].rows > 50
    assert {"description", "scale_m_per_N"} <= set(ent["/world/forces"].components)
    for e in ("attitude/roll", "attitude/pitch", "attitude/yaw", "flow/alpha", "flow/beta", "surfaces/aileron",
              "surfaces/elevator", "surfaces/rudder", "surfaces/throttle", "forces/lift", "forces/drag",
              "forces/tether", "forces/thrust"):
        assert "Scalars:scalars" in ent[f"/plots/{e}"].components, e
    assert "TextLog:text" in ent["/events"].components
    views = rrd_views(recording)
    assert views["events"] == ["$origin/**"]  # the event log view (origin /events) in the layout
    assert views["attitude [rad]"] == ["plots/attitude/**"] and views["alpha, beta [rad]"] == ["plots/flow/**"]
    assert views["surfaces, throttle [-]"] == ["plots/surfaces/**"]
    assert views["forces on the glider [N]"] == ["plots/forces/**"]
    assert any(name.startswith("power [W] (y: ") for name in views)  # the robust range, said in the title


def test_glider_mesh_is_the_aircraft_files_geometry(recording):
    shape = glider_shape()
    assert shape.span_unfolded == pytest.approx(1.1) and shape.span_folded == pytest.approx(0.22)
    (verts,), _, _ = rrd_values(recording, "/world/glider/airframe/body", "Mesh3D:vertex_positions")
    (tris,), _, _ = rrd_values(recording, "/world/glider/airframe/body", "Mesh3D:triangle_indices")
    v, t = np.asarray(verts, float), np.asarray(tris, int)
    assert t.min() >= 0 and t.max() < len(v)
    assert v[:, 0].max() == pytest.approx(shape.nose, rel=1e-6)  # the nose (propeller) ahead of the CG
    assert v[:, 2].min() < 0.0  # the fin points up (-z, body axes)
    _, times, wings = rrd_values(recording, "/world/glider/airframe/wing", "Mesh3D:vertex_positions")
    assert times[0] == pytest.approx(0.0, abs=1e-6)
    span = np.ptp(np.asarray(wings[0], float)[:, 1])
    assert span == pytest.approx(shape.span(0.0), rel=1e-6)
    assert np.ptp(shape.wing_mesh(1.0)[0][:, 1]) == pytest.approx(0.22)  # folded
    static, _, _ = rrd_values(recording, "/world/glider/airframe", "Transform3D:scale")
    assert np.allclose(static[0], 10.0)


def _rows_at(times: list[float]) -> np.ndarray:
    """Row index of each recorded time (the rows are DT apart from t = 0)."""
    return np.rint(np.asarray(times) / DT).astype(int)


def test_arrow_lengths_are_the_stated_scale_times_the_forces(recording, flight):  # noqa: F811
    ((scale,),), _, _ = rrd_values(recording, "/world/forces", "scale_m_per_N")  # one row of one value
    ((text,),), _, _ = rrd_values(recording, "/world/forces", "description")
    assert f"{scale:g} m per N" in text
    r = flight.result
    f = flight_forces(flight)
    expected = {"tether": np.linalg.norm(r.tether_force, axis=1), "thrust": np.abs(r.thrust),
                "lift": np.abs(f.L), "drag": np.abs(f.D)}
    for name, magnitude in expected.items():
        _, times, vectors = rrd_values(recording, f"/world/forces/{name}", "Arrows3D:vectors")
        i = _rows_at(times)
        length = np.linalg.norm(np.asarray(vectors, float).reshape(-1, 3), axis=1)
        # float32 storage: ~1e-7 relative
        np.testing.assert_allclose(length, scale * magnitude[i], rtol=1e-5, atol=1e-5, err_msg=name)
        _, _, origins = rrd_values(recording, f"/world/forces/{name}", "Arrows3D:origins")
        np.testing.assert_allclose(np.asarray(origins, float).reshape(-1, 3), r.pos[i], atol=1e-3)
    # the tether arrow points along the logged force, not only as long
    _, times, vectors = rrd_values(recording, "/world/forces/tether", "Arrows3D:vectors")
    np.testing.assert_allclose(np.asarray(vectors, float).reshape(-1, 3), scale * r.tether_force[_rows_at(times)],
                               rtol=1e-5, atol=1e-5)


def test_aerodynamic_force_agrees_with_jsbsim_load_factor(flight):  # noqa: F811
    """The lift and drag come from Newton's second law on the logged motion. Check against
    JSBSim's own accelerometer (the logged load factor = -body-z specific force / g0), which
    the derivation does not use: the body-z component of all forces but weight, over m g0."""
    from fdm_awe.recording.forces import body_axes

    r = flight.result
    f = flight_forces(flight)
    tether = f.tether.copy()
    tether[:-1] = 0.5 * (f.tether[:-1] + f.tether[1:])  # the step mean the derivation uses
    total = f.lift + f.drag + f.side + tether + f.thrust
    fz_body = np.einsum("nij,ni->nj", body_axes(r.euler), total)[:, 2]
    err = -fz_body / (f.mass * G0) - r.load_factor
    late = f.t > 0.1  # the line's first pull is a step in force: two rows ring
    assert np.sqrt(np.mean(err[late][:-1] ** 2)) < 0.01, err  # g (0.003 g here)
    assert np.all(np.abs(np.einsum("ni,ni->n", f.lift, f.drag)[1:]) < 1e-9 * (1 + np.abs(f.L * f.D)[1:]))
    assert np.all(f.D[late] > 0.0) and np.mean(f.L[late]) > 0.5 * f.mass * G0  # drag retards, lift carries


def test_power_panel_range_excludes_the_start_up_spike():
    """A 20 s flight whose propeller draws 700 W for the first half second (the motor spinning
    up) and 40..80 W after: the power panel's y-range covers the flight, not the spike; the
    legend says how the range was chosen."""
    from fdm_awe.recording.plots import POWER_LABEL, time_figure
    from fdm_awe.recording.series import robust_note
    from fdm_awe.sim.result import COLUMNS

    res = _synthetic_result(n=2401, p_elec=20.0)
    t, p = res.data[:, 0], COLUMNS.index("p_prop")
    res.data[:, p] = 60.0 + 20.0 * np.sin(t)
    res.data[t < 0.5, p] = 700.0
    s = flight_series(res)
    fig = time_figure(s, "synthetic", "flight")
    try:
        ax = next(a for a in fig.axes if a.get_ylabel() == POWER_LABEL)
        lo, hi = ax.get_ylim()
        late = s.t >= STARTUP_S
        assert hi < 700.0 and hi >= 0.99 * np.max(s["prop_power"][late])
        assert lo <= min(np.min(s["p_electrical"][late]), np.min(s["prop_power"][late]))
        assert robust_note() in [txt.get_text() for txt in ax.get_legend().get_texts()]
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_time_plots_have_legends_off_the_data_and_no_clipped_labels(flight):  # noqa: F811
    """Every legend lies outside every panel's plotting area, and every label, tick label,
    legend and title lies inside the figure."""
    import matplotlib.pyplot as plt

    from fdm_awe.recording.plots import time_figure

    fig = time_figure(flight_series(flight), "flight", "flight")
    try:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        box = fig.bbox
        axes = [a for a in fig.axes if a.get_visible()]
        legends = [a.get_legend() for a in axes if a.get_legend() is not None] + list(fig.legends)
        assert len(legends) >= 4
        for leg in legends:
            lb = leg.get_window_extent(renderer)
            for a in axes:
                assert not lb.overlaps(a.get_window_extent(renderer)), (leg.get_texts()[0].get_text(), a.get_ylabel())
            assert box.x0 - 1 <= lb.x0 and lb.x1 <= box.x1 + 1 and box.y0 - 1 <= lb.y0 and lb.y1 <= box.y1 + 1
        texts = [fig._suptitle] + [t for a in axes for t in (a.xaxis.label, a.yaxis.label, *a.get_xticklabels(),
                                                              *a.get_yticklabels()) if t.get_visible() and t.get_text()]
        for txt in texts:
            b = txt.get_window_extent(renderer)
            assert box.x0 - 1 <= b.x0 and b.x1 <= box.x1 + 1 and box.y0 - 1 <= b.y0 and b.y1 <= box.y1 + 1, txt
    finally:
        plt.close(fig)
