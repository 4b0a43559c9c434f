"""The flight as ``fdm-awe fly`` flies it: the hooks it attaches (the progress bar, the start
mode, the MAVLink endpoint with its telemetry and link-loss failsafe, the pacing against the
wall clock, the live viewer), the MAVLink link opened before the work with its boot heartbeat,
and the vehicle kept on the link after the flight until a ground station shuts it down."""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any, Callable

from ._aircraft import aircraft_from_args
from ._station import station_from_args


def boot_beacon(args: argparse.Namespace, link: Any) -> Any:
    """The heartbeat sent while the rest loads (:class:`~fdm_awe.mavlink.boot.BootBeacon`) on the
    opened ``--mavlink`` link, None without one."""
    if link is None:
        return None
    from ..mavlink.boot import BootBeacon

    return BootBeacon(link, args.mode, signing_key=getattr(args, "signing_key", None))


def stay_on_link(endpoint: Any, tel: Any, t_end: float) -> None:
    """After the flight and its outputs: keep the vehicle on the MAVLink link, answering
    (heartbeats and the streams of the last simulated state, parameters, the mission; the
    commands that would fly refused with their reason), until a ground station shuts it down
    (MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN 2) or Ctrl-C; the endpoint's clock runs on from the
    flight's end time ``t_end`` [s] at wall-clock rate."""
    print("flight over: the vehicle stays on the MAVLink link (the last simulated state) until a ground station "
          "shuts it down (MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN 2) or Ctrl-C (--exit-after-cycles: end at once)",
          file=sys.stderr, flush=True)
    w0 = time.monotonic()
    try:
        while not endpoint.shutdown_requested:
            endpoint.update(t_end + (time.monotonic() - w0), tel)
            time.sleep(0.01)
    except KeyboardInterrupt:
        print("\nCtrl-C: the vehicle leaves the link", file=sys.stderr)
        return
    endpoint.update(t_end + (time.monotonic() - w0), tel)  # the COMMAND_ACK of the shutdown goes out
    print("shut down by the ground station", file=sys.stderr)


def open_mavlink(args: argparse.Namespace) -> Any:
    """The ``--mavlink`` transport opened (a tcp client connected once, bounded in time), or
    None without ``--mavlink``; one-line error naming the option when it cannot be opened."""
    if not args.mavlink:
        return None
    from ..mavlink.transport import open_link

    return open_link(args.mavlink)


class _FlightHooks:
    """What the command attaches to a flight: the progress bar (unless ``--quiet`` or not a
    terminal; ``n_total`` steps), and at the flight's set-up the start mode (``--mode``), the
    MAVLink endpoint with its telemetry and link-loss failsafe (``--mavlink``) and the pacing
    against the wall clock (``--realtime``) and the live viewer (``--spawn`` / ``--connect``,
    ``live``); all called after every step (:meth:`on_step`)."""

    def __init__(self, args: argparse.Namespace, n_total: int, live: Any = None, link: Any = None,
                 beacon: Any = None) -> None:
        self.args = args
        self.live = live
        self.link = link  #: the --mavlink transport, opened before the work (None: opened at set-up)
        self.beacon = beacon  #: the boot heartbeat on ``link``, stopped before the endpoint's first update
        self.endpoint: Any = None
        self.telemetry: Any = None  #: the last step's telemetry, built when read (``--mavlink``)
        self.bar: Any = None
        self._hooks: list[Callable[[int, Any, Any], None]] = []
        if not args.quiet and sys.stderr.isatty():
            from tqdm import tqdm

            bar = self.bar = tqdm(total=n_total, unit="step", desc="flying", file=sys.stderr, mininterval=0.5)
            self._hooks.append(lambda k, s, o: bar.update(600) if k % 600 == 0 else None)

    def setup(self, ap: Any, sim: Any) -> None:
        """The flight's ``setup(autopilot, cosim)``."""
        args = self.args
        if args.mode != "AUTO":
            ap.set_mode(args.mode)
        if args.mavlink:
            from ..mavlink.bridge import telemetry_builder
            from ..mavlink.endpoint import MavlinkEndpoint

            endpoint = self.endpoint = MavlinkEndpoint(args.mavlink, vehicle=ap,
                                                       signing_key=getattr(args, "signing_key", None),
                                                       signing_key_file=args.mavlink_key, connection=self.link)
            self.link = None  # the endpoint owns it now
            build = telemetry_builder(ap, sim)

            def link(k: int, s: Any, o: Any) -> None:
                if self.beacon is not None:  # the first step: the endpoint sends from now on
                    self.beacon.stop()
                    self.beacon = None
                build.integrate(s)
                self.telemetry = lambda: build(s, o)
                endpoint.update(s.t, self.telemetry)
                ap.gcs_link(endpoint.link_up, s.t)  # the link-loss failsafe (FS_GCS_ENABL)

            self._hooks.append(link)
        if args.realtime:
            from ..sim.pacing import RealtimePacer

            pacer = RealtimePacer(args.realtime)
            self._hooks.append(lambda k, s, o: pacer.wait(s.t))
        if self.live is not None:
            self.live.setup(ap, sim)
            self._hooks.append(self.live)
        print(f"flying: {args.cycles} cycle(s), mode {ap.mode}", file=sys.stderr, flush=True)  # set up, the loop starts

    @property
    def per_step(self) -> bool:
        """Whether the flight has work for every step (progress bar, MAVLink, pacing, live
        viewer); without, it passes no ``on_step`` and the autopilot may fly compiled blocks."""
        a = self.args
        return bool(self._hooks) or bool(a.mavlink) or bool(a.realtime) or self.live is not None

    def on_step(self, k: int, s: Any, o: Any) -> None:
        """The flight's ``on_step``: every hook in turn."""
        for h in self._hooks:
            h(k, s, o)

    def close(self, keep_endpoint: bool = False) -> None:
        """Close the progress bar, the MAVLink endpoint unless ``keep_endpoint`` (or the link no
        endpoint took) and the live viewer's stream."""
        if self.bar is not None:
            self.bar.close()
        if self.beacon is not None:
            self.beacon.stop()
        if self.endpoint is not None:
            if not keep_endpoint:
                self.endpoint.close()
        elif self.link is not None:
            from ..mavlink.transport import close_link

            close_link(self.link)
            self.link = None
        if self.live is not None:
            self.live.close()


def fly_with_hooks(args: argparse.Namespace, ref: Any, params: Any, plant: str, scale: float, live: Any = None,
                   link: Any = None, refs: Any = None, flight_wind: dict[str, Any] | None = None, beacon: Any = None,
                   stay: list[Any] | None = None) -> Any:
    """Fly ``ref`` as the options say (:func:`fdm_awe.sim.flight.fly` with the command's hooks);
    the report's wall time is the whole flight's, hooks included. The ground station on the
    MAVLink link (``link``, opened before the work, its boot heartbeat ``beacon``) is told how the
    flight ended; the link is closed here, or, without ``--exit-after-cycles``, when the flight
    ended by itself and a ground station was heard on the link during it, its endpoint, the last
    telemetry and the end time go into ``stay`` (:func:`stay_on_link`)."""
    from ..sim import flight

    hooks = _FlightHooks(args, int(round(args.cycles * ref.period / args.dt)), live, link, beacon)
    t0 = time.perf_counter()
    keep = False
    try:
        report = flight.fly(ref, config=args.config, cycles=args.cycles, dt=args.dt, turbulence=args.turbulence,
                            on_step=hooks.on_step if hooks.per_step else None, params=params, setup=hooks.setup,
                            plant=plant, tether_drag_scale=scale, tether=args.tether, references=refs,
                            flight_wind=flight_wind, aircraft=aircraft_from_args(args), ground_station=station_from_args(args))
        if hooks.endpoint is not None:
            hooks.endpoint.flight_ended(report.status, report.message)  # the crash or landing, told to the ground station
            if (stay is not None and not getattr(args, "exit_after_cycles", False) and report.status != "interrupted"
                    and hooks.telemetry is not None and hooks.endpoint.ever_linked):
                tel = hooks.telemetry()
                stay[:] = [hooks.endpoint, tel, float(tel.t)]
                keep = True
        if live is not None:
            live.finish(report)  # the last rows, the flown path, the events and the report
    finally:
        hooks.close(keep_endpoint=keep)
    report.wall_s = time.perf_counter() - t0
    return report
