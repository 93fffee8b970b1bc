"""A free-form Mueller phase matrix that is physically realizable by construction: NIST SCATMECH's
``Constrained_Phase_Function`` (Germer, Proc. SPIE 10655, 1065504 (2018)) with its nodes drawn from a box.

For a macroscopically isotropic, mirror-symmetric medium the reduced phase matrix (divided by P11) is, in the
scattering plane's (parallel, perpendicular) basis,

    [[1, b1, 0, 0], [b1, a2, 0, 0], [0, 0, a3, b2], [0, 0, -b2, a4]]

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import reduce

import jax
import jax.numpy as jnp
import numpy as np

_PI = np.pi
_TINY = 1e-30
SUBDIVISIONS = 4  # arcs per cubic piece whose control points are held inside K
INNER = 0.8  # the share of the way to the spline's realizability limit that is kept unchanged
SHARPNESS = 1000.0  # the pull's smooth maximum over the control points' gauges: log-sum-exp at this sharpness

# the 14 box coordinates, in order: at 0 deg (m22 = m33, m44), at 60 and 120 deg (m22, the split of m33 - m44,
# then m12, the sum m33 + m44 and m34 inside their ball), at 180 deg (m22 = -m33, m44)
COORDINATES = (
    ("m22_0", "M22/M11 (= M33/M11) at 0 deg"),
    ("m44_0", "M44/M11 at 0 deg, as a position in its realizable range [|2 M22| - 1, 1]"),
    ("m22_60", "M22/M11 at 60 deg"),
    ("d_60", "(M33 - M44)/M11 at 60 deg, as a share of its realizable bound 1 - M22/M11"),
    ("m12_60", "2 M12/M11 at 60 deg, as a share of its realizable bound 1 + M22/M11"),
    ("s_60", "(M33 + M44)/M11 at 60 deg, as a share of what M12 leaves of the bound 1 + M22/M11"),
    ("m34_60", "2 M34/M11 at 60 deg, as a share of what M12 and M33 + M44 leave of the bound 1 + M22/M11"),
    ("m22_120", "M22/M11 at 120 deg"),
    ("d_120", "(M33 - M44)/M11 at 120 deg, as a share of its realizable bound 1 - M22/M11"),
    ("m12_120", "2 M12/M11 at 120 deg, as a share of its realizable bound 1 + M22/M11"),
    ("s_120", "(M33 + M44)/M11 at 120 deg, as a share of what M12 leaves of the bound 1 + M22/M11"),
    ("m34_120", "2 M34/M11 at 120 deg, as a share of what M12 and M33 + M44 leave of the bound 1 + M22/M11"),
    ("m22_180", "M22/M11 (= -M33/M11) at 180 deg"),
    ("m44_180", "M44/M11 at 180 deg, as a position in its realizable range [-1, 1 - 2 |M22|]"),
)

# SCATMECH Constrained_Phase_Function's parameter names (0-based elements) for NodeValues' fields
SCATMECH_NAMES = {
    "m11_0": ("a2", 0), "m11_60": ("a2", 1), "m11_120": ("a2", 2), "m11_180": ("a2", 3),
    "m22_60": ("a3", 1), "m22_120": ("a3", 2),
    "m33_0": ("a4", 0), "m33_60": ("a4", 1), "m33_120": ("a4", 2), "m33_180": ("a4", 3),
    "m10_60": ("b1", 1), "m10_120": ("b1", 2), "m23_60": ("b2", 1), "m23_120": ("b2", 2),
}


def spline_weights(theta):
    """SCATMECH's spline through values at 0, 60, 120 and 180 deg (zero slope at both ends) as its four cardinal
    weights at the scattering angle ``theta`` (radians, [0, pi]): the spline is sum_j w_j y_j."""
    x = theta
    x2, x3 = x * x, x * x * x
    pi2, pi3 = _PI * _PI, _PI ** 3
    # SCATMECH phasefunction.cpp, the three pieces, each written as the coefficients of y0..y3
    first = ((5 * pi3 + 162 * x3 - 99 * _PI * x2), (-243 * x3 + 126 * _PI * x2), (108 * x3 - 36 * _PI * x2),
             (-27 * x3 + 9 * _PI * x2))
    second = ((144 * _PI * x2 + 14 * pi3 - 81 * x3 - 81 * pi2 * x), (-306 * _PI * x2 - 16 * pi3 + 189 * x3 + 144 * pi2 * x),
              (261 * _PI * x2 + 11 * pi3 - 189 * x3 - 99 * pi2 * x), (-99 * _PI * x2 - 4 * pi3 + 81 * x3 + 36 * pi2 * x))
    tail = (_PI - x) ** 2
    third = (-9 * tail * (-3 * x + 2 * _PI), -9 * tail * (12 * x - 8 * _PI), -9 * tail * (-27 * x + 13 * _PI),
             (2 * _PI - 3 * x) * (34 * pi2 - 93 * _PI * x + 54 * x2))
    in_first, in_second = x <= _PI / 3, x <= 2 * _PI / 3
    return tuple(jnp.where(in_first, a, jnp.where(in_second, b, c)) / (5 * pi3) for a, b, c in zip(first, second, third))


def _control_point_weights(subdivisions: int = SUBDIVISIONS) -> np.ndarray:
    """(12 ``subdivisions``, 4): the Bezier control points of the spline's three cubic pieces, each cut into
    ``subdivisions`` equal arcs, as weights of the four node values (each arc's Bernstein coefficients, from its
    cubic fitted exactly through four points). Finer arcs bring the control points closer to the curve."""
    rows = []
    width = _PI / 3 / subdivisions
    for arc in range(3 * subdivisions):
        tau = np.array([0.1, 0.4, 0.6, 0.9])
        weights = np.array(spline_weights(arc * width + tau * width)).T  # (4 points, 4 nodes)
        monomial = np.linalg.solve(np.vander(tau, 4, increasing=True), weights)  # (power, node)
        a0, a1, a2, a3 = monomial
        rows += [a0, a0 + a1 / 3, a0 + 2 * a1 / 3 + a2 / 3, a0 + a1 + a2 + a3]
    return np.array(rows)


CONTROL_POINTS = _control_point_weights()


@dataclass(frozen=True)
class NodeValues:
    """The reduced phase matrix's elements at the nodes 0, 60, 120, 180 deg: a2 = m22, a3 = m33, a4 = m44,
    b1 = m12, b2 = m34 (NIST's 1-based names), each a tuple of four arrays."""
    a2: tuple
    a3: tuple
    a4: tuple
    b1: tuple
    b2: tuple

    def scaled(self, factor) -> "NodeValues":
        """Every value times ``factor`` (a pull towards the depolarizer, whose reduced elements are all 0)."""
        return NodeValues(*(tuple(v * factor for v in values) for values in self.elements()))

    def elements(self) -> tuple:
        """(a2, a3, a4, b1, b2)."""
        return (self.a2, self.a3, self.a4, self.b1, self.b2)

    def scatmech(self) -> dict:
        """SCATMECH Constrained_Phase_Function's parameters."""
        return {name: getattr(self, field)[node] for name, (field, node) in SCATMECH_NAMES.items()}

    def at(self, theta) -> tuple:
        """The splined elements (a2, a3, a4, b1, b2) at scattering angles ``theta`` (radians)."""
        w = spline_weights(theta)
        return tuple(sum(wj * yj for wj, yj in zip(w, values)) for values in self.elements())


def _sqrt(x):
    return jnp.sqrt(jnp.maximum(x, 0.0) + _TINY)


def _ball(c1, c2, c3):
    """A point of the unit ball from three coordinates in [-1, 1] (onto, one-to-one inside)."""
    r1 = _sqrt(1.0 - c1 * c1)
    r2 = r1 * _sqrt(1.0 - c2 * c2)
    return c1, c2 * r1, c3 * r2


def node_values(u) -> NodeValues:
    """The 14 box coordinates ``u`` (``COORDINATES``' order, each in [-1, 1]) as node values, each node inside the
    realizable set K (before the pull that keeps the spline inside it between the nodes)."""
    m22_0, m44_0, *mid, m22_180, m44_180 = u
    # 0 deg: a3 = a2 = p; K asks |p - a4| <= 1 - p and |p + a4| <= 1 + p, so a4 in [|2p| - 1, 1]
    a4_0 = jnp.abs(2 * m22_0) - 1 + (1 - jnp.abs(m22_0)) * (m44_0 + 1)
    # 180 deg: a3 = -a2 = -p; K asks |p + a4| <= 1 - p and |a4 - p| <= 1 + p, so a4 in [-1, 1 - 2 |p|]
    a4_180 = -1 + (1 - jnp.abs(m22_180)) * (m44_180 + 1)
    nodes = {"a2": [m22_0], "a3": [m22_0], "a4": [a4_0], "b1": [0.0], "b2": [0.0]}
    for a2, d, c1, c2, c3 in (mid[:5], mid[5:]):
        x, y, z = _ball(c1, c2, c3)
        total = (1 + a2) * y  # a3 + a4
        diff = (1 - a2) * d  # a3 - a4
        for key, value in (("a2", a2), ("a3", 0.5 * (total + diff)), ("a4", 0.5 * (total - diff)),
                           ("b1", 0.5 * (1 + a2) * x), ("b2", 0.5 * (1 + a2) * z)):
            nodes[key].append(value)
    for key, value in (("a2", m22_180), ("a3", -m22_180), ("a4", a4_180), ("b1", 0.0), ("b2", 0.0)):
        nodes[key].append(value)
    return NodeValues(*(tuple(nodes[k]) for k in ("a2", "a3", "a4", "b1", "b2")))


def gauge(a2, a3, a4, b1, b2):
    """K's gauge (Minkowski functional about the depolarizer): the smallest t >= 0 with the reduced matrix / t in K;
    <= 1 exactly where it is realizable."""
    return jnp.maximum(jnp.maximum(a2 + jnp.abs(a3 - a4), _sqrt((a3 + a4) ** 2 + 4 * b1 * b1 + 4 * b2 * b2) - a2), 0.0)


def nodes_gauge(nodes: NodeValues):
    """The largest gauge over the four nodes."""
    values = [gauge(*(e[j] for e in nodes.elements())) for j in range(4)]
    return reduce(jnp.maximum, values)


def control_point_gauges(nodes: NodeValues):
    """The gauge of each of the spline's Bezier control points (``CONTROL_POINTS``' rows), all at once as one
    (points x nodes) product per element (a loop over them traced ~2,500 operations)."""
    points = [jnp.tensordot(CONTROL_POINTS, jnp.stack(jnp.broadcast_arrays(*values)), axes=1)
              for values in nodes.elements()]
    return gauge(*points)


def spline_gauge(nodes: NodeValues):
    """The largest gauge over the spline's Bezier control points: <= 1 means realizable at every angle."""
    return jnp.max(control_point_gauges(nodes), axis=0)


def smooth_spline_gauge(nodes: NodeValues):
    """A smooth upper bound on ``spline_gauge``: the log-sum-exp of the control points' gauges at ``SHARPNESS``.
    It exceeds the largest gauge by at most log(number of control points) / ``SHARPNESS``, so a pull by it keeps the
    spline realizable, and it has no kink where two control points tie for the largest gauge."""
    gauges = control_point_gauges(nodes)
    top = jax.lax.stop_gradient(jnp.max(gauges, axis=0))
    return top + jnp.log(jnp.sum(jnp.exp(SHARPNESS * (gauges - top)), axis=0)) / SHARPNESS


def realizable_nodes(u) -> NodeValues:
    """The node values of box coordinates ``u``, pulled towards the depolarizer in the box's outer shell so that the
    spline is realizable at every angle (one-to-one; unchanged where the nodes are within ``INNER`` of the way to the
    spline's limit along their ray)."""
    nodes = node_values(u)
    t = nodes_gauge(nodes)  # <= 1 by construction
    q = t / jnp.maximum(smooth_spline_gauge(nodes), _TINY)  # the nodes' extent over the spline's along this ray, <= 1
    knee = INNER * q
    outer = knee + (t - knee) * (q - knee) / (1.0 - knee)
    factor = jnp.where(t > knee, outer / jnp.maximum(t, _TINY), 1.0)
    return nodes.scaled(factor)


def phase_matrix(nodes: NodeValues, phase, cos_theta):
    """The phase matrix: the reduced one times the scalar phase function ``phase`` (4 x 4 nested lists, 0.0 where
    structurally zero) at the scattering angles' cosines, in the scattering plane's (parallel, perpendicular) basis."""
    theta = jnp.arccos(jnp.clip(cos_theta, -1.0, 1.0))
    a2, a3, a4, b1, b2 = (v * phase for v in nodes.at(theta))
    return [[phase, b1, 0.0, 0.0], [b1, a2, 0.0, 0.0], [0.0, 0.0, a3, b2], [0.0, 0.0, -b2, a4]]
