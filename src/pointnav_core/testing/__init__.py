"""Test kit for pointnav-core and its backends: hypothesis strategies and conformance checks.

``pointnav_core.testing.strategies`` needs the ``hypothesis`` package (the ``dev`` extra).
"""
