"""Command line: run the backend conformance checks.

Usage::

    python -m pointnav_core.testing BACKEND [--check NAME ...]
    python -m pointnav_core.testing --list

``BACKEND`` is an installed backend name (entry-point group ``pointnav_core.backends``) or
a ``package.module:Class`` path. Prints one line per check (PASS or FAIL and why) and a
summary. Exit status: 0 when every check passes, 1 when one fails, 2 for a usage error
such as an unknown backend (the message lists the installed ones).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from pointnav_core.backends.protocol import UnknownBackendError, available_backends
from pointnav_core.testing.conformance import (
    CHECKS,
    backend_factory,
    format_report,
    run_checks,
)

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m pointnav_core.testing",
        description="Run the pointnav-core conformance checks on a backend.",
    )
    parser.add_argument(
        "backend",
        nargs="?",
        help="installed backend name (e.g. kinematic) or a package.module:Class path",
    )
    parser.add_argument(
        "--check",
        action="append",
        choices=[c.name for c in CHECKS],
        metavar="NAME",
        help="run only this check (repeatable); see --list",
    )
    parser.add_argument("--list", action="store_true", help="list the checks and exit")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI with ``argv`` (default: ``sys.argv[1:]``) and return the exit status."""
    parser = _parser()
    args = parser.parse_args(argv)
    if args.list:
        width = max(len(c.name) for c in CHECKS)
        for check in CHECKS:
            print(f"{check.name:<{width}}  {check.summary}")
        return 0
    if args.backend is None:
        parser.print_usage(sys.stderr)
        installed = ", ".join(available_backends())
        print(f"error: give a backend; installed: {installed}", file=sys.stderr)
        return 2
    try:
        factory = backend_factory(args.backend)
    except UnknownBackendError:
        print(
            f"error: no backend named {args.backend!r}; installed: "
            f"{', '.join(available_backends()) or '(none)'}",
            file=sys.stderr,
        )
        return 2
    except (ImportError, AttributeError) as exc:
        print(f"error: cannot load backend {args.backend!r}: {exc}", file=sys.stderr)
        return 2
    target = getattr(factory, "__module__", "?") + ":" + getattr(factory, "__qualname__", "?")
    results = run_checks(factory, args.check)
    title = f"pointnav-core conformance: backend {args.backend!r} ({target})"
    print(format_report(results, title))
    return 0 if all(r.passed for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
