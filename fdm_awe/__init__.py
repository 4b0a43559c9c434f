"""fdm-awe: ground-generation airborne wind energy with a foldable-wing glider.

Units are SI throughout the Python side; the ground frame is NED with its origin at
the winch. JSBSim's English units are converted only in :mod:`fdm_awe.units` (used by
the JSBSim adapter).
"""

from pathlib import Path

__version__ = "0.1.0"

#: Repository root holding ``aircraft/``, ``engine/`` and ``tether/`` definition folders.
ROOT = Path(__file__).resolve().parent.parent

__all__ = ["ROOT", "__version__"]
