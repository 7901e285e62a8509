"""Property: an episode's recorded crowd (issue 33) round-trips exactly through the file in
both frames, whatever its finite coordinates, seeds, radii and speeds."""

from __future__ import annotations

import dataclasses
import gzip
import json

from hypothesis import given, settings
from hypothesis import strategies as st

from pointnav_core.crowds.record import SEED_LIMIT, PedestrianRecord
from pointnav_core.datasets import EpisodeDataset, PointNavEpisode

coords = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)
points = st.tuples(coords, coords)


@st.composite
def records(draw: st.DrawFn) -> PedestrianRecord:
    goals = tuple(draw(st.lists(points, max_size=4)))
    return PedestrianRecord(
        start=draw(points),
        goals=goals,
        loop=bool(goals) and draw(st.booleans()),
        seed=draw(st.integers(0, SEED_LIMIT - 1)),
        radius=draw(st.floats(1e-6, 2.0)),
        speed=draw(st.floats(0.0, 3.0)),
    )


@settings(max_examples=60, deadline=None)
@given(crowd=st.none() | st.lists(records(), max_size=5).map(tuple), z=coords, frame=st.sampled_from(["z-up", "habitat"]))
def test_a_recorded_crowd_round_trips_in_both_frames(crowd, z, frame):
    episode = PointNavEpisode("0", "rooms:0", 0, (1.0, 2.0, z), (0.0, 0.0, 0.0, 1.0), (3.0, 4.0, z), 0.5, 2.0, 0.18)
    data = EpisodeDataset([dataclasses.replace(episode, pedestrians=crowd)])
    back = EpisodeDataset.from_json(json.loads(gzip.decompress(data.to_bytes(frame))))
    assert back[0].pedestrians == crowd
    assert back.to_bytes(frame) == data.to_bytes(frame)
