"""A simple picture of the robot, drawn with numpy: two side views (looking along world -y and
along world +x) of the ball, the body's axis and the floor."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ballbot._core import StepTelemetry

_HEIGHT, _WIDTH = 240, 240
_METRES_PER_PIXEL = 1.0 / _HEIGHT


def _rotate(q: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """``v`` rotated by the unit quaternion ``q = (x, y, z, w)``."""
    u, w = q[:3], q[3]
    t = 2.0 * np.cross(u, v)
    return np.asarray(v + w * t + np.cross(u, t), dtype=np.float64)


def _panel(
    ball: NDArray[np.float64],
    top: NDArray[np.float64],
    radius_m: float,
    centre: float,
) -> NDArray[np.uint8]:
    """One side view: ``ball`` and ``top`` are (horizontal, height) in metres."""
    img = np.full((_HEIGHT, _WIDTH, 3), 245, dtype=np.uint8)
    rows, cols = np.mgrid[0:_HEIGHT, 0:_WIDTH]
    # Pixel centres in metres: the view follows the ball horizontally.
    x = (cols - _WIDTH / 2) * _METRES_PER_PIXEL + centre
    z = (_HEIGHT - 20 - rows) * _METRES_PER_PIXEL
    img[z < 0] = (120, 110, 100)
    in_ball = (x - ball[0]) ** 2 + (z - ball[1]) ** 2 <= radius_m**2
    img[in_ball] = (200, 60, 50)
    # The body: a thick segment from the ball centre to the top.
    d = top - ball
    length2 = float(d @ d) or 1.0
    s = np.clip(((x - ball[0]) * d[0] + (z - ball[1]) * d[1]) / length2, 0.0, 1.0)
    dist2 = (x - ball[0] - s * d[0]) ** 2 + (z - ball[1] - s * d[1]) ** 2
    img[dist2 <= 0.035**2] = (40, 70, 160)
    return img


def draw(t: StepTelemetry, radius_m: float, height_m: float) -> NDArray[np.uint8]:
    """A (240, 482, 3) uint8 picture of the state ``t``: the two views side by side."""
    ball = np.asarray(t.ball_position_m, dtype=np.float64)
    axis = _rotate(np.asarray(t.body_orientation, dtype=np.float64), np.array([0.0, 0.0, 1.0]))
    top = ball + height_m * axis
    side_x = _panel(ball[[0, 2]], top[[0, 2]], radius_m, float(ball[0]))
    side_y = _panel(ball[[1, 2]], top[[1, 2]], radius_m, float(ball[1]))
    gap = np.zeros((_HEIGHT, 2, 3), dtype=np.uint8)
    return np.concatenate([side_x, gap, side_y], axis=1)
