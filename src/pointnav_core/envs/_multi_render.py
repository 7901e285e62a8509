"""``render()`` of the multi-robot env: the mode rules PettingZoo asks for, then the frame."""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from numpy.typing import NDArray

from pointnav_core.errors import ArgumentError

__all__ = ["render_frame"]


def render_frame(env: Any, mode: str | None, renderers: Any) -> NDArray[np.uint8] | None:
    """``env``'s top-down frame (:func:`pointnav_core.render.recording.render_env`), or None
    with Gymnasium's warning without a render mode. ``mode``, if given, must be the env's
    ``render_mode``; ``"human"`` opens no window and is refused."""
    if mode is not None and mode != env.render_mode:
        raise ArgumentError(
            f"render() draws in the render_mode given at construction "
            f"({env.render_mode!r}), got mode={mode!r}"
        )
    if env.render_mode is None:
        gymnasium.logger.warn(
            "You are calling render method without specifying any render mode. "
            "You can specify the render_mode at initialization, e.g. "
            'parallel_env(render_mode="rgb_array")'
        )
        return None
    if env.render_mode == "human":
        raise NotImplementedError(
            'render_mode="human" is not supported (pointnav-core opens no window): use '
            'render_mode="rgb_array" and show or save the frames '
            "(pointnav_core.render.recording.save_gif)"
        )
    # Imported here: drawing is only needed when rendering.
    from pointnav_core.render.recording import render_env

    return render_env(env, renderers=renderers)
