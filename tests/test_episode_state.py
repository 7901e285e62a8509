"""EpisodeState: the per-step bookkeeping every term reads, against hand calculations."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from pointnav_core.task.episode_state import EpisodeState


class _Field:
    """A goal field whose geodesic is 2x the L2 distance to (4, 0), and none where x < 0."""

    def distance(self, x: float, y: float) -> float:
        return math.inf if x < 0.0 else 2.0 * math.hypot(4.0 - x, y)


def _begun(reward_type: str, geodesic: float = 8.0) -> EpisodeState:
    episode = SimpleNamespace(
        start_xy=(0.0, 0.0), start_quat=(0.0, 0.0, 0.0, 1.0), goal_xy=(4.0, 0.0),
        field=_Field(), geodesic=geodesic,
    )
    state = EpisodeState()
    state.begin(episode, reward_type, (0.0, 0.0, 0.0), [0.0, 0.0, 0.0, 1.0], ["a", "b"])
    return state


def test_begin_starts_every_count_at_zero():
    state = _begun("l2")
    assert (state.steps, state.collisions, state.path_length) == (0, 0, 0.0)
    assert state.results == {"a": (False, False), "b": (False, False)}
    assert state.distance_to_goal == 8.0  # 2 x 4 m
    assert state.potential == 4.0  # L2 to (4, 0)
    assert state.metric == "l2"


def test_advance_sums_the_planar_path_and_counts_steps_and_contacts():
    state = _begun("l2")
    state.advance(3.0, 4.0, 0.5, [0.0, 0.0, 0.0, 1.0], contact=True)   # 5 m (3-4-5)
    state.advance(3.0, 1.0, 0.0, [0.0, 0.0, 0.0, 1.0], contact=False)  # 3 m; z not counted
    assert state.path_length == 8.0
    assert (state.steps, state.collisions, state.in_contact) == (2, 1, False)
    assert state.robot_xyz == (3.0, 1.0, 0.0)
    assert state.potential == pytest.approx(math.hypot(1.0, 1.0))
    assert state.distance_to_goal == pytest.approx(2.0 * math.hypot(1.0, 1.0))


def test_the_geodesic_potential_holds_its_last_value_where_there_is_no_geodesic():
    state = _begun("geodesic")
    assert state.metric == "geodesic" and state.potential == 8.0
    state.advance(1.0, 0.0, 0.0, [0.0, 0.0, 0.0, 1.0], contact=False)
    assert state.potential == 6.0
    state.advance(-1.0, 0.0, 0.0, [0.0, 0.0, 0.0, 1.0], contact=False)  # no geodesic here
    assert state.distance_to_goal == math.inf and state.potential == 6.0


def test_an_unreachable_goal_makes_the_geodesic_potential_l2_for_the_episode():
    state = _begun("geodesic", geodesic=math.inf)
    assert state.metric == "l2" and state.potential == 4.0


def test_info_reports_spl_from_the_start_geodesic_and_the_path():
    state = _begun("l2")
    state.advance(4.0, 0.0, 0.0, [0.0, 0.0, 0.0, 1.0], contact=False)  # 4 m driven, d0 8 m
    info = state.info(True, True, {"r": 1.0}, {})
    # SPL = S * d0 / max(d0, L) = 8 / 8; the robot is on the goal, so SoftSPL is 1 too.
    assert info["spl"] == 1.0 and info["soft_spl"] == 1.0
    assert (info["path_length"], info["episode_length"], info["geodesic_dist"]) == (4.0, 1, 8.0)
    assert info["reward_breakdown"] == {"r": 1.0} and info["potential_metric"] == "l2"
