"""fdm-awe: ground-generation airborne wind energy with a foldable-wing glider.

Units are SI throughout the Python side; the ground frame is NED with its origin at
the winch. JSBSim's English units are converted only in :mod:`fdm_awe.units` (used by
the JSBSim adapter).
"""

from importlib import resources
from pathlib import Path

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

__all__ = ["DEFINITION_FOLDERS", "ROOT", "__version__"]
