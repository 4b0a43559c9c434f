"""The autopilot's parameters: named numbers with ranges, change callbacks and a persistence file.

A :class:`ParamStore` holds the tunable numbers of the autopilot (gains, PI speed-loop gains,
fold timing); a ground station reads and sets them over MAVLink (:mod:`fdm_awe.mavlink.params`
turns the wire's float32 values into these numbers and back). Each parameter has

- an id of 1..16 characters ``[A-Z0-9_]`` (the MAVLink ``param_id`` limit; upper case by
  convention, as ground stations expect),
- a kind: ``"float"``, ``"int"`` (whole numbers) or ``"bool"`` (0 or 1),
- an inclusive range ``lo..hi`` and a unit/description for humans,
- optional callbacks ``fn(name, value)`` run after every accepted change, so a change
  made in flight takes effect at once.

With a ``path`` the store saves every accepted change to a JSON file (atomically:
write a temporary file, then rename) and a new store on the same file starts from the
saved values: when a parameter is declared with :meth:`ParamStore.add` and the file
holds a value for it, the saved value wins over the default (after range checking). The
file is ``{"format": "fdm-awe-params-1", "params": {id: value}}``; another format tag is
refused, and once every parameter is declared :meth:`ParamStore.check_saved` refuses an id
that none of them has (a typo would otherwise be ignored silently).
"""

from __future__ import annotations

import difflib
import json
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

from fdm_awe.errors import DefinitionError, InputError
from fdm_awe.fileio import atomic_write_text

ParamCallback = Callable[[str, float], None]

_ID_RE = re.compile(r"^[A-Z0-9_]{1,16}$")
KINDS = ("float", "int", "bool")
#: the ``format`` tag of a parameter file
FILE_FORMAT = "fdm-awe-params-1"


@dataclass
class Param:
    """One parameter: id, kind, value, inclusive range, default and description."""

    name: str
    kind: str
    value: float
    lo: float
    hi: float
    default: float
    doc: str = ""
    callbacks: list[ParamCallback] = field(default_factory=list)


class ParamStore:
    """Ordered collection of named numeric parameters (see module doc).

    Args:
        path: JSON file for persistence, or None to keep values in memory only.
    """

    def __init__(self, path: str | os.PathLike | None = None) -> None:
        self._params: dict[str, Param] = {}
        self._order: list[str] = []
        self.path = Path(path) if path is not None else None
        self._saved: dict[str, float] = self._read_file() if self.path else {}

    # -- declaration -------------------------------------------------------------
    def add(self, name: str, default: float, lo: float, hi: float, kind: str = "float",
            doc: str = "", on_change: ParamCallback | None = None) -> Param:
        """Declare a parameter; the saved value (if any) replaces the default.

        Raises InputError for a bad id, kind, range or default, or a duplicate id, and
        DefinitionError naming the file when its saved value is out of range.
        """
        if not isinstance(name, str) or not _ID_RE.match(name):
            raise InputError(
                f"parameter id {name!r}: must be 1..16 characters of A-Z, 0-9, _")
        if name in self._params:
            raise InputError(f"parameter id {name!r}: declared twice")
        if kind not in KINDS:
            raise InputError(f"parameter {name} kind {kind!r}: allowed {', '.join(KINDS)}")
        lo, hi = float(lo), float(hi)
        if kind == "bool":
            lo, hi = 0.0, 1.0
        if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
            raise InputError(f"parameter {name} range [{lo}, {hi}]: needs finite lo <= hi")
        p = Param(name, kind, 0.0, lo, hi, 0.0, doc)
        ok, why = self._check(p, default)
        if not ok:
            raise InputError(f"parameter {name} default: {why}")
        p.default = p.value = float(default)
        if name in self._saved:
            ok, why = self._check(p, self._saved[name])
            if not ok:
                raise DefinitionError(self.path, f"parameter {name}", why)
            p.value = float(self._saved[name])
        if on_change is not None:
            p.callbacks.append(on_change)
        self._params[name] = p
        self._order.append(name)
        return p

    def check_saved(self) -> None:
        """DefinitionError naming the file for a saved id that no declared parameter has (call
        it once every parameter is declared)."""
        unknown = [k for k in self._saved if k not in self._params]
        if unknown:
            close = difflib.get_close_matches(unknown[0], self._order, n=1)
            hint = f"did you mean {close[0]}?" if close else f"e.g. {', '.join(self._order[:3])}"
            raise DefinitionError(self.path, f"parameter {unknown[0]}",
                                  f"unknown id ({len(unknown)} unknown in the file; the ids are the "
                                  f"autopilot's, {hint})")

    def on_change(self, name: str, fn: ParamCallback) -> None:
        """Call ``fn(name, value)`` after every accepted change of ``name``."""
        self._param(name).callbacks.append(fn)

    # -- access ------------------------------------------------------------------
    def __contains__(self, name: object) -> bool:
        return name in self._params

    def __len__(self) -> int:
        return len(self._order)

    def __iter__(self) -> Iterator[str]:
        return iter(self._order)

    def __getitem__(self, name: str) -> float:
        return self._param(name).value

    def get(self, name: str, default: float | None = None) -> float | None:
        p = self._params.get(name)
        return default if p is None else p.value

    def info(self, name: str) -> Param:
        """The full record of a parameter (read it, do not modify it)."""
        return self._param(name)

    def names(self) -> list[str]:
        """Parameter ids in declaration order (this order gives the MAVLink index)."""
        return list(self._order)

    def index(self, name: str) -> int:
        """MAVLink ``param_index`` of a parameter."""
        return self._order.index(name)

    def name_at(self, index: int) -> str | None:
        """Parameter id at a MAVLink index, or None if out of range."""
        if 0 <= index < len(self._order):
            return self._order[index]
        return None

    def as_dict(self) -> dict[str, float]:
        return {n: self._params[n].value for n in self._order}

    # -- change ------------------------------------------------------------------
    def try_set(self, name: str, value: float) -> tuple[bool, str]:
        """Set a value if valid; returns (accepted, reason). Callbacks run, file is saved.

        A callback that raises is reported in the reason but the value stays set.
        """
        p = self._params.get(name)
        if p is None:
            return False, f"unknown parameter {name!r}"
        ok, why = self._check(p, value)
        if not ok:
            return False, f"{name}: {why}"
        value = float(value)
        changed = value != p.value
        p.value = value
        reason = "ok"
        if changed:
            if self.path is not None:
                try:
                    self.save()
                except OSError as e:
                    reason = f"{name} set but not saved: {e}"
            for fn in list(p.callbacks):
                try:
                    fn(name, value)
                except Exception as e:  # noqa: BLE001 - a callback must not break the link
                    reason = f"{name} set, callback failed: {type(e).__name__}: {e}"
        return True, reason

    def set(self, name: str, value: float) -> None:
        """Like :meth:`try_set` but raises InputError when the value is refused."""
        ok, why = self.try_set(name, value)
        if not ok:
            raise InputError(why)

    @staticmethod
    def _check(p: Param, value: object) -> tuple[bool, str]:
        if isinstance(value, bool):
            value = float(value)
        if not isinstance(value, (int, float)):
            return False, f"{value!r} is not a number"
        v = float(value)
        if not math.isfinite(v):
            return False, f"{v} is not finite"
        if not (p.lo <= v <= p.hi):
            return False, f"{v:g} outside [{p.lo:g}, {p.hi:g}]"
        if p.kind in ("int", "bool") and v != int(v):
            return False, f"{v:g} is not a whole number ({p.kind})"
        return True, "ok"

    def _param(self, name: str) -> Param:
        try:
            return self._params[name]
        except KeyError:
            raise InputError(f"parameter {name!r}: unknown") from None

    # -- persistence -------------------------------------------------------------
    def save(self) -> None:
        """Write all values (and any saved values of undeclared ids) to ``path``."""
        if self.path is None:
            return
        data = dict(self._saved)
        data.update(self.as_dict())
        self._saved = data
        self.path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(self.path, json.dumps({"format": FILE_FORMAT, "params": data}, indent=1,
                                                sort_keys=True) + "\n")

    def _read_file(self) -> dict[str, float]:
        assert self.path is not None
        if not self.path.exists():
            return {}
        try:
            doc = json.loads(self.path.read_text())
        except (OSError, ValueError) as e:
            raise DefinitionError(self.path, "params", f"unreadable JSON: {e}") from None
        fmt = doc.get("format") if isinstance(doc, dict) else None
        if isinstance(doc, dict) and fmt != FILE_FORMAT:
            raise DefinitionError(self.path, "format", f"{fmt!r}; a parameter file has \"format\": \"{FILE_FORMAT}\"")
        params = doc.get("params") if isinstance(doc, dict) else None
        if not isinstance(params, dict):
            raise DefinitionError(self.path, "params", "expected an object {\"params\": {id: value}}")
        out: dict[str, float] = {}
        for k, v in params.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise DefinitionError(self.path, f"parameter {k}", f"{v!r} is not a finite number")
            out[str(k)] = float(v)
        return out
