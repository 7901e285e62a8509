"""The social metrics of a batched engine's episodes among pedestrians, on request.

The single env adds ``info["social"]`` at each episode's end (:mod:`pointnav_core.task.social`,
about 1 ms for 500 steps of 10 pedestrians). The batched engine leaves them out of its
``info`` (at 1,024 x 4 robots some 8 episodes end in a step: 13 % of the step); a
:class:`SocialTracker` beside it records what they need and computes them, by the single
env's own :func:`~pointnav_core.task.social_metrics`, for the robots whose episode ended:

>>> import numpy as np
>>> from pointnav_core.vector import VectorPointNavEnv
>>> env = VectorPointNavEnv(2, seed=0, pedestrians={"count": 3}, task={"termination_config": {"max_steps": 5}})
>>> tracker = SocialTracker(env)
>>> obs, info = env.reset(seed=0)
>>> tracker.reset()
>>> for _ in range(5):
...     obs, reward, terminated, truncated, info = env.step(np.zeros((2, 2)))
...     ended = tracker.step(terminated, truncated, info)
>>> sorted(ended), round(ended[0, 0]["psc"], 3) <= 1.0
([(0, 0), (1, 0)], True)

It samples the robots and the pedestrians after every control step the crowd walks (the
engine's crowd calls it: :attr:`VectorCrowd.listeners <pointnav_core.vector.crowd.VectorCrowd.listeners>`),
as the single env's track does: once per step with continuous actions, once per control
step of a discrete action.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pointnav_core.errors import ArgumentError

__all__ = ["SocialTracker"]


class SocialTracker:
    """Records a batched engine's episodes among pedestrians and gives their social metrics.

    Parameters
    ----------
    env : VectorPointNavEnv
        An engine with ``pedestrians`` (one robot a world or several, continuous or
        discrete actions).

    Call :meth:`reset` after the engine's ``reset()`` and :meth:`step` after each of its
    ``step()`` calls.
    """

    def __init__(self, env: Any) -> None:
        if getattr(env, "crowd", None) is None:
            raise ArgumentError("env must be a batched engine built with pedestrians={...}")
        self.env = env
        shape = np.shape(env.arrays.numpy(env.state.x))
        self._w, self._r = shape[0], (shape[1] if len(shape) > 1 else 1)
        self._t_max = 64  # samples kept a world, doubled when an episode needs more
        self._robot = np.zeros((self._w, self._t_max, self._r, 2))
        self._heading = np.zeros((self._w, self._t_max, self._r))
        self._peds = np.zeros((self._w, self._t_max, 0, 2))  # widened as crowds are placed
        self._t = np.zeros(self._w, np.int64)
        radii = [s.radius for s in getattr(env, "robots", [env.robot])]
        speeds = [s.max_linear_velocity for s in getattr(env, "robots", [env.robot])]
        self._radius, self._speed = radii, speeds
        env.crowd.listeners.append(self._control_step)

    def reset(self) -> None:
        """Start recording every world's episode (after the engine's ``reset()``)."""
        self._record(np.arange(self._w), start=True)

    def step(self, terminated: Any, truncated: Any, info: dict[str, Any]) -> dict[tuple[int, int], dict[str, Any]]:
        """Record the step the engine just took and return the social metrics of the robots
        whose episode ended in it: ``{(world, robot): {name: value}}``, each dict the
        single env's ``info["social"]`` for the same episode."""
        a = self.env.arrays
        restarted = np.asarray(a.numpy(info["autoreset"])).reshape(self._w, -1).any(-1)
        self._record(np.flatnonzero(restarted), start=True)  # (their samples of this step were the old episode's)
        ended = (np.asarray(a.numpy(terminated)) | np.asarray(a.numpy(truncated))).reshape(self._w, self._r)
        out = {}
        for w, r in zip(*np.nonzero(ended)):
            out[int(w), int(r)] = self._metrics(int(w), int(r), info)
        return out

    def _control_step(self, motion: Any, stepping: np.ndarray) -> None:
        """The crowd walked a control step in the ``stepping`` worlds, beside robots as ``motion``."""
        self._record(np.flatnonzero(stepping), start=False, motion=motion)

    def _record(self, worlds: np.ndarray, start: bool, motion: Any = None) -> None:
        """Sample the robots (``motion``, default the engine's committed state) and the
        pedestrians of ``worlds`` now (``start``: as their first sample)."""
        if not len(worlds):
            return
        a, crowd = self.env.arrays, self.env.crowd
        st = self.env.state if motion is None else motion
        if start:
            self._t[worlds] = 0
        else:
            self._t[worlds] += 1
        t = self._t[worlds]
        if t.max() >= self._t_max:  # a longer episode than any so far: twice the room
            self._t_max *= 2
            self._robot, self._heading, self._peds = (
                np.concatenate([v, np.zeros_like(v)], axis=1) for v in (self._robot, self._heading, self._peds)
            )
        p = crowd.positions.shape[1]
        if p > self._peds.shape[2]:  # the crowds were placed (or widened) since
            wider = np.zeros(self._peds.shape[:2] + (p, 2))
            wider[:, :, : self._peds.shape[2]] = self._peds
            self._peds = wider
        x, y, yaw = (np.asarray(a.numpy(v)).reshape(self._w, self._r)[worlds] for v in (st.x, st.y, st.yaw))
        self._robot[worlds, t] = np.stack([x, y], -1)
        self._heading[worlds, t] = np.arctan2(np.sin(yaw), np.cos(yaw))  # as a quaternion's yaw reads it
        self._peds[worlds, t, :p] = crowd.positions[worlds]

    def _metrics(self, w: int, r: int, info: dict[str, Any]) -> dict[str, Any]:
        """Robot ``r`` of world ``w``'s social metrics, from its recording and ``info``."""
        from pointnav_core.task import recorded_social_metrics

        a, env, crowd = self.env.arrays, self.env, self.env.crowd
        n, k = int(self._t[w]) + 1, int(crowd.count[w])

        def at(v: Any) -> Any:  # robot r of world w's entry of an engine array
            return np.asarray(a.numpy(v)).reshape(self._w, self._r)[w, r]

        goal = [float(at(env.state.goal_x)), float(at(env.state.goal_y))]
        return recorded_social_metrics(
            self._robot[w, :n, r], self._heading[w, :n, r], self._peds[w, :n, :k], dt=1.0 / env.action_frequency,
            robot_radius=self._radius[r], pedestrian_radii=crowd.radius[w, :k], success=bool(at(info["success"])),
            geodesic_dist=float(at(info["geodesic_dist"])), max_speed=self._speed[r], goal=goal,
        )
