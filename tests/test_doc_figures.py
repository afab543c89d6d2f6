"""Every figure the README, the recipes, getting-started and the results page state is what the
commands print.

Each figure of :data:`doc_figures.FIGURES` and :data:`results_figures.RESULTS` that takes less
than minutes is produced by running its commands (on the real logs where they are beside the
repository, skipped where they are not) and compared with what its page says: a change that moves
a figure fails here until the page says the new one (``python benchmarks/bench_doc_figures.py
--write`` puts them in). The optimisations, placements and benchmark tables, minutes each, are
checked by that benchmark (and a table by its own script's ``--check``).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from doc_figures import FIGURES, Figure, Missing, Runs, Table, Transcript
from results_figures import RESULTS

ALL = (*FIGURES, *RESULTS)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Runs:
    return Runs(tmp_path_factory.mktemp("figures"))


@pytest.mark.parametrize(
    "figure", [f for f in ALL if not f.slow], ids=lambda f: f.name.replace(" ", "_")
)
def test_the_page_says_what_the_commands_print(
    figure: Figure | Transcript | Table, runs: Runs
) -> None:
    try:
        differences = figure.differences(runs)
    except Missing as exc:
        pytest.skip(str(exc))
    assert not differences, "\n".join(differences)


def test_every_figure_is_found_once_in_its_page() -> None:
    """The sentences and tables themselves (a page edited so that a figure's sentence is gone
    fails here, without running anything)."""
    for figure in ALL:
        if isinstance(figure, Figure):
            figure.found()
        elif isinstance(figure, Table):
            text, start, end = figure._block()
            assert text[start:end].startswith(figure.marker), figure.name


def test_a_moved_figure_fails(tmp_path: Path) -> None:
    """The comparison itself: a page that states another figure than the command gives."""
    figure = Figure(
        "README.md", "UR5e twin: {ours} % overall efficiency", lambda _: {"ours": "1.00"}
    )
    [line] = figure.differences(Runs(tmp_path))
    assert "the commands give '1.00'" in line


def test_a_moved_table_line_fails(tmp_path: Path) -> None:
    """A table a benchmark gives: one line of it moved is named, and a line more is counted."""
    [table] = [f for f in RESULTS if isinstance(f, Table)]
    text, start, end = table._block()
    shown = text[start:end].splitlines()
    moved = Table(table.page, table.marker, lambda _: "\n".join([*shown[:-1], "| mean |"]))
    [line] = moved.differences(Runs(tmp_path))
    assert "the benchmark gives '| mean |'" in line
    longer = Table(table.page, table.marker, lambda _: "\n".join([*shown, "| more |"]))
    assert len(longer.differences(Runs(tmp_path))) == 1
    same = Table(table.page, table.marker, lambda _: "\n".join(shown))
    assert same.differences(Runs(tmp_path)) == []


def test_a_timing_placeholder_matches_any_figure_and_is_not_compared(tmp_path: Path) -> None:
    """A ``{name}`` its function does not return (a timing) is found but not compared."""
    [row] = [f for f in RESULTS if isinstance(f, Figure) and "{wall}" in f.text][:1]
    match = row.found()
    assert match.group("wall")
    timing_only = Figure(row.page, row.text, lambda _: {})
    assert timing_only.differences(Runs(tmp_path)) == []
