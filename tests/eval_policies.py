"""Policies for the ``pointnav eval --policy MODULE:CALLABLE`` tests."""

import os

import numpy as np


def standstill(env):
    """A policy that never moves: every episode ends by timeout."""
    return lambda obs: np.zeros(env.action_space.shape, dtype=np.float32)


def raise_on_episode(env):
    """The oracle, except that it raises on the first step of the episode whose start and
    goal ``x, y`` are ``POINTNAV_TEST_RAISE`` (an environment variable, so that worker
    processes see it too: ``"sx,sy,gx,gy"``)."""
    from pointnav_core.policies.oracle import ShortestPathFollower

    target = os.environ.get("POINTNAV_TEST_RAISE")
    here = [*env.task.get_current_pos(env)[:2], *env.task.get_goal_pos()[:2]]
    if target is not None and [float(v) for v in here] == [float(v) for v in target.split(",")]:

        def broken(obs):
            raise RuntimeError("boom")

        return broken
    follower = ShortestPathFollower(env)
    return lambda obs: follower.act()


def scan16_forward(env):
    """MOVE_FORWARD always, after checking that the env is the one the 16-ray scan config
    of ``tests/test_eval_env_config.py`` builds: flat observations of the 8 ``low_dim``
    values and 16 ranges, 3 discrete actions (no STOP), 12 actions per episode."""
    assert env.observation_space.shape == (24,) and env.action_space.n == 3
    assert env.task.max_steps == 12 and env.task.goal_in_polar

    def act(obs):
        assert obs.shape == (24,)
        return 0

    return act
