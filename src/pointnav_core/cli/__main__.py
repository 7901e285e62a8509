"""``python -m pointnav_core.cli``: the same as the ``pointnav`` command."""

import os
import sys

from pointnav_core.cli.main import main

status = main()
if status == 130:
    # CPython (3.11 to 3.13) ends `python -m` by killing itself with SIGINT when a
    # KeyboardInterrupt ever passed through code that exec or eval ran from a string
    # (numba and the standard library build code so), even one that was caught: an
    # interrupted run that said so, and kept its results, must still exit with 130.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(130)
sys.exit(status)
