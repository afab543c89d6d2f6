"""Every figure the README, the recipes and getting-started state is what the commands print.

Each figure of :data:`doc_figures.FIGURES` that takes less than minutes is produced by running its
commands (on the real logs where they are beside the repository, skipped where they are not) and
compared with what its page says: a change that moves a figure fails here until the page says
the new one (``python benchmarks/bench_doc_figures.py --write`` puts them in). The optimisations
and placements, minutes each, are checked by that benchmark.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from doc_figures import FIGURES, Figure, Missing, Runs, Transcript


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Runs:
    return Runs(tmp_path_factory.mktemp("figures"))


@pytest.mark.parametrize(
    "figure", [f for f in FIGURES if not f.slow], ids=lambda f: f.name.replace(" ", "_")
)
def test_the_page_says_what_the_commands_print(figure: Figure | Transcript, runs: Runs) -> None:
    try:
        differences = figure.differences(runs)
    except Missing as exc:
        pytest.skip(str(exc))
    assert not differences, "\n".join(differences)


def test_every_figure_is_found_once_in_its_page() -> None:
    """The sentences themselves (a page edited so that a figure's sentence is gone fails here,
    without running anything)."""
    for figure in FIGURES:
        if isinstance(figure, Figure):
            figure.found()


def test_a_moved_figure_fails(tmp_path: Path) -> None:
    """The comparison itself: a page that states another figure than the command gives."""
    figure = Figure(
        "README.md", "UR5e twin: {ours} % overall efficiency", lambda _: {"ours": "1.00"}
    )
    [line] = figure.differences(Runs(tmp_path))
    assert "the commands give '1.00'" in line
