"""The Backend protocol, RobotSpec and the backend registry."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest
from pointnav_kinematic import KinematicBackend

from pointnav_core.backends.protocol import (
    Backend,
    UnknownBackendError,
    available_backends,
    check_backend,
    get_backend,
    make_backend,
)
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.errors import BackendError, PointNavError

PROTOCOL_MEMBERS = {
    "load",
    "reset",
    "n_robots",
    "land",
    "set_pose",
    "get_pose",
    "get_velocity",
    "step",
    "in_contact",
    "is_valid_pose",
    "set_present",
    "is_present",
    "get_robot_floor",
}


# ----------------------------------------------------------------------- RobotSpec


def test_robot_spec_defaults_follow_the_spec():
    spec = RobotSpec()
    assert (spec.radius, spec.max_linear_velocity, spec.max_angular_velocity, spec.drive) == (
        0.18,
        0.5,
        1.5,
        "differential",
    )


@pytest.mark.parametrize(
    ("field", "value", "expected"),
    [
        ("radius", -0.1, ">= 0"),
        ("radius", float("nan"), ">= 0"),
        ("radius", float("inf"), ">= 0"),
        ("radius", "big", "number"),
        ("max_linear_velocity", 0.0, "> 0"),
        ("max_linear_velocity", -1.0, "> 0"),
        ("max_angular_velocity", 0.0, "> 0"),
        ("max_angular_velocity", float("nan"), "> 0"),
    ],
)
def test_robot_spec_rejects_bad_numbers_naming_the_field(field, value, expected):
    with pytest.raises(ValueError, match=field) as info:
        RobotSpec(**{field: value})
    assert expected in str(info.value)


def test_robot_spec_rejects_unknown_drive_listing_choices():
    with pytest.raises(ValueError, match=r"drive must be one of \['differential', 'holonomic'\]"):
        RobotSpec(drive="ackermann")


def test_robot_spec_accepts_zero_radius_as_point_robot():
    assert RobotSpec(radius=0).radius == 0.0


def test_robot_spec_is_keyword_only_and_frozen():
    with pytest.raises(TypeError):
        RobotSpec(0.2)  # type: ignore[misc]
    spec = RobotSpec()
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.radius = 1.0  # type: ignore[misc]


def test_robot_spec_stores_floats_so_equal_specs_compare_equal():
    assert RobotSpec(radius=np.float32(0.5), max_linear_velocity=1) == RobotSpec(
        radius=0.5, max_linear_velocity=1.0
    )
    assert isinstance(RobotSpec(radius=np.float64(0.5)).radius, float)
    assert [f.name for f in dataclasses.fields(RobotSpec)] == [
        "radius",
        "max_linear_velocity",
        "max_angular_velocity",
        "drive",
    ]


def test_action_dim_depends_on_drive():
    assert RobotSpec().action_dim == 2
    assert RobotSpec(drive="holonomic").action_dim == 3


def test_scale_action_scales_by_the_maxima():
    spec = RobotSpec(max_linear_velocity=2.0, max_angular_velocity=3.0)
    out = spec.scale_action(np.array([0.5, -0.25]))
    assert out.dtype == np.float64
    np.testing.assert_array_equal(out, [1.0, -0.75])
    holo = RobotSpec(max_linear_velocity=2.0, max_angular_velocity=3.0, drive="holonomic")
    np.testing.assert_array_equal(holo.scale_action([0.5, -0.5, 1.0]), [1.0, -1.0, 3.0])


def test_scale_action_clips_out_of_range_values():
    spec = RobotSpec(max_linear_velocity=2.0, max_angular_velocity=3.0)
    np.testing.assert_array_equal(spec.scale_action([7.0, -1e30]), [2.0, -3.0])


def test_scale_action_accepts_lists_tuples_and_float32():
    spec = RobotSpec()
    expected = spec.scale_action(np.array([0.5, 0.5]))
    for action in ([0.5, 0.5], (0.5, 0.5), np.array([0.5, 0.5], dtype=np.float32)):
        np.testing.assert_array_equal(spec.scale_action(action), expected)


def test_scale_action_returns_a_fresh_array():
    spec = RobotSpec()
    action = np.array([0.5, 0.5])
    out = spec.scale_action(action)
    out[0] = 99.0
    assert action[0] == 0.5 and spec.scale_action(action)[0] == 0.25


@pytest.mark.parametrize(
    "dtype", [np.float32, np.float64, ">f8", np.float16, np.longdouble, np.int64, object]
)
@pytest.mark.parametrize("drive", ["differential", "holonomic"])
def test_scale_action_of_an_array_is_that_of_its_float64_values(drive, dtype):
    # 1-d float32 and float64 arrays skip the conversion (what env.step passes); every
    # dtype, layout and shape must give what the values as a list of floats give.
    spec = RobotSpec(max_linear_velocity=0.7, max_angular_velocity=1.3, drive=drive)
    values = np.array([0.3, -1.7, 0.55, 2.0, -0.123456789], dtype=np.float64)
    for action in (values[: spec.action_dim], values[::2][: spec.action_dim]):
        action = action.astype(dtype)
        expected = spec.scale_action_floats(np.asarray(action, dtype=np.float64).tolist())
        scaled = spec.scale_action_floats(action)
        assert scaled == expected and all(type(v) is float for v in scaled)
    n = spec.action_dim
    for wrong in (values[: n + 1], values[: n - 1], values[:4].reshape(2, 2)):
        with pytest.raises(ValueError) as from_array:
            spec.scale_action_floats(wrong.astype(dtype))
        with pytest.raises(ValueError) as from_list:
            spec.scale_action_floats(wrong.astype(np.float64).tolist())
        assert str(from_array.value) == str(from_list.value)
    if np.dtype(dtype).kind == "f":
        bad = np.full(spec.action_dim, np.nan, dtype=dtype)
        with pytest.raises(ValueError, match=r"action must be finite, got \[nan, nan"):
            spec.scale_action_floats(bad)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_scale_action_rejects_non_finite_values(bad):
    with pytest.raises(ValueError, match="action must be finite"):
        RobotSpec().scale_action([0.0, bad])


@pytest.mark.parametrize(
    ("drive", "action"),
    [
        ("differential", [1.0]),
        ("differential", [1.0, 0.0, 0.0]),
        ("differential", [[1.0, 0.0]]),
        ("differential", [[1.0], [0.0]]),
        ("differential", 1.0),
        ("differential", "ab"),
        ("holonomic", [1.0, 0.0]),
    ],
)
def test_scale_action_rejects_wrong_shape_naming_expected_shape(drive, action):
    spec = RobotSpec(drive=drive)
    with pytest.raises(ValueError, match=rf"action must have shape \({spec.action_dim},\)"):
        spec.scale_action(action)


# ----------------------------------------------------------------------- protocol


def test_protocol_has_exactly_the_documented_members():
    from pointnav_core.backends import protocol as backend

    assert set(backend._protocol_members()) == PROTOCOL_MEMBERS


def test_kinematic_backend_is_a_backend_instance():
    assert isinstance(KinematicBackend(), Backend)


def test_object_missing_methods_is_not_a_backend_instance():
    class Partial:
        def load(self, scene, robots, action_frequency=10.0): ...

    assert not isinstance(Partial(), Backend)


def test_check_backend_accepts_kinematic_class_and_instance():
    assert check_backend(KinematicBackend) is KinematicBackend
    backend = KinematicBackend()
    assert check_backend(backend) is backend


def test_check_backend_lists_every_missing_method():
    class Partial:
        n_robots = 0

        def load(self, scene, robots, action_frequency=10.0): ...

        def step(self, actions): ...

        in_contact = "not callable"

    with pytest.raises(BackendError) as info:
        check_backend(Partial())
    message = str(info.value)
    assert "Partial does not implement the Backend protocol" in message
    listed = set(message.split("missing: ")[1].split(", "))
    assert listed == PROTOCOL_MEMBERS - {"n_robots", "load", "step"}


def test_check_backend_does_not_run_properties():
    class Exploding(KinematicBackend):
        @property
        def n_robots(self) -> int:
            raise AssertionError("check_backend must not call properties")

    check_backend(Exploding())


def test_backend_module_imports_no_backend_package():
    code = (
        "import sys, pointnav_core.backends.protocol\n"
        "assert not [m for m in sys.modules if m.startswith('pointnav_kinematic')]\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


# ----------------------------------------------------------------------- registry


def test_available_backends_lists_kinematic():
    names = available_backends()
    assert "kinematic" in names
    assert names == sorted(names)


def test_get_backend_resolves_kinematic():
    assert get_backend("kinematic") is KinematicBackend


def test_get_backend_unknown_name_lists_installed_names():
    with pytest.raises(UnknownBackendError) as info:
        get_backend("bullet")
    message = str(info.value)
    assert "backend must be one of" in message and "'kinematic'" in message
    assert "'bullet'" in message
    # Both a bad argument value and a backend problem.
    assert isinstance(info.value, ValueError)
    assert isinstance(info.value, BackendError)
    assert isinstance(info.value, PointNavError)


def test_make_backend_from_name_passes_kwargs():
    backend = make_backend("kinematic", collision_mode="stop")
    assert isinstance(backend, KinematicBackend) and backend.collision_mode == "stop"


def test_make_backend_from_class_and_instance():
    assert isinstance(make_backend(KinematicBackend), KinematicBackend)
    backend = KinematicBackend()
    assert make_backend(backend) is backend


def test_make_backend_rejects_kwargs_with_an_instance():
    with pytest.raises(ValueError, match="only apply when backend is a name or a class"):
        make_backend(KinematicBackend(), collision_mode="stop")


def test_make_backend_rejects_non_backends():
    class NotABackend:
        pass

    with pytest.raises(BackendError, match="NotABackend does not implement"):
        make_backend(NotABackend)
    with pytest.raises(BackendError, match="int does not implement"):
        make_backend(3)  # type: ignore[arg-type]


def test_make_backend_unknown_name_is_a_value_error():
    with pytest.raises(ValueError, match="backend must be one of"):
        make_backend("nope")
