"""Every figure the README, the recipes, getting-started and the results page state, from the
commands that print it.

Runs each figure of ``tests/doc_figures.py`` and ``tests/results_figures.py`` (the test suite
runs the fast ones; this script runs all of them, the optimisations, placements and benchmark
tables that take minutes included), prints each one the page states differently from what the
commands give, and with ``--write`` puts the commands' figures into the pages (review the diff,
and say why in the commit). Run::

    python benchmarks/bench_doc_figures.py [--write] [--fast | --slow] [--work DIR]

Exit status 1 when a page differs (and ``--write`` was not given).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from doc_figures import FIGURES, Runs, check
from results_figures import RESULTS


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="put the figures into the pages")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--fast", action="store_true", help="only what the test suite checks")
    which.add_argument("--slow", action="store_true", help="only the slow figures")
    parser.add_argument("--work", type=Path, help="folder for the commands' outputs [a new one]")
    args = parser.parse_args()
    figures = [
        f
        for f in (*FIGURES, *RESULTS)
        if not (args.fast and f.slow) and not (args.slow and not f.slow)
    ]
    with tempfile.TemporaryDirectory() as tmp:
        work = args.work or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        differ = check(figures, Runs(work), write=args.write)
    return 1 if differ and not args.write else 0


if __name__ == "__main__":
    sys.exit(main())
