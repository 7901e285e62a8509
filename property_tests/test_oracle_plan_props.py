"""The oracle's kept plan takes the same decisions as its tested path.

Mid-leg the follower heads along the planned chord without testing the candidates' or its
arc's clearance, because the chord was proven clear for a disc a little wider (see
``ShortestPathFollower._follow``). Each time it does, the test here makes the decision again
the general way, with every clearance test, on the same plan: the same carrot, and the
same arc (or the same refusal of it). Whole episodes on generated houses, both drives.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pointnav_core import scenes
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.policies.oracle import ShortestPathFollower


def _checked(follower: ShortestPathFollower, tmap: Any, seen: list[int]) -> None:
    """Make ``follower`` check each untested decision against its tested path."""
    carrot, arc_step = follower.carrot, follower._arc_step

    def checked_carrot(xy: np.ndarray) -> Any:
        out = carrot(xy)
        if follower._room is not None:
            plan = follower._plan
            general = follower._pick(
                xy, np.vstack([xy, plan.points[plan.leg + 1 :]]), plan.radius, tmap, fallback=False
            )
            np.testing.assert_allclose(out, general, rtol=0, atol=1e-12)
            seen[0] += 1
        return out

    def checked_arc(*args: Any) -> Any:
        out = arc_step(*args)
        if follower._room is not None:
            room, follower._room = follower._room, None
            assert arc_step(*args) == out
            follower._room = room
            seen[1] += 1
        return out

    follower.carrot, follower._arc_step = checked_carrot, checked_arc


@settings(max_examples=4, deadline=None)
@given(house=st.integers(0, 10_000), episode=st.integers(0, 2**31 - 1), drive=st.sampled_from(("differential", "holonomic")))
def test_the_kept_plan_decides_as_the_tested_path_does(house, episode, drive):
    env = PointNavEnv(scene=scenes.rooms(seed=house), robot={"drive": drive})
    env.reset(seed=episode)
    follower = ShortestPathFollower(env)
    seen = [0, 0]
    _checked(follower, env.scene.floors[env.task.floor], seen)
    done = False
    while not done:
        _, _, terminated, truncated, info = env.step(follower.act())
        done = terminated or truncated
    assert info["success"]
    # The untested path is the common one mid-leg (a vacuous pass would prove nothing).
    assert seen[0] > 0
