"""Frame transformations of the point-mass model (paper section II-A, corrected).

Ground frame N is NED with its origin at the winch. The air-path frame C is reached from N
by the 3-2-1 rotation (heading psi, flight-path angle gamma, bank phi) of the air velocity:
``C_CN = C1(phi) C2(gamma) C3(psi)``. Lift acts along -c3, drag along -c1, thrust along +c1.
The paper's eq. 1 prints entry (1,3) as ``-sin(gamma) cos(psi)``; the product of the three
rotations gives ``-sin(gamma)`` (as eq. 7 has it), which is what this module uses.

All functions work on floats, NumPy arrays and CasADi symbols (see :mod:`fdm_awe.pointmass.mathops`).
"""

from __future__ import annotations

from typing import Any, Sequence

from . import mathops as mo


def c_cn(gamma: Any, psi: Any, phi: Any) -> list[list[Any]]:
    """Rotation matrix from N (NED) to C (air-path, banked) components, as nested lists."""
    cg, sg = mo.cos(gamma), mo.sin(gamma)
    cp, sp = mo.cos(psi), mo.sin(psi)
    cf, sf = mo.cos(phi), mo.sin(phi)
    return [
        [cg * cp, cg * sp, -sg],
        [-cf * sp + sf * sg * cp, cf * cp + sf * sg * sp, sf * cg],
        [sf * sp + cf * sg * cp, -sf * cp + cf * sg * sp, cf * cg],
    ]


def n_to_c(vec_n: Sequence[Any], gamma: Any, psi: Any, phi: Any) -> list[Any]:
    """Components in C of a vector given in N."""
    R = c_cn(gamma, psi, phi)
    return [R[i][0] * vec_n[0] + R[i][1] * vec_n[1] + R[i][2] * vec_n[2] for i in range(3)]


def c_to_n(vec_c: Sequence[Any], gamma: Any, psi: Any, phi: Any) -> list[Any]:
    """Components in N of a vector given in C (transpose of :func:`c_cn`)."""
    R = c_cn(gamma, psi, phi)
    return [R[0][j] * vec_c[0] + R[1][j] * vec_c[1] + R[2][j] * vec_c[2] for j in range(3)]


def tether_direction_ned(x: Any, y: Any, z: Any) -> list[Any]:
    """Unit vector from the glider towards the winch, ``-P/|P|`` (corrected eqs. 8/31)."""
    d = mo.sqrt(x * x + y * y + z * z)
    return [-x / d, -y / d, -z / d]
