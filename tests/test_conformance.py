"""The conformance kit: every installed backend passes it, and broken backends are caught."""

from __future__ import annotations

import subprocess
import sys
import types

import numpy as np
import pytest
from hypothesis import given, reject
from hypothesis import strategies as st
from pointnav_kinematic import KinematicBackend

from pointnav_core.backends.protocol import (
    FLOAT_TWINS,
    UnknownBackendError,
    available_backends,
    check_backend,
    float_twin,
    get_backend,
    make_backend,
)
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import BackendError
from pointnav_core.floor.maps import FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.testing import strategies
from pointnav_core.testing.__main__ import main
from pointnav_core.testing.conformance import (
    CHECKS,
    OVERLAP_TOLERANCE,
    Check,
    CheckResult,
    ConformanceError,
    assert_conforms,
    backend_factory,
    format_report,
    get_check,
    obstacle_distance,
    run_checks,
)

BACKENDS = available_backends()


def test_both_shipped_backends_are_installed():
    assert {"kinematic", "pymunk"} <= set(BACKENDS)


@pytest.mark.parametrize("check", CHECKS, ids=str)
@pytest.mark.parametrize("backend", BACKENDS)
def test_backend_passes_check(backend, check):
    check(backend_factory(backend))


# ----------------------------------------------------------------------- broken backends


def recoded(scene, old: int, new: int):
    """The scene with every ``old`` cell turned into ``new`` (a stand-in with three members)."""
    floors = [
        TraversableMap(np.where(f.codes == old, new, f.codes), f.resolution, f.origin, f.height)
        for f in scene.floors
    ]
    return types.SimpleNamespace(
        floors=floors, n_floors=len(floors), get_floor_height=lambda i=0: floors[i].height
    )


class Ghost(KinematicBackend):
    """Walls are not there: robots drive through them."""

    def load(self, scene, robots, action_frequency=10.0):
        super().load(recoded(scene, OBSTACLE, FREE), robots, action_frequency)


class Hover(KinematicBackend):
    """VOID is floor: nothing ever falls."""

    def load(self, scene, robots, action_frequency=10.0):
        super().load(recoded(scene, VOID, FREE), robots, action_frequency)


class Numb(KinematicBackend):
    """Never reports a contact."""

    def in_contact(self, idn):
        return False


class Flat(KinematicBackend):
    """Returns (x, y) positions instead of (x, y, z)."""

    def get_pose(self, idn):
        position, orientation = super().get_pose(idn)
        return position[:2], orientation


class Jittery(KinematicBackend):
    """Adds a little noise to every action: not reproducible."""

    def __init__(self):
        super().__init__()
        self._rng = np.random.default_rng()

    def step(self, actions):
        noise = self._rng.uniform
        super().step({k: a + noise(-1e-3, 1e-3, np.shape(a)) for k, a in actions.items()})


class Boastful(KinematicBackend):
    """Reports velocities 50% too high."""

    def get_velocity(self, idn):
        lin, ang = super().get_velocity(idn)
        return lin * 1.5, ang


class Clingy(KinematicBackend):
    """Keeps robots placed across reset, so old positions still block new placements."""

    def reset(self):
        for rb in self._robots:
            rb.contact = False
            rb.vel = (0.0, 0.0, 0.0, 0.0)


class Shifted(KinematicBackend):
    """Its float twin of get_pose reports x 1 m off (get_pose itself is right)."""

    def get_pose_floats(self, idn):
        x, *rest = super().get_pose_floats(idn)
        return (x + 1.0, *rest)


class Partial:
    """Implements only part of the protocol."""

    n_robots = 0

    def load(self, scene, robots, action_frequency=10.0): ...

    def step(self, actions): ...


@pytest.mark.parametrize(
    ("backend", "failing", "message"),
    [
        (Ghost, {"wall_contact", "no_tunnelling", "valid_pose", "reset"}, "overlapping an"),
        (Hover, {"valid_pose", "falling"}, "should have fallen"),
        (Numb, {"wall_contact", "robot_contact", "no_tunnelling", "reset"}, "contact flags"),
        (Flat, None, "get_pose(0) position must have shape (3,), got shape (2,)"),
        (Jittery, {"open_space_motion", "determinism"}, "diverged at step 1"),
        (Boastful, {"velocity_matches_motion"}, "but the robot moved"),
        (Clingy, {"reset"}, "still blocks is_valid_pose"),
        (Shifted, {"fast_paths"}, "get_pose_floats(0) after land returned"),
    ],
    ids=lambda v: v.__name__ if isinstance(v, type) else None,
)
def test_kit_reports_what_a_broken_backend_gets_wrong(backend, failing, message):
    results = run_checks(backend)
    failed = {r.name for r in results if not r.passed}
    if failing is None:  # wrong shapes break nearly everything; the protocol check says why
        assert "protocol" in failed
    else:
        assert failing <= failed
    assert any(message in r.message for r in results if not r.passed)
    with pytest.raises(ConformanceError, match="failed .* conformance checks") as info:
        assert_conforms(backend)
    assert message in str(info.value)
    assert isinstance(info.value, BackendError) and isinstance(info.value, AssertionError)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_wrong_float_twin_fails_the_fast_path_check(backend):
    # A third-party subclass whose fast path lies: the task would read its numbers on
    # every step, so the kit must refuse it, naming the twin and the entries that differ.
    class SlowVelocity(get_backend(backend)):
        def get_velocity_floats(self, idn):
            vx, *rest = super().get_velocity_floats(idn)
            return (vx * 0.5, *rest)

    check = get_check("fast_paths")
    check(backend_factory(backend))  # the shipped backend passes
    with pytest.raises(AssertionError, match=r"get_velocity_floats\(0\) after step 1 returned"):
        check(SlowVelocity)
    with pytest.raises(AssertionError, match=r"differ at entries \[0\]"):
        check(Shifted)


def test_the_fast_path_check_skips_twins_the_task_does_not_read():
    # Boastful overrides get_velocity but inherits get_velocity_floats: the task reads
    # get_velocity then (see backend.float_twin), so the stale twin is not its business.
    class ArraysOnly(Boastful):  # overrides get_pose too: the task reads no twin at all
        def get_pose(self, idn):
            return super().get_pose(idn)

    assert float_twin(Boastful(), "get_velocity_floats") is None
    assert float_twin(Boastful(), "get_pose_floats") is not None
    assert [float_twin(ArraysOnly(), twin) for twin in FLOAT_TWINS] == [None, None]
    results = run_checks(Boastful, ["fast_paths"]) + run_checks(ArraysOnly, ["fast_paths"])
    assert [r.passed for r in results] == [True, True]


def test_wrong_shapes_are_named_by_the_protocol_check():
    (result,) = run_checks(Flat, ["protocol"])
    assert not result.passed
    assert result.message == "get_pose(0) position must have shape (3,), got shape (2,)"


def test_missing_methods_are_refused_by_check_backend_and_make_backend():
    with pytest.raises(BackendError, match="Partial does not implement the Backend") as info:
        check_backend(Partial)
    missing = str(info.value).split("missing: ")[1].split(", ")
    assert {"get_pose", "in_contact", "is_valid_pose", "land"} <= set(missing)
    assert "load" not in missing and "step" not in missing
    with pytest.raises(BackendError, match="missing: .*get_pose"):
        make_backend(Partial)


def test_missing_methods_fail_the_protocol_check_listing_them():
    results = run_checks(Partial)
    protocol = results[0]
    assert protocol.name == "protocol" and not protocol.passed
    assert "missing: " in protocol.message and "get_velocity" in protocol.message
    with pytest.raises(ConformanceError, match="protocol: Partial does not implement"):
        assert_conforms(Partial, ["protocol"])


def test_an_unexpected_exception_fails_the_check_and_says_where():
    class Exploding(KinematicBackend):
        def land(self, *args, **kwargs):
            raise RuntimeError("boom")

    (result,) = run_checks(Exploding, ["landing"])
    assert not result.passed
    assert result.message.startswith("raised RuntimeError: boom (at ")
    assert "in land)" in result.message


# ----------------------------------------------------------------------- kit API


def test_checks_have_unique_names_and_summaries():
    names = [c.name for c in CHECKS]
    assert len(set(names)) == len(names) == 14
    assert all(isinstance(c, Check) and c.summary and str(c) == c.name for c in CHECKS)


def test_get_check_lists_the_valid_names():
    assert get_check("determinism") is CHECKS[-1]
    with pytest.raises(ValueError, match=r"check must be one of \['protocol', .*got 'x'"):
        get_check("x")


def test_backend_factory_accepts_names_paths_classes_and_callables():
    assert backend_factory("kinematic") is KinematicBackend
    assert backend_factory("pointnav_kinematic:KinematicBackend") is KinematicBackend
    assert backend_factory(KinematicBackend) is KinematicBackend

    def factory():
        return KinematicBackend(collision_mode="stop")

    assert backend_factory(factory) is factory
    with pytest.raises(UnknownBackendError, match=r"backend must be one of \[.*'kinematic'"):
        backend_factory("warp_drive")
    with pytest.raises(TypeError, match="backend must be a backend name, a class or a factory"):
        backend_factory(3)  # type: ignore[arg-type]


def test_run_checks_accepts_names_or_checks_and_keeps_their_order():
    stopping = lambda: KinematicBackend(collision_mode="stop")  # noqa: E731
    results = run_checks(stopping, ["reset", get_check("protocol")])
    assert [r.name for r in results] == ["reset", "protocol"]
    assert all(r.passed and r.message == "" and r.seconds >= 0.0 for r in results)


def test_format_report_has_one_line_per_check_and_a_summary():
    report = format_report(
        [CheckResult("a", True, "", 0.0), CheckResult("long_name", False, "why", 0.0)], "title"
    )
    assert report.splitlines() == [
        "title",
        "PASS  a",
        "FAIL  long_name  why",
        "2 checks: 1 passed, 1 failed",
    ]


# ----------------------------------------------------------------------- command line


def test_cli_passes_the_kinematic_backend_with_exit_status_0():
    done = subprocess.run(
        [sys.executable, "-m", "pointnav_core.testing", "kinematic"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("pointnav-core conformance: backend 'kinematic'")
    assert [line.split()[0] for line in lines[1:-1]] == ["PASS"] * len(CHECKS)
    assert lines[-1] == f"{len(CHECKS)} checks: {len(CHECKS)} passed, 0 failed"
    assert done.stderr == ""


def test_cli_unknown_backend_exits_2_listing_installed_names(capsys):
    assert main(["warp_drive"]) == 2
    err = capsys.readouterr().err
    assert "no backend named 'warp_drive'" in err
    assert all(name in err for name in BACKENDS)


def test_cli_without_a_backend_exits_2(capsys):
    assert main([]) == 2
    assert "give a backend" in capsys.readouterr().err


def test_cli_broken_backend_exits_1_with_a_readable_report(tmp_path, monkeypatch, capsys):
    (tmp_path / "broken_backend_mod.py").write_text(
        "from pointnav_kinematic import KinematicBackend\n"
        "class Numb(KinematicBackend):\n"
        "    def in_contact(self, idn):\n"
        "        return False\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    assert main(["broken_backend_mod:Numb", "--check", "wall_contact", "--check", "landing"]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[1].startswith("FAIL  wall_contact  contact flags over 5 steps")
    assert out[2] == "PASS  landing"
    assert out[3] == "2 checks: 1 passed, 1 failed"


def test_cli_bad_module_path_exits_2(capsys):
    assert main(["no_such_module_xyz:Thing"]) == 2
    assert "cannot load backend" in capsys.readouterr().err


def test_cli_lists_the_checks(capsys):
    assert main(["--list"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in out] == [c.name for c in CHECKS]


# ----------------------------------------------------------------------- properties, every backend


@pytest.mark.parametrize("name", BACKENDS)
@given(data=st.data())
def test_a_robot_never_ends_a_step_in_an_obstacle_and_reports_its_motion(name, data):
    scene = data.draw(strategies.scenes(max_floors=2, max_side=16, resolutions=(0.1, 0.25)))
    spec = data.draw(strategies.robot_specs(max_radius=0.3, max_speed=2.0))
    try:
        poses = strategies.valid_poses(scene, spec)
    except ValueError:
        reject()
    floor, position, orientation = data.draw(poses)
    actions = data.draw(strategies.action_sequences(spec, max_steps=12, overshoot=0.5))
    backend = make_backend(name)
    backend.load(scene, [spec])
    assert backend.is_valid_pose(0, position, orientation, floor=floor)
    backend.land(0, floor, position, orientation)
    height = scene.get_floor_height(floor)
    for action in actions:
        before = backend.get_pose(0)[0]
        backend.step({0: action})
        after = backend.get_pose(0)[0]
        np.testing.assert_allclose(backend.get_velocity(0)[0], (after - before) * 10.0, atol=1e-6)
        if after[2] == height:  # not falling
            depth = spec.radius - obstacle_distance(scene.floors[floor], after[0], after[1])
            assert depth <= OVERLAP_TOLERANCE


@pytest.mark.parametrize("name", BACKENDS)
@given(data=st.data())
def test_robots_never_end_a_step_overlapping_each_other(name, data):
    scene = data.draw(strategies.scenes(max_floors=1, max_side=20, resolutions=(0.1,)))
    one_spec = strategies.robot_specs(max_radius=0.15, max_speed=1.0)
    specs = data.draw(st.lists(one_spec, min_size=2, max_size=4))
    placements = data.draw(strategies.robot_placements(scene, tuple(specs), floor=0))
    steps = data.draw(st.integers(1, 10))
    actions = [
        {i: data.draw(strategies.robot_actions(s)) for i, s in enumerate(specs)}
        for _ in range(steps)
    ]
    backend = make_backend(name)
    backend.load(scene, specs)
    for idn, (floor, position, orientation) in enumerate(placements):
        assert backend.is_valid_pose(idn, position)
        backend.land(idn, floor, position, orientation)
    for step in actions:
        backend.step(step)
        standing = [i for i in range(len(specs)) if backend.get_pose(i)[0][2] == 0.0]
        for a in standing:
            for b in standing:
                if a < b:
                    gap = np.linalg.norm(backend.get_pose(a)[0] - backend.get_pose(b)[0])
                    assert gap >= specs[a].radius + specs[b].radius - OVERLAP_TOLERANCE


# ----------------------------------------------------------------------- strategies


@given(data=st.data())
def test_valid_poses_are_valid_for_every_backend(data):
    scene = data.draw(strategies.scenes())
    radius = data.draw(st.floats(0.0, 0.3))
    try:
        poses = strategies.valid_poses(scene, radius)
    except ValueError:
        assert not any(f.usable(radius).any() for f in scene.floors)
        return
    floor, position, orientation = data.draw(poses)
    assert position[2] == scene.get_floor_height(floor)
    assert np.linalg.norm(orientation) == pytest.approx(1.0)
    for name in BACKENDS:
        backend = make_backend(name)
        backend.load(scene, [RobotSpec(radius=radius)])
        assert backend.is_valid_pose(0, position, orientation, floor=floor), name


@given(strategies.action_sequences(RobotSpec(drive="holonomic"), min_steps=2, max_steps=5))
def test_action_sequences_have_one_row_per_step(actions):
    assert actions.dtype == np.float64 and actions.shape[1] == 3 and 2 <= len(actions) <= 5
    assert np.all(np.abs(actions) <= 1.0)


def test_strategy_arguments_are_validated():
    with pytest.raises(ValueError, match="min_steps and max_steps"):
        strategies.action_sequences(RobotSpec(), min_steps=3, max_steps=2)
    with pytest.raises(ValueError, match="fits nowhere"):
        scene = types.SimpleNamespace(
            floors=[TraversableMap(np.zeros((3, 3), np.uint8), 0.1)], n_floors=1
        )
        strategies.valid_poses(scene, 1.0)
    with pytest.raises(ValueError, match=r"floor must be an int in \[0, 1\)"):
        strategies.valid_poses(scene, 0.0, floor=2)
