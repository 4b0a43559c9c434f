"""6-DOF flight of the glider in JSBSim: adapter (units, property nodes, tether hook, fold),
state/command data, and a simple stabilising controller.

``JSBSimGlider`` loads ``aircraft/NAME`` from the repository; see :mod:`.adapter`.
"""

from ..turbulence import TURBULENCE_LEVELS
from .adapter import JSBSimGlider
from .stabilizer import Stabilizer
from .attitude_law import StabilizerGains
from .state import SixDofState, Surfaces, dcm_body_to_ned, euler_to_quat

__all__ = ["JSBSimGlider", "SixDofState", "Stabilizer", "StabilizerGains", "Surfaces", "TURBULENCE_LEVELS",
           "dcm_body_to_ned", "euler_to_quat"]
