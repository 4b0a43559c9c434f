"""fdm-awe: ground-generation airborne wind energy with a foldable-wing glider.

Units are SI throughout the Python side; the ground frame is NED with its origin at
the winch. JSBSim's English units are converted only in :mod:`fdm_awe.units` (used by
the JSBSim adapter).

The Python API (:mod:`fdm_awe.api`) is the package's top level: :func:`optimize`, :func:`fly`,
:func:`sweep` and :func:`load_reference`, with the defaults of :mod:`fdm_awe.defaults`, and
their results (:mod:`fdm_awe.api_results`). They are imported on first use, so ``import fdm_awe``
stays as fast as the command line's start.
``fdm_awe.sweep`` is also the sub-package of the sweep's modules; calling it runs the API's
:func:`fdm_awe.api.sweep`.
"""

import importlib
import types
from importlib import resources
from pathlib import Path
from typing import Any

__version__ = "0.1.0"

#: Definition folders below :data:`ROOT` (docs/design.md section 2).
DEFINITION_FOLDERS = ("aircraft", "engine", "tether")


def _definition_root() -> Path:
    """Folder holding the ``aircraft/``, ``engine/`` and ``tether/`` definition folders.

    An installed wheel carries them as package data in ``fdm_awe/data/`` (setup.py maps the
    repository's top-level folders there); a source checkout, editable install included, has
    no such copy and uses the repository's top-level folders next to the package.
    """
    packaged = Path(str(resources.files(__name__).joinpath("data")))
    if all((packaged / folder).is_dir() for folder in DEFINITION_FOLDERS):
        return packaged
    return Path(__file__).resolve().parent.parent


#: JSBSim root holding the ``aircraft/``, ``engine/`` and ``tether/`` definition folders: the
#: installed package's ``fdm_awe/data/`` or, in a source checkout, the repository root.
ROOT = _definition_root()

#: names of the Python API on the package's top level -> the module that defines them (imported on
#: first use)
_API = {"FlightResult": ".api_results", "OptimizeResult": ".api_results", "SweepResult": ".api_results",
        "fly": ".api", "load_reference": ".api", "optimize": ".api"}


def __getattr__(name: str) -> Any:
    # looked up by name on first use: the package's own __init__ imports no unit of it (the
    # layers of docs/architecture.md), and ``import fdm_awe`` stays light
    if name in _API:
        return getattr(importlib.import_module(_API[name], __name__), name)
    if name == "sweep":  # the sub-package, callable (its __init__ makes itself a CallableModule)
        return importlib.import_module(".sweep", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class CallableModule(types.ModuleType):
    """The ``fdm_awe.sweep`` sub-package, callable as the API's :func:`fdm_awe.api.sweep`
    (``fdm_awe/sweep/__init__.py`` gives itself this class when it is imported, whatever imports
    it first)."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return importlib.import_module(".api", __package__ or "fdm_awe").sweep(*args, **kwargs)


__all__ = ["DEFINITION_FOLDERS", "ROOT", "__version__", *_API, "sweep"]
