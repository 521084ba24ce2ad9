"""The environments' pictures: frames of :class:`ballbot.SceneRenderer` (the Rust renderer
``ballbot world --video`` uses too) and, for ``render_mode="human"``, a matplotlib window.

A frame is a 3/4 view that follows the ball over a floor grid fixed to the world: the ball,
the body, the three omniwheels with their rollers, and per wheel an arrow of the force it
applies to the ball coloured by friction-cone use (green 0 to red 1); a lifted wheel is red
and labelled "lift-off"."""

from __future__ import annotations

import importlib
import importlib.util
import warnings
from typing import Any, Optional

import numpy as np
from numpy.typing import NDArray

from ballbot._core import SceneRenderer, StepTelemetry, WorldParams

#: The frame size of ``render_mode="rgb_array"`` (height, width).
FRAME_SHAPE = (360, 480)


def has_matplotlib() -> bool:
    """Whether matplotlib is installed (``render_mode="human"`` is offered only then)."""
    return importlib.util.find_spec("matplotlib") is not None


def require_matplotlib() -> Any:
    """``matplotlib.pyplot``, or a clear error naming what to install."""
    try:
        plt = importlib.import_module("matplotlib.pyplot")
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            'render_mode="human" opens a matplotlib window and needs matplotlib '
            '(pip install matplotlib, or pip install "ballbot[train]"); '
            'render_mode="rgb_array" returns the same frames without it'
        ) from e
    return plt


class Viewer:
    """Draws an environment's states; in ``human`` mode shows them in a window."""

    def __init__(self, params: WorldParams, human: bool = False, fps: float = 50.0) -> None:
        height, width = FRAME_SHAPE
        self._renderer = SceneRenderer(params, width, height)
        self._plt = require_matplotlib() if human else None
        self._pause = 1.0 / max(fps, 1.0)
        self._figure: Any = None
        self._image: Any = None

    def frame(self, t: StepTelemetry) -> NDArray[np.uint8]:
        """The state ``t`` as a ``(360, 480, 3)`` uint8 RGB array."""
        return np.asarray(self._renderer.render(t), dtype=np.uint8)

    def show(self, t: StepTelemetry) -> None:
        """Draws ``t`` in the window (opened on the first call)."""
        plt = self._plt
        if plt is None:
            raise RuntimeError("this viewer was not made for render_mode='human'")
        frame = self.frame(t)
        if self._figure is None or not plt.fignum_exists(self._figure.number):
            plt.ion()
            self._figure, ax = plt.subplots(figsize=(frame.shape[1] / 100, frame.shape[0] / 100))
            ax.set_axis_off()
            self._figure.subplots_adjust(0, 0, 1, 1)
            self._image = ax.imshow(frame)
        else:
            self._image.set_data(frame)
        self._figure.canvas.draw_idle()
        with warnings.catch_warnings():
            # A non-interactive backend (Agg, headless) cannot show a window: no warning.
            warnings.simplefilter("ignore", UserWarning)
            plt.pause(self._pause)

    def close(self) -> None:
        """Closes the window, if any."""
        if self._plt is not None and self._figure is not None:
            self._plt.close(self._figure)
        self._figure = None


def viewer(params: WorldParams, render_mode: Optional[str], fps: float) -> Optional[Viewer]:
    """The viewer a render mode needs (none for ``None`` and ``"ansi"``)."""
    if render_mode == "rgb_array":
        return Viewer(params)
    if render_mode == "human":
        return Viewer(params, human=True, fps=fps)
    return None
