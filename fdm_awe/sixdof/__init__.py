"""6-DOF flight of the glider in JSBSim: adapter (units, property nodes, tether hook, fold),
state/command data, and a simple stabilising controller.

``JSBSimGlider`` loads ``aircraft/NAME`` from the repository; see :mod:`.adapter`.
"""

from .adapter import TURBULENCE_LEVELS, JSBSimGlider
from .stabilizer import Stabilizer, StabilizerGains
from .state import SixDofState, Surfaces, dcm_body_to_ned, euler_to_quat

__all__ = ["JSBSimGlider", "SixDofState", "Stabilizer", "StabilizerGains", "Surfaces", "TURBULENCE_LEVELS",
           "dcm_body_to_ned", "euler_to_quat"]
