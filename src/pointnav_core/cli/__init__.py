"""The ``pointnav`` command line: ``demo``, ``dataset``, ``eval``, ``scene`` and ``train``."""

from pointnav_core.cli.main import main, run_demo

__all__ = ["main", "run_demo"]
