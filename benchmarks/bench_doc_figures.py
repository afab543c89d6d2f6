"""Every figure the README, the recipes and getting-started state, from the commands that print it.

Runs each figure of ``tests/doc_figures.py`` (the test suite runs the fast ones; this script runs
all of them, the optimisations and placements that take minutes included), prints each one the
page states differently from what the commands give, and with ``--write`` puts the commands'
figures into the pages (review the diff, and say why in the commit). Run::

    python benchmarks/bench_doc_figures.py [--write] [--fast | --slow] [--work DIR]

Exit status 1 when a page differs (and ``--write`` was not given).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from doc_figures import FIGURES, Missing, Runs


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="put the figures into the pages")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--fast", action="store_true", help="only what the test suite checks")
    which.add_argument("--slow", action="store_true", help="only the slow figures")
    parser.add_argument("--work", type=Path, help="folder for the commands' outputs [a new one]")
    args = parser.parse_args()
    figures = [f for f in FIGURES if not (args.fast and f.slow) and not (args.slow and not f.slow)]
    with tempfile.TemporaryDirectory() as tmp:
        work = args.work or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        runs = Runs(work)
        differ = 0
        for figure in figures:
            start = time.perf_counter()
            try:
                lines = figure.differences(runs)
            except Missing as exc:
                print(f"skipped  {figure.name}: {exc}")
                continue
            took = time.perf_counter() - start
            if not lines:
                print(f"same     {figure.name} ({took:.0f} s)")
                continue
            differ += 1
            for line in lines:
                print(f"differs  {line}")
            if args.write and figure.write(runs):
                print(f"written  {figure.page}")
    return 1 if differ and not args.write else 0


if __name__ == "__main__":
    sys.exit(main())
