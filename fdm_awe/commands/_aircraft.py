"""``--aircraft NAME|DIR``: the option every command that uses the glider shares, and the check
of a reference against the aircraft that flies it."""

from __future__ import annotations

import argparse
import sys
from typing import Any

#: what ``fly`` does with a reference optimised for another aircraft (docs/design.md section 1)
OTHER_AIRCRAFT_POLICY = "warn"


def add_aircraft_arg(p: argparse.ArgumentParser, what: str = "the glider") -> None:
    """``--aircraft NAME|DIR`` (default None: the package's glider)."""
    from ..definitions.catalog import AIRCRAFT, DEFAULT_AIRCRAFT

    p.add_argument("--aircraft", default=None, metavar="NAME|DIR",
                   help=f"{what}: an aircraft of the package ({', '.join(AIRCRAFT)}; default {DEFAULT_AIRCRAFT}) or a "
                        "definition folder with the package's layout (aircraft/P_foldable, P_unfolded, P_folded, "
                        "engine/; 'fdm-awe info --export DIR' writes a copy to start from), checked before any work")


def aircraft_from_args(args: argparse.Namespace) -> Any:
    """The :class:`~fdm_awe.definitions.catalog.Aircraft` of ``--aircraft`` (resolved and
    checked once; one-line errors naming the option), kept in ``args.aircraft_def``."""
    from ..definitions.catalog import resolve_aircraft

    a = getattr(args, "aircraft_def", None)
    if a is None:
        a = args.aircraft_def = resolve_aircraft(getattr(args, "aircraft", None), "--aircraft")
    return a


def check_reference_aircraft(meta: dict[str, Any], aircraft: Any, source: object) -> bool:
    """Warn (one line on stderr) when the reference ``source`` (metadata ``meta``) was optimised
    for an aircraft other than ``aircraft`` (its recorded content hash differs; a reference that
    records none was optimised for the package's glider before references recorded it). The
    flight goes ahead: flying a reference with a changed glider is a legitimate study, but the
    trajectory is not that glider's optimum. Returns whether the aircraft differ."""
    rec = meta.get("aircraft")
    had = (rec.get("name") or rec.get("directory")) if isinstance(rec, dict) else None
    return warn_other_definition(source, rec, had, aircraft, "for the aircraft", "aircraft",
                                 "the package's glider", "this aircraft's optimum")


def warn_other_definition(source: object, rec: Any, had: object, mine: Any, made: str, kind: str, package: str,
                          optimum: str) -> bool:
    """The one-line warning (stderr) of a reference ``source`` made with another definition:
    ``rec`` its metadata record (a dict with ``sha256``, else none recorded) naming ``had``;
    ``mine`` the definition flying it (``sha256``, ``label()``, ``builtin``); ``made`` how the
    reference was made (e.g. "for the aircraft"), ``kind`` the definition's word, ``package``
    the package's own definition, ``optimum`` what the trajectory is not. Whether they differ."""
    if isinstance(rec, dict):
        if rec.get("sha256") == mine.sha256:
            return False
        print(f"warning: {source} was optimised {made} {had} (sha256 {str(rec.get('sha256'))[:12]}); flying "
              f"{mine.label()} (sha256 {mine.sha256[:12]}): the reference is not {optimum}", file=sys.stderr)
        return True
    if mine.builtin:
        return False
    print(f"warning: {source} records no {kind} (written before references recorded it: {package}); flying "
          f"{mine.label()}: the reference is not {optimum}", file=sys.stderr)
    return True
    if aircraft.builtin:
        return False
    print(f"warning: {source} records no aircraft (written before references recorded it: the package's glider); "
          f"flying {aircraft.label()}: the reference is not this aircraft's optimum", file=sys.stderr)
    return True
