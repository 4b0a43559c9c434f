"""``--ground-station FILE``: the option every command that uses the ground station shares, and
the check of a reference against the station that flies it."""

from __future__ import annotations

import argparse
from typing import Any

from ._aircraft import warn_other_definition

#: what ``fly`` does with a reference optimised for another ground station (as for another aircraft)
OTHER_STATION_POLICY = "warn"


def add_station_arg(p: argparse.ArgumentParser, what: str = "the ground station") -> None:
    """``--ground-station FILE`` (default None: the package's ``tether/ground_station.xml``)."""
    p.add_argument("--ground-station", default=None, metavar="FILE",
                   help=f"{what}: a ground-station definition with the layout of the package's "
                        "tether/ground_station.xml (drum, DC machine, converter, speed controller, lines; 'fdm-awe info "
                        "--export DIR' writes a copy to start from), read instead of the package's and checked before "
                        "any work (default: the package's)")


def station_from_args(args: argparse.Namespace) -> Any:
    """The :class:`~fdm_awe.groundstation.source.StationFile` of ``--ground-station`` (resolved
    and checked once; one-line errors naming the option), kept in ``args.ground_station_def``."""
    from ..groundstation.source import resolve_ground_station

    st = getattr(args, "ground_station_def", None)
    if st is None:
        st = args.ground_station_def = resolve_ground_station(getattr(args, "ground_station", None), "--ground-station")
    return st


def check_reference_station(meta: dict[str, Any], station: Any, source: object) -> bool:
    """Warn (one line on stderr) when the reference ``source`` (metadata ``meta``) was optimised
    with a ground station other than ``station`` (its recorded hash differs; a reference that
    records none was optimised with the package's station before references recorded it). The
    flight goes ahead: flying a cycle on another drive is a legitimate study, but the trajectory
    is not that station's optimum. Returns whether the stations differ."""
    rec = meta.get("ground_station")
    return warn_other_definition(source, rec, rec.get("file") if isinstance(rec, dict) else None, station,
                                 "with the ground station", "ground station", "the package's", "this station's optimum")
    if station.builtin:
        return False
    print(f"warning: {source} records no ground station (written before references recorded it: the package's); "
          f"flying {station.label()}: the reference is not this station's optimum", file=sys.stderr)
    return True


def check_reference_definitions(meta: dict[str, Any], args: argparse.Namespace, source: object) -> None:
    """Warn (stderr) where the reference ``source`` (metadata ``meta``) was optimised for another
    aircraft (``--aircraft``) or with another ground station (``--ground-station``) than flies it."""
    from ._aircraft import aircraft_from_args, check_reference_aircraft

    check_reference_aircraft(meta, aircraft_from_args(args), source)
    check_reference_station(meta, station_from_args(args), source)
