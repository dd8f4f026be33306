"""Shortest car paths in numpy: the lengths of OMPL's Dubins and Reeds-Shepp paths for whole
batches of pose pairs, word for word as ``DubinsStateSpace.cpp`` and
``ReedsSheppStateSpace.cpp`` (OMPL 2.0.1) compute them, so that they equal ``space.distance``
(tests/ompl_setup/test_spaces.py: to 1e-9 on thousands of random pairs).

Poses are rows ``(x, y, yaw)``: units, units, rad; lengths are in turning radii (multiply by the
radius for the space's distance).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["dubins_lengths", "reeds_shepp_lengths"]

_TWO_PI = 2.0 * math.pi
_PI = math.pi

# -- Dubins in numpy -------------------------------------------------------------------------------
_DUBINS_EPS = 1e-6
_DUBINS_ZERO = -1e-7


def _mod2pi(x: np.ndarray) -> np.ndarray:
    """OMPL's ``mod2pi`` of DubinsStateSpace.cpp (tiny negatives and near-2pi values to 0)."""
    xm = x - _TWO_PI * np.floor(x / _TWO_PI)
    xm = np.where(_TWO_PI - xm < 0.5 * _DUBINS_EPS, 0.0, xm)
    return np.where((x < 0) & (x > _DUBINS_ZERO), 0.0, xm)


def _dubins_words(d: np.ndarray, alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Lengths (in turning radii) of OMPL's six Dubins words, ``inf`` where a word does not
    exist; shape ``(6, ...)`` in OMPL's order LSL, RSR, RSL, LSR, RLR, LRL."""
    ca, sa, cb, sb = np.cos(alpha), np.sin(alpha), np.cos(beta), np.sin(beta)
    inf = np.inf
    out = []
    with np.errstate(invalid="ignore"):
        # LSL
        tmp = 2.0 + d * d - 2.0 * (ca * cb + sa * sb - d * (sa - sb))
        theta = np.arctan2(cb - ca, d + sa - sb)
        p = np.sqrt(np.maximum(tmp, 0.0))
        length = _mod2pi(-alpha + theta) + p + _mod2pi(beta - theta)
        out.append(np.where(tmp >= _DUBINS_ZERO, length, inf))
        # RSR
        tmp = 2.0 + d * d - 2.0 * (ca * cb + sa * sb - d * (sb - sa))
        theta = np.arctan2(ca - cb, d - sa + sb)
        p = np.sqrt(np.maximum(tmp, 0.0))
        length = _mod2pi(alpha - theta) + p + _mod2pi(-beta + theta)
        out.append(np.where(tmp >= _DUBINS_ZERO, length, inf))
        # RSL
        tmp = d * d - 2.0 + 2.0 * (ca * cb + sa * sb - d * (sa + sb))
        p = np.sqrt(np.maximum(tmp, 0.0))
        theta = np.arctan2(ca + cb, d - sa - sb) - np.arctan2(2.0, p)
        length = _mod2pi(alpha - theta) + p + _mod2pi(beta - theta)
        out.append(np.where(tmp >= _DUBINS_ZERO, length, inf))
        # LSR
        tmp = -2.0 + d * d + 2.0 * (ca * cb + sa * sb + d * (sa + sb))
        p = np.sqrt(np.maximum(tmp, 0.0))
        theta = np.arctan2(-ca - cb, d + sa + sb) - np.arctan2(-2.0, p)
        length = _mod2pi(-alpha + theta) + p + _mod2pi(-beta + theta)
        out.append(np.where(tmp >= _DUBINS_ZERO, length, inf))
        # RLR
        tmp = 0.125 * (6.0 - d * d + 2.0 * (ca * cb + sa * sb + d * (sa - sb)))
        p = _TWO_PI - np.arccos(np.clip(tmp, -1.0, 1.0))
        theta = np.arctan2(ca - cb, d - sa + sb)
        t = _mod2pi(alpha - theta + 0.5 * p)
        length = t + p + _mod2pi(alpha - beta - t + p)
        out.append(np.where(np.abs(tmp) < 1.0, length, inf))
        # LRL
        tmp = 0.125 * (6.0 - d * d + 2.0 * (ca * cb + sa * sb - d * (sa - sb)))
        p = _TWO_PI - np.arccos(np.clip(tmp, -1.0, 1.0))
        theta = np.arctan2(-ca + cb, d + sa - sb)
        t = _mod2pi(-alpha + theta + 0.5 * p)
        length = t + p + _mod2pi(beta - alpha - t + p)
        out.append(np.where(np.abs(tmp) < 1.0, length, inf))
    return np.stack(out)


def dubins_lengths(a: np.ndarray, b: np.ndarray, rho: float) -> np.ndarray:
    """Length of the shortest forward Dubins path from each pose of ``a`` to the matching one of
    ``b``, in turning radii (OMPL's ``getPath(a, b).length()``).

    Parameters
    ----------
    a, b : ndarray, shape (..., 3)
        Poses ``(x, y, yaw)``: units, units, rad.
    rho : float
        Turning radius, units.

    Returns
    -------
    ndarray, shape (...)
        The shortest of the six words (LSL, RSR, RSL, LSR, RLR, LRL), as OMPL computes them.
        OMPL picks the word of a long path by Shkel and Lumelsky's classification rather than
        by trying all six; both give the shortest word (they agree to 1e-9 on random pairs,
        tests/ompl_setup/test_spaces.py).
    """
    dx = b[..., 0] - a[..., 0]
    dy = b[..., 1] - a[..., 1]
    d = np.sqrt(dx * dx + dy * dy) / rho
    th = np.arctan2(dy, dx)
    alpha = _mod2pi(a[..., 2] - th)
    beta = _mod2pi(b[..., 2] - th)
    # OMPL's degenerate case: the same pose, to 1e-6 (a straight "path" of length d).
    same = (d < _DUBINS_EPS) & (np.abs(alpha - beta) < _DUBINS_EPS)
    best = _dubins_words(d, alpha, beta).min(axis=0)
    return np.where(same, d, best)


# -- Reeds-Shepp in numpy --------------------------------------------------------------------------
#: OMPL's tolerance on the signs of a word's segments.
_RS_ZERO = 10 * np.finfo(float).eps


def _rs_mod2pi(x: np.ndarray) -> np.ndarray:
    """OMPL's ``mod2pi`` of ReedsSheppStateSpace.cpp: into ``[-pi, pi]`` by ``fmod``."""
    v = np.fmod(x, _TWO_PI)
    v = np.where(v < -_PI, v + _TWO_PI, v)
    return np.where(v > _PI, v - _TWO_PI, v)


def _polar(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.sqrt(x * x + y * y), np.arctan2(y, x)


def _tau_omega(u, v, xi, eta, phi):
    delta = _rs_mod2pi(u - v)
    a = np.sin(u) - np.sin(delta)
    b = np.cos(u) - np.cos(delta) - 1.0
    t1 = np.arctan2(eta * a - xi * b, xi * a + eta * b)
    t2 = 2.0 * (np.cos(delta) - np.cos(v) - np.cos(u)) + 3.0
    tau = np.where(t2 < 0, _rs_mod2pi(t1 + _PI), _rs_mod2pi(t1))
    return tau, _rs_mod2pi(tau - u + v - phi)


# Each word returns the length |t| + |u| + |v| where it exists (formula 8.x of Reeds and Shepp,
# as OMPL writes it), inf elsewhere.
def _lp_sp_lp(x, y, phi):  # 8.1
    u, t = _polar(x - np.sin(phi), y - 1.0 + np.cos(phi))
    v = _rs_mod2pi(phi - t)
    ok = (t >= -_RS_ZERO) & (v >= -_RS_ZERO)
    return np.where(ok, np.abs(t) + np.abs(u) + np.abs(v), np.inf)


def _lp_sp_rp(x, y, phi):  # 8.2
    u1, t1 = _polar(x + np.sin(phi), y - 1.0 - np.cos(phi))
    u1 = u1 * u1
    u = np.sqrt(np.maximum(u1 - 4.0, 0.0))
    t = _rs_mod2pi(t1 + np.arctan2(2.0, u))
    v = _rs_mod2pi(t - phi)
    ok = (u1 >= 4.0) & (t >= -_RS_ZERO) & (v >= -_RS_ZERO)
    return np.where(ok, np.abs(t) + np.abs(u) + np.abs(v), np.inf)


def _lp_rm_l(x, y, phi):  # 8.3 / 8.4
    u1, theta = _polar(x - np.sin(phi), y - 1.0 + np.cos(phi))
    u = -2.0 * np.arcsin(np.minimum(0.25 * u1, 1.0))
    t = _rs_mod2pi(theta + 0.5 * u + _PI)
    v = _rs_mod2pi(phi - t + u)
    ok = (u1 <= 4.0) & (t >= -_RS_ZERO) & (u <= _RS_ZERO)
    return np.where(ok, np.abs(t) + np.abs(u) + np.abs(v), np.inf)


def _lp_rup_lum_rm(x, y, phi):  # 8.7
    xi, eta = x + np.sin(phi), y - 1.0 - np.cos(phi)
    rho = 0.25 * (2.0 + np.sqrt(xi * xi + eta * eta))
    u = np.arccos(np.minimum(rho, 1.0))
    t, v = _tau_omega(u, -u, xi, eta, phi)
    ok = (rho <= 1.0) & (t >= -_RS_ZERO) & (v <= _RS_ZERO)
    return np.where(ok, np.abs(t) + 2.0 * np.abs(u) + np.abs(v), np.inf)


def _lp_rum_lum_rp(x, y, phi):  # 8.8
    xi, eta = x + np.sin(phi), y - 1.0 - np.cos(phi)
    rho = (20.0 - xi * xi - eta * eta) / 16.0
    u = -np.arccos(np.clip(rho, -1.0, 1.0))
    t, v = _tau_omega(u, u, xi, eta, phi)
    ok = (rho >= 0) & (rho <= 1) & (u >= -0.5 * _PI) & (t >= -_RS_ZERO) & (v >= -_RS_ZERO)
    return np.where(ok, np.abs(t) + 2.0 * np.abs(u) + np.abs(v), np.inf)


def _lp_rm_sm_lm(x, y, phi):  # 8.9
    rho, theta = _polar(x - np.sin(phi), y - 1.0 + np.cos(phi))
    r = np.sqrt(np.maximum(rho * rho - 4.0, 0.0))
    u = 2.0 - r
    t = _rs_mod2pi(theta + np.arctan2(r, -2.0))
    v = _rs_mod2pi(phi - 0.5 * _PI - t)
    ok = (rho >= 2.0) & (t >= -_RS_ZERO) & (u <= _RS_ZERO) & (v <= _RS_ZERO)
    return np.where(ok, np.abs(t) + np.abs(u) + np.abs(v) + 0.5 * _PI, np.inf)


def _lp_rm_sm_rm(x, y, phi):  # 8.10
    xi, eta = x + np.sin(phi), y - 1.0 - np.cos(phi)
    rho, t = _polar(-eta, xi)
    u = 2.0 - rho
    v = _rs_mod2pi(t + 0.5 * _PI - phi)
    ok = (rho >= 2.0) & (t >= -_RS_ZERO) & (u <= _RS_ZERO) & (v <= _RS_ZERO)
    return np.where(ok, np.abs(t) + np.abs(u) + np.abs(v) + 0.5 * _PI, np.inf)


def _lp_rm_s_lm_rp(x, y, phi):  # 8.11
    xi, eta = x + np.sin(phi), y - 1.0 - np.cos(phi)
    rho, _theta = _polar(xi, eta)
    u = 4.0 - np.sqrt(np.maximum(rho * rho - 4.0, 0.0))
    t = _rs_mod2pi(np.arctan2((4.0 - u) * xi - 2.0 * eta, -2.0 * xi + (u - 4.0) * eta))
    v = _rs_mod2pi(t - phi)
    ok = (rho >= 2.0) & (u <= _RS_ZERO) & (t >= -_RS_ZERO) & (v >= -_RS_ZERO)
    return np.where(ok, np.abs(t) + np.abs(u) + np.abs(v) + _PI, np.inf)


def _four(word, x, y, phi) -> np.ndarray:
    """The shortest of a word, its time flip, its reflection and both."""
    return np.minimum(np.minimum(word(x, y, phi), word(-x, y, -phi)),
                      np.minimum(word(x, -y, -phi), word(-x, -y, phi)))  # fmt: skip


def reeds_shepp_lengths(a: np.ndarray, b: np.ndarray, rho: float) -> np.ndarray:
    """Length of the shortest Reeds-Shepp path from each pose of ``a`` to the matching one of
    ``b``, in turning radii (OMPL's ``getPath(a, b).length()``).

    Parameters
    ----------
    a, b : ndarray, shape (..., 3)
        Poses ``(x, y, yaw)``: units, units, rad.
    rho : float
        Turning radius, units.

    Returns
    -------
    ndarray, shape (...)
        The shortest of OMPL's 48 words (CSC, CCC, CCCC, CCSC, CCSCC, each time-flipped,
        reflected, and the CCC and CCSC ones also backwards).
    """
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    x, y = (c * dx + s * dy) / rho, (-s * dx + c * dy) / rho
    phi = b[..., 2] - a[..., 2]
    xb, yb = x * np.cos(phi) + y * np.sin(phi), x * np.sin(phi) - y * np.cos(phi)
    with np.errstate(invalid="ignore"):
        best = np.minimum(_four(_lp_sp_lp, x, y, phi), _four(_lp_sp_rp, x, y, phi))
        for word in (_lp_rm_l, _lp_rm_sm_lm, _lp_rm_sm_rm):
            best = np.minimum(best, _four(word, x, y, phi))
            best = np.minimum(best, _four(word, xb, yb, phi))  # backwards
        for word in (_lp_rup_lum_rm, _lp_rum_lum_rp, _lp_rm_s_lm_rp):
            best = np.minimum(best, _four(word, x, y, phi))
    return best
