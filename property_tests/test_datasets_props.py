"""Properties of episode datasets: exact file round trips, and generated episodes that obey
the rules on arbitrary small scenes."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from pointnav_core.datasets import (
    EpisodeDataset,
    GeneratorConfig,
    PointNavEpisode,
    generate_episodes,
)
from pointnav_core.testing.strategies import nav_scenes, yaws

coords = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


@st.composite
def episodes(draw: st.DrawFn, episode_id: str) -> PointNavEpisode:
    """An episode with arbitrary finite coordinates, a yaw, and optional goal radius."""
    yaw = draw(yaws())
    z = draw(coords)
    return PointNavEpisode(
        episode_id=episode_id,
        scene_id=draw(st.sampled_from(("rooms:0", "movingai:maps/a b.map", "trav:Rs_int"))),
        floor=draw(st.integers(0, 5)),
        start_position=(draw(coords), draw(coords), z),
        start_rotation=(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)),
        goal_position=(draw(coords), draw(coords), z),
        goal_radius=draw(st.none() | st.floats(1e-6, 5.0)),  # a radius of 0 is refused
        geodesic_distance=draw(st.floats(0.0, 1e4)),
        robot_radius=draw(st.floats(0.0, 1.0)),
    )


@st.composite
def datasets(draw: st.DrawFn) -> EpisodeDataset:
    n = draw(st.integers(0, 5))
    return EpisodeDataset(
        [draw(episodes(str(i))) for i in range(n)], {"note": draw(st.text(max_size=8))}
    )


@given(datasets())
def test_bytes_round_trip_exactly(data):
    again = EpisodeDataset.from_json(data.to_json())
    assert again == data and again.to_bytes() == data.to_bytes()


@given(datasets())
def test_habitat_frame_round_trips(data):
    again = EpisodeDataset.from_json(data.to_json("habitat"))
    for a, b in zip(again, data):
        assert a.start_position == b.start_position and a.goal_position == b.goal_position
        assert abs(math.remainder(a.start_yaw - b.start_yaw, 2 * math.pi)) <= 1e-12


@settings(max_examples=15)
@given(nav_scenes(), st.integers(0, 2**32 - 1))
def test_generated_episodes_obey_the_rules(scene, seed):
    config = GeneratorConfig(
        geodesic_range=(0.3, 5.0),
        robot_radius=0.1,
        island_radius_limit=0.0,
        max_goals_per_episode=200,
    )
    for ep in generate_episodes(scene, "s", 3, seed=seed, config=config):
        assert 0.3 <= ep.geodesic_distance <= 5.0
        assert scene.is_usable(0, ep.start_xy, 0.1) and scene.is_usable(0, ep.goal_xy, 0.1)
        _, length = scene.get_shortest_path(0, ep.start_xy, ep.goal_xy, entire_path=True, robot=0.1)
        assert abs(length - ep.geodesic_distance) <= 1e-6
