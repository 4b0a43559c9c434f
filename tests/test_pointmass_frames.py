"""Frame matrices against the paper's eq. 7 and basic rotation algebra."""

import numpy as np
import pytest

from fdm_awe.pointmass.frames import c_cn, c_to_n, n_to_c, tether_direction_ned


def C1(a):
    return np.array([[1, 0, 0], [0, np.cos(a), np.sin(a)], [0, -np.sin(a), np.cos(a)]])


def C2(a):
    return np.array([[np.cos(a), 0, -np.sin(a)], [0, 1, 0], [np.sin(a), 0, np.cos(a)]])


def C3(a):
    return np.array([[np.cos(a), np.sin(a), 0], [-np.sin(a), np.cos(a), 0], [0, 0, 1]])


def eq7(gamma, psi, phi):
    """The matrix printed in the paper's eq. 7 (entry (1,3) = -sin gamma)."""
    cg, sg, cp, sp, cf, sf = np.cos(gamma), np.sin(gamma), np.cos(psi), np.sin(psi), np.cos(phi), np.sin(phi)
    return np.array([
        [cg * cp, cg * sp, -sg],
        [-cf * sp + sf * sg * cp, cf * cp + sf * sg * sp, sf * cg],
        [sf * sp + cf * sg * cp, -sf * cp + cf * sg * sp, cf * cg],
    ])


ANGLES = np.random.default_rng(1).uniform([-1.5, -np.pi, -1.2], [1.5, np.pi, 1.2], size=(25, 3))


@pytest.mark.parametrize("gamma,psi,phi", ANGLES)
def test_c_cn_orthonormal_and_equals_eq7_and_product(gamma, psi, phi):
    R = np.array(c_cn(gamma, psi, phi), dtype=float)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(R, eq7(gamma, psi, phi), atol=1e-15)
    np.testing.assert_allclose(R, C1(phi) @ C2(gamma) @ C3(psi), atol=1e-14)


def test_eq1_entry_13_is_a_typo():
    """The paper's eq. 1 prints (1,3) = -sin(gamma) cos(psi); the product gives -sin(gamma)."""
    gamma, psi, phi = 0.3, 1.0, 0.2
    R = np.array(c_cn(gamma, psi, phi), dtype=float)
    assert R[0, 2] == pytest.approx(-np.sin(gamma), abs=1e-15)
    assert abs(R[0, 2] - (-np.sin(gamma) * np.cos(psi))) > 0.1


def test_round_trip_and_axes():
    v = [1.0, -2.0, 0.5]
    np.testing.assert_allclose(c_to_n(n_to_c(v, 0.2, -0.7, 0.4), 0.2, -0.7, 0.4), v, atol=1e-14)
    # level flight heading east: c1 = east
    np.testing.assert_allclose(c_to_n([1, 0, 0], 0.0, np.pi / 2, 0.0), [0, 1, 0], atol=1e-15)
    # climbing: c1 has a negative down component
    assert c_to_n([1, 0, 0], 0.1, 0.0, 0.0)[2] < 0
    # unbanked: c3 is straight down when level
    np.testing.assert_allclose(c_to_n([0, 0, 1], 0.0, 0.3, 0.0), [0, 0, 1], atol=1e-15)
    # positive bank tilts the lift (-c3) to the right wing (c2 side): heading north, right = east
    lift_dir = -np.array(c_to_n([0, 0, 1], 0.0, 0.0, 0.3))
    assert lift_dir[1] > 0 and lift_dir[2] < 0


def test_tether_direction_points_to_winch():
    e = tether_direction_ned(100.0, 0.0, -100.0)
    np.testing.assert_allclose(e, [-np.sqrt(0.5), 0, np.sqrt(0.5)], atol=1e-15)
