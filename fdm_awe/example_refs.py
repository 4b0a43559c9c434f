"""Example references: stored, flyable reference trajectories reachable by name.

``--reference example:nominal-8`` (``fdm-awe fly``) and ``fdm_awe.load_reference("example:nominal-8")``
name one of :data:`EXAMPLES`. The files are the stored references of ``tests/data/`` (physical
scenario, sized line, flyable bounds; the paper scenario's Table-3 references); a source checkout
reads them there, an installed wheel carries them as package data in ``fdm_awe/data/examples/``
(setup.py reads :data:`EXAMPLES` to ship exactly these files).

Plain module: importing it imports nothing heavy.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from .errors import InputError

#: Prefix that names an example instead of a file.
PREFIX = "example:"

#: name -> file (below the examples folder). ``<config>-<wind m/s>``: the physical scenario on the
#: sized line; ``paper-<config>-3``: the paper scenario at Table 3's 3 m/s (the nominal one with
#: the flight-path bound 0.7 rad that makes it flyable).
EXAMPLES = {
    "nominal-8": "ref_physical_nominal_8mps_sized.json",
    "foldable-8": "ref_physical_foldable_8mps_sized.json",
    "nominal-10": "ref_physical_nominal_10mps_sized.json",
    "foldable-10": "ref_physical_foldable_10mps_sized.json",
    "nominal-12": "ref_physical_nominal_12mps_sized.json",
    "foldable-12": "ref_physical_foldable_12mps_sized.json",
    "paper-nominal-3": "ref_paper_nominal_3mps_gamma07.json",
    "paper-foldable-3": "ref_paper_foldable_3mps.json",
}


def examples_folder() -> Path:
    """Folder of the example files: the installed package's ``fdm_awe/data/examples/`` or, in a
    source checkout, the repository's ``tests/data/``."""
    packaged = Path(str(resources.files(__package__ or "fdm_awe").joinpath("data", "examples")))
    if packaged.is_dir():
        return packaged
    return Path(__file__).resolve().parent.parent / "tests" / "data"


def is_example(text: object) -> bool:
    """Whether ``text`` names an example (``example:NAME``)."""
    return isinstance(text, str) and text.startswith(PREFIX)


def example_path(text: str, option: str = "reference") -> Path:
    """The file of ``example:NAME`` (or of a bare ``NAME``); an unknown name is an
    :class:`~fdm_awe.errors.InputError` naming ``option`` and the allowed names."""
    name = text[len(PREFIX):] if is_example(text) else text
    if name not in EXAMPLES:
        raise InputError(f"{option} {text}: no such example (allowed {PREFIX}NAME, NAME one of "
                         f"{', '.join(EXAMPLES)})")
    path = examples_folder() / EXAMPLES[name]
    if not path.is_file():
        raise InputError(f"{option} {text}: the example's file {EXAMPLES[name]} is missing from this installation")
    return path


def resolve(text: str | None, option: str = "--reference") -> str | None:
    """``text`` with an ``example:NAME`` replaced by its file's path (anything else unchanged)."""
    return str(example_path(text, option)) if is_example(text) else text


__all__ = ["EXAMPLES", "PREFIX", "example_path", "examples_folder", "is_example", "resolve"]
