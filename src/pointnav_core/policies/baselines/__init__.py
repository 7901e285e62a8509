"""Trained policies shipped with the package: ``pointnav eval --policy baseline:<name>``.

Each is a checkpoint of ``pointnav train`` (a ``.pt`` of plain data, played with the env
config it carries). Their figures, and the command and time that trained them, are in the
README's "Training" section.

======================  =============================================================
``scan-ppo``            goal in polar form and a 64-ray scan to 12 m, Habitat's
                        discrete actions without STOP, trained on the ``houses`` train
                        split with the shipped validation set's distances (1-30 m) by
                        ``pointnav train --config examples/train_scan.yaml``
======================  =============================================================
"""

from __future__ import annotations

from importlib import resources

from pointnav_core.errors import ArgumentError

__all__ = ["PREFIX", "baseline_path", "names"]

#: A policy spec ``PREFIX + name`` names a shipped baseline.
PREFIX = "baseline:"


def names() -> list[str]:
    """The shipped baselines' names, sorted."""
    folder = resources.files(__name__)
    return sorted(entry.name[: -len(".pt")] for entry in folder.iterdir() if entry.name.endswith(".pt"))


def baseline_path(name: str) -> str:
    """The checkpoint file of the baseline ``name``; ValueError naming the shipped ones if
    there is none of that name."""
    known = names()
    if name not in known:
        raise ArgumentError(f"unknown baseline {name!r}: the shipped baselines are {known}")
    return str(resources.files(__name__) / f"{name}.pt")
