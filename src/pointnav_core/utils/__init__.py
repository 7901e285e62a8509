"""Plumbing every package shares: argument checks, frozen containers, atomic output files,
worker processes and the switch for compiled kernels.

==================  ============================================================
Module              What it owns
==================  ============================================================
``validation``      what counts as a number, a vector, a known key (argument errors)
``frozen``          read-only containers that survive ``pickle`` and ``deepcopy``
``outputs``         files written whole or not at all; output paths checked early
``workers``         worker processes that die with their parent
``compiled``        numba kernels when the ``fast`` extra is installed, else numpy
==================  ============================================================
"""
