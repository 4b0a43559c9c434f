"""The Python API: optimise, fly and sweep pumping cycles from a script or a notebook.

The functions here are the top level of the package (``fdm_awe.optimize``, ``fdm_awe.fly``,
``fdm_awe.sweep``, ``fdm_awe.load_reference``). Each takes the route of its command line
(:mod:`fdm_awe.commands`): the same option checks (an :class:`~fdm_awe.errors.InputError` with
one line naming the keyword, the field and the allowed range, before any work), the same
defaults (:mod:`fdm_awe.defaults`), the same solver and flight calls, so a call and the command
with the same options give the same numbers. Each returns a result object
(:mod:`fdm_awe.api_results`) whose :meth:`~fdm_awe.api_results.OptimizeResult.to_dict` is the
document the command's ``--json`` writes, whose time series are numpy arrays named as the CSV
columns (the unit in every name, e.g. ``tension_N``) and which makes a pandas ``DataFrame`` on
request (:meth:`~fdm_awe.api_results.FlightResult.to_dataframe`; pandas is not a dependency of
the package).

Units are SI throughout: m, s, m/s, rad (the command's degree options ``wind_from`` excepted, as
the command line), J, W, N.

Example
-------
>>> import fdm_awe
>>> cycle = fdm_awe.optimize(config="nominal", wind=8.0, mesh="30,16,3")      # doctest: +SKIP
>>> flight = fdm_awe.fly(cycle, cycles=1)                                      # doctest: +SKIP
>>> flight.cycles[0]["E_net_J"], cycle.E_net_J                                 # doctest: +SKIP
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterator

from . import defaults as D
from .api_results import FlightResult, OptimizeResult, SweepResult, tracking_reference

if TYPE_CHECKING:  # pragma: no cover
    from .trajectory import ReferenceTrajectory

__all__ = ["fly", "load_reference", "optimize", "sweep"]


# --------------------------------------------------------------------------------------------
# the command line's route


def _namespace(command: str, required: list[str] | None = None, **given: Any) -> argparse.Namespace:
    """The command's parsed options with its own defaults (``required``: the arguments it
    cannot parse without), ``given`` set on top (keyword -> option attribute)."""
    from .cli import build_parser

    parser = build_parser()
    args = parser.parse_args([command, *(required or [])])
    for k, v in given.items():
        if not hasattr(args, k):
            raise TypeError(f"{command}() got an unexpected keyword argument {k!r}")
        setattr(args, k, v)
    return args


@contextlib.contextmanager
def _quiet(verbose: bool) -> Iterator[None]:
    """The command's printed lines (stdout and stderr) shown when ``verbose``, else dropped."""
    if verbose:
        yield
        return
    sink = io.StringIO()
    with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
        yield


@contextlib.contextmanager
def _keep_plot_backend() -> Iterator[None]:
    """The caller's matplotlib backend (a notebook's inline one) back after the work: the
    commands' plot files switch matplotlib to its file backend ``Agg``."""
    import sys

    before = sys.modules["matplotlib"].get_backend() if "matplotlib.pyplot" in sys.modules else None
    try:
        yield
    finally:
        if before is not None:
            import matplotlib.pyplot as plt

            if plt.get_backend() != before:
                plt.switch_backend(before)
                _reenable_inline(before)


def _reenable_inline(backend: str) -> None:
    """In an IPython kernel, the inline backend's figure display again (switching to ``Agg``
    turned it off)."""
    import sys

    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None and hasattr(ipython, "get_ipython") else None
    if shell is None or "inline" not in backend:
        return
    try:
        from matplotlib_inline.backend_inline import configure_inline_support
    except ImportError:  # pragma: no cover (IPython without its inline backend)
        return
    configure_inline_support(shell, backend)


def _read_json(path: Path) -> dict[str, Any]:
    import json

    return json.loads(path.read_text())


# --------------------------------------------------------------------------------------------
# the functions


def load_reference(path_or_example: str | os.PathLike) -> "ReferenceTrajectory":
    """Read and check a reference trajectory.

    Parameters
    ----------
    path_or_example : str or path
        A reference-trajectory file (written by ``fdm-awe optimize --trajectory`` or
        :meth:`OptimizeResult.write_reference <fdm_awe.api_results.OptimizeResult.write_reference>`),
        or ``"example:NAME"``, one of the stored references the package carries
        (:data:`fdm_awe.example_refs.EXAMPLES`, e.g. ``"example:nominal-8"``: the physical
        nominal glider at 8 m/s, flyable bounds).

    Returns
    -------
    ReferenceTrajectory
        ``metadata`` (scenario, config, wind [m/s], energies [J], ...), ``columns`` (arrays,
        SI units) and ``units``; :func:`fly` flies it.
    """
    from .example_refs import example_path, is_example
    from .trajectory import read_reference

    text = os.fspath(path_or_example)
    return read_reference(example_path(text, "load_reference") if is_example(text) else text)


def optimize(*, scenario: str = D.SCENARIO, config: str = D.CONFIG, wind: float = D.WIND_MPS,
             wind_from: float = D.WIND_FROM_DEG, d0: float = D.D0_M, d_tf: float = D.D_TF_M,
             v_min: float = D.V_MIN_MPS, v_max: float = D.V_MAX_MPS, h_min: float = D.H_MIN_M,
             t_max: float = D.T_MAX_S, flyable: bool = False, tether_drag_scale: float = D.TETHER_DRAG_SCALE,
             line: str | None = None, propeller: str | None = None, line_weight: bool | None = None,
             generator: str | None = None, wind_profile: str | None = None, wind_ref_height: float | None = None,
             bank_rate_max: float | None = None, alpha_rate_max: float | None = None,
             catch_speed_max: float | None = None, mesh: str | None = None, starts: int = 1,
             time_budget: float = 180.0, verify: bool = False, aircraft: str | os.PathLike | None = None,
             ground_station: str | os.PathLike | None = None, verbose: bool = False) -> OptimizeResult:
    """Optimise one periodic pumping cycle, as ``fdm-awe optimize`` does.

    Parameters
    ----------
    scenario : {"physical", "paper"}
        Model family (docs/design.md section 4).
    config : {"nominal", "foldable"}
        Nominal: unfolded throughout; foldable: folded for recovery.
    wind : float
        Wind speed [m/s], 0..25, at ``wind_ref_height`` for a shear profile.
    wind_from : float
        Direction the wind blows from [deg, compass], -360..360 (180: from the south).
    d0, d_tf : float
        Tether length at the cycle start and at the end of generation [m].
    v_min, v_max : float
        Airspeed bounds [m/s].
    h_min : float
        Ground clearance [m].
    t_max : float
        Longest cycle T1 + T2 [s].
    flyable : bool
        Keep the flyable margins (C_L <= 0.85 C_Lmax, tension <= 50 N / 1.25, bank <= 0.8 rad),
        the bounds with which :func:`fly` optimises its own reference; default Table 3's bounds.
    tether_drag_scale : float
        Factor on the line drag, 0..10 (physical scenario).
    line, propeller, line_weight, generator : optional
        The optimiser's plant (None: the scenario's default; ``fdm-awe optimize --help``).
    wind_profile : str, optional
        ``"uniform"``, ``"log:Z0"`` (Z0 [m]) or ``"power:ALPHA"``.
    wind_ref_height : float, optional
        Height [m] at which ``wind`` holds for a log or power profile (default 10 m).
    bank_rate_max, alpha_rate_max : float, optional
        Rate bounds of the reference's bank and angle of attack [rad/s].
    catch_speed_max : float, optional
        Closing speed bound of the line at the catch [m/s].
    mesh : str, optional
        ``"NG,NR,DEG"``: collocation intervals in generation, recovery and the Radau degree
        (default 60,20,4; e.g. ``"30,16,3"`` for a quick coarse cycle).
    starts : int
        Successful starts to compare on a coarse mesh, 1..100.
    time_budget : float
        Solver seconds before the optimisation is reported as failed.
    verify : bool
        Re-integrate the optimal controls and add the check (``verification``) to the document.
    aircraft, ground_station : str or path, optional
        The glider (a name of the package's aircraft table, ``"glider"``, the default, or a definition folder) and the
        ground-station definition file (default: the package's); ``fdm-awe info --export DIR`` writes both to start from.
    verbose : bool
        Print the command's lines (progress, summary).

    Returns
    -------
    OptimizeResult
        ``ok``, the ``--json`` numbers (``E_net_J`` [J], ``P_avg_W`` [W], ...), the reference
        trajectory and the time series.
    """
    from .commands import optimize as O

    args = _namespace("optimize", scenario=scenario, config=config, wind=wind, wind_from=wind_from, d0=d0, d_tf=d_tf,
                      v_min=v_min, v_max=v_max, h_min=h_min, t_max=t_max, flyable=flyable,
                      tether_drag_scale=tether_drag_scale, line=line, propeller=propeller, line_weight=line_weight,
                      generator=generator, wind_profile=wind_profile, wind_ref_height=wind_ref_height,
                      bank_rate_max=bank_rate_max, alpha_rate_max=alpha_rate_max, catch_speed_max=catch_speed_max,
                      mesh=mesh, starts=starts, time_budget=time_budget, verify=verify,
                      aircraft=None if aircraft is None else os.fspath(aircraft), ground_station=ground_station)
    with _quiet(verbose):
        problem = O.problem_from_args(args)
        from .ocp import build, solve

        res = solve.solve_cycle(problem, n_starts=args.starts, time_budget_s=args.time_budget)
        if verbose:
            O.print_summary(res)
        doc = res.summary()
        if res.ok and verify:
            from .ocp.verify import verify as check

            doc["verification"] = check(res, build.get_nlp(problem)[0]).as_dict()
    return OptimizeResult(result=res, document=doc)


def fly(reference: Any = None, *, scenario: str | None = None, config: str | None = None,
        wind: float | None = None, wind_from: float | None = None, cycles: int = D.CYCLES, dt: float = D.DT_S,
        turbulence: str | None = None, tether: str = D.TETHER, tether_drag_scale: float | None = None,
        gamma_max: float | None = None, v_min: float | None = None, line: str | None = None,
        propeller: str | None = None, line_weight: bool | None = None, generator: str | None = None,
        wind_profile: str | None = None, wind_ref_height: float | None = None, allow_mismatch: bool = False,
        mode: str = "AUTO", params: str | os.PathLike | None = None, mavlink: str | None = None,
        mavlink_key: str | os.PathLike | None = None, realtime: float | None = None,
        out: str | os.PathLike | None = None, rrd: str | os.PathLike | None = None,
        json: str | os.PathLike | None = None, aircraft: str | os.PathLike | None = None, verbose: bool = False,
        ground_station: str | os.PathLike | None = None, **options: Any) -> FlightResult:
    """Fly pumping cycles of a reference in 6-DOF co-simulation, as ``fdm-awe fly`` does.

    Parameters
    ----------
    reference : optional
        What to fly: a reference file, ``"example:NAME"`` (:func:`load_reference`), an
        :class:`~fdm_awe.api_results.OptimizeResult`, a reference trajectory or a tracking
        reference. None: optimise one first with the flyable bounds (``scenario``, ``config``,
        ``wind``, ...; the defaults of :mod:`fdm_awe.defaults`).
    scenario, config : str, optional
        The plant and the glider (default: the reference's, else physical and nominal).
    wind, wind_from : float, optional
        Wind [m/s] and its direction [deg] of the reference to optimise (not with a reference).
    cycles : int
        Pumping cycles, 1..1000.
    dt : float
        Co-simulation step [s].
    turbulence : str, optional
        ``"FORM[:SEED]"``, e.g. ``"moderate:3"`` or ``"iec:B"`` (docs/wind.md).
    tether : str
        ``"straight"``, ``"lumped:N"`` (N elastic segments) or another ``--tether`` form
        (``fdm_awe.groundstation.linemodels.LINE_MODELS``).
    tether_drag_scale : float, optional
        Factor on the line drag (default: the reference's).
    gamma_max, v_min, line, propeller, line_weight, generator, wind_profile, wind_ref_height : optional
        The reference to optimise (not with a reference; ``fdm-awe fly --help``).
    allow_mismatch : bool
        Fly a reference with another ``config``/``scenario`` than its own.
    mode : {"AUTO", "RECOVER"}
        Autopilot mode at the start.
    params : path, optional
        Autopilot parameter file.
    mavlink : str, optional
        Speak MAVLink 2 to a ground station, e.g. ``"udpout:127.0.0.1:14550"``.
    mavlink_key : path, optional
        MAVLink 2 signing key file.
    realtime : float, optional
        Pace against the wall clock at this factor.
    out, rrd, json : path, optional
        Output folder (recording, plots, CSV, report), recording and JSON file, as the command's.
    aircraft, ground_station : str or path, optional
        The glider flown (and optimised without a reference): a name of the package's aircraft table (``"glider"``,
        the default) or a definition folder; the ground-station definition file (default: the package's). A reference
        optimised for another aircraft or with another station is flown with a warning.
    verbose : bool
        Print the command's lines (progress, the per-cycle table).
    **options
        Any other option of ``fdm-awe fly`` by its attribute name (``references="DIR"``,
        ``start_wind=8.0``, ``bank_rate_max=0.5``, ...).

    Returns
    -------
    FlightResult
        The ``--json`` numbers (status, per-cycle energies [J] beside the reference's own),
        the time series and the exit code the command would give.
    """
    from .commands import fly as F

    mem_ref = None
    if reference is not None and not isinstance(reference, (str, os.PathLike)):
        mem_ref = tracking_reference(reference)
        reference = None
    options.setdefault("exit_after_cycles", True)  # a call returns after its cycles (no ground station keeps it)
    args = _namespace("fly", reference=None if reference is None else os.fspath(reference), scenario=scenario,
                      config=config, wind=wind, wind_from=wind_from, cycles=cycles, dt=dt, turbulence=turbulence,
                      tether=tether, tether_drag_scale=tether_drag_scale, gamma_max=gamma_max, v_min=v_min,
                      line=line, propeller=propeller, line_weight=line_weight, generator=generator,
                      wind_profile=wind_profile, wind_ref_height=wind_ref_height, allow_mismatch=allow_mismatch,
                      mode=mode, params=None if params is None else os.fspath(params), mavlink=mavlink,
                      mavlink_key=None if mavlink_key is None else os.fspath(mavlink_key), realtime=realtime,
                      out=None if out is None else os.fspath(out), rrd=None if rrd is None else os.fspath(rrd),
                      json=None if json is None else os.fspath(json), quiet=True,
                      aircraft=None if aircraft is None else os.fspath(aircraft), ground_station=ground_station, **options)
    got: dict[str, Any] = {}
    with _quiet(verbose), _keep_plot_backend(), tempfile.TemporaryDirectory(prefix="fdm-awe-api-") as tmp:
        if args.json is None:
            args.json = str(Path(tmp) / "flight.json")  # the command's document, read back
        code = F.run(args, given=mem_ref, result=got)  # the command's route: its checks, flight and outputs
        doc = _read_json(Path(args.json))
    return FlightResult(report=got["report"], document=doc, reference=got["reference"], exit_code=code)


def sweep(out: str | os.PathLike, *, wind: str = D.SWEEP_WINDS, config: str = D.SWEEP_CONFIGS, verbose: bool = False,
          scenario: str = D.SCENARIO, mesh: str | None = None, workers: int | None = 1,
          scheduler: str | None = None, cold: bool = False, cold_check: bool = True, json: str | os.PathLike | None = None,
          aircraft: str | os.PathLike | None = None, ground_station: str | os.PathLike | None = None, **options: Any) -> SweepResult:
    """Power curves and design sweeps on Dask, as ``fdm-awe sweep`` does.

    Parameters
    ----------
    out : path
        The sweep's folder: point files (a rerun computes only the missing points), ``points.csv``,
        ``power_curve.png``, ``summary.md``.
    wind : str
        Wind speeds [m/s]: ``"START:STOP:STEP"`` or a comma list, each 0..25.
    config : str
        ``"nominal"``, ``"foldable"`` or both, comma-separated.
    scenario : {"physical", "paper"}
        Model family.
    mesh : str, optional
        ``"NGEN,NREC[,DEG]"`` (default: the optimiser's).
    workers : int, optional
        Local Dask worker processes (None: one per core; not with ``scheduler``).
    scheduler : str, optional
        An external Dask scheduler, ``tcp://HOST:PORT``.
    cold : bool
        Solve every point cold (no warm starts along the wind axis).
    cold_check : bool
        Also solve warm-started points cold and keep the better (``--no-cold-check`` when False).
    json : path, optional
        Also write the ``--json`` document there.
    aircraft, ground_station : str or path, optional
        The glider of every point (a name of the package's aircraft table, ``"glider"``, the default, or a
        definition folder) and the ground-station definition file (default: the package's).
    verbose : bool
        Print the command's lines.
    **options
        Any other option of ``fdm-awe sweep`` by its attribute name (``folded_span="0.3,0.4"``,
        ``tether_range="200:250"``, ``fold_time``, ``line``, ``max_iter``, ...).

    Returns
    -------
    SweepResult
        The points (``wind_mps`` [m/s], ``P_avg_W`` [W], ``status``, ...), the answer and the files.
    """
    from .commands import sweep as S

    args = _namespace("sweep", ["--out", os.fspath(out)], wind=wind, config=config, scenario=scenario, mesh=mesh,
                      workers=workers, scheduler=scheduler, cold=cold, no_cold_check=not cold_check,
                      json=None if json is None else os.fspath(json), no_progress=not verbose,
                      aircraft=None if aircraft is None else os.fspath(aircraft), ground_station=ground_station, **options)
    if scheduler is not None and "workers" not in options:
        args.workers = None
    with _quiet(verbose), _keep_plot_backend():
        S.check_args(args)
        spec = S.build_spec(args)
        S.check_not_in_points(args)
        with tempfile.TemporaryDirectory(prefix="fdm-awe-api-") as tmp:
            user_json = args.json
            locks = S.output_locks(args, "json", "out")
            args.json = str(Path(tmp) / "sweep.json") if user_json is None else user_json
            with locks:
                code = S.run_checked(args, spec)
            doc = _read_json(Path(args.json))
    return SweepResult(document=doc, out=Path(out), exit_code=code)
