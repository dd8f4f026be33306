"""Eqs. 1-3 and 9-12: wheel speeds and the drive equations integrated."""

from __future__ import annotations

import numpy as np
import pytest

from rrtpso_ompl.kinematics import integrate_wheels, wheel_speeds
from rrtpso_ompl.kinematics.diffdrive import step_wheels


def test_eqs_9_to_12():
    v_r, v_l, w_r, w_l = wheel_speeds(np.array([10.0]), np.array([0.5]), 0.38, 0.076)
    assert v_r[0] == pytest.approx((2 * 10 + 0.38 * 0.5) / 2)
    assert v_l[0] == pytest.approx((2 * 10 - 0.38 * 0.5) / 2)
    assert w_r[0] == pytest.approx(v_r[0] / 0.076) and w_l[0] == pytest.approx(v_l[0] / 0.076)


def test_open_loop_model_follows_a_straight_command():
    poses = integrate_wheels((0.0, 0.0, 0.0), np.full(11, 10.0), np.full(11, 10.0), 38.0, 0.1)
    assert np.allclose(poses[-1], [10.0, 0.0, 0.0])
    spin = integrate_wheels((0.0, 0.0, 0.0), np.full(11, 19.0), np.full(11, -19.0), 38.0, 0.1)
    assert np.allclose(spin[-1], [0.0, 0.0, 1.0])  # (V_R - V_L) / L * Ts per step, eq. 3


def test_one_closed_loop_step_is_one_step_of_the_drive_equations():
    pose = (1.0, 2.0, 0.3)
    poses = integrate_wheels(pose, [12.0, 12.0], [9.0, 9.0], 38.0, 0.15)
    assert step_wheels(pose, 12.0, 9.0, 38.0, 0.15) == pytest.approx(tuple(poses[1]), abs=1e-12)
