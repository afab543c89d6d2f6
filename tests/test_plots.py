"""Report figures: each is drawn, saved and read back.

Checked: the PNG exists, is not blank-small, has the figure's size times the DPI in pixels; the
figure has the expected axes, titles and labels; the numbers it shows (R² in titles, box medians,
cumulative energies, the Pareto front) equal values computed here independently; bad input is a
one-line KinergyError; saving is atomic and leaves no temporary file.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path
from typing import BinaryIO

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.image import imread

from kinergy.errors import KinergyError
from kinergy.report import plots

NAMES = ["base", "shoulder", "elbow", "wrist1", "wrist2", "wrist3"]


def signals(seed: int, n: int = 6, samples: int = 800) -> tuple[np.ndarray, ...]:
    """Time, a smooth 'measured' signal per joint and a noisy 'prediction' of it."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 10.0, samples)
    amp = rng.uniform(1.0, 50.0, n)
    freq = rng.uniform(0.3, 2.0, n)
    y = amp * np.sin(np.outer(t, freq) + rng.uniform(0, np.pi, n))
    p = y + rng.normal(0.0, 0.1, (samples, n)) * amp
    return t, y, p


def r2_reference(y: np.ndarray, p: np.ndarray) -> list[float]:
    """R² per column, written out: 1 - sum of squared residuals / (N * variance)."""
    return [
        1.0 - float(np.sum((y[:, j] - p[:, j]) ** 2)) / (y.shape[0] * float(np.var(y[:, j])))
        for j in range(y.shape[1])
    ]


def saved(fig: Figure, path: Path) -> np.ndarray:
    """Save through plots.save, check the file, return the image read back."""
    out = plots.save(fig, path)
    assert out == path
    assert path.is_file()
    assert path.stat().st_size > 10_000
    image = imread(path)
    w, h = fig.get_size_inches() * plots.DPI
    assert abs(image.shape[1] - w) <= 1
    assert abs(image.shape[0] - h) <= 1
    return image


# -- time_series -------------------------------------------------------------------------------


def test_time_series_six_joints(tmp_path: Path) -> None:
    t, y, p = signals(1)
    fig = plots.time_series(
        t,
        y,
        p,
        joint_names=NAMES,
        quantity="Joint torque",
        unit="N m",
        measured_label="target_moment",
        predicted_label="model",
    )
    image = saved(fig, tmp_path / "torque.png")
    assert image.shape[:2] == (880, 1210)  # 11 x 8 in at 110 dpi

    axes, below = fig.axes[:6], fig.axes[6:]
    assert len(fig.axes) == 12  # each joint with its residual panel below it
    for ax, name, r2 in zip(axes, NAMES, r2_reference(y, p), strict=True):
        assert name in ax.get_title()
        assert f"R² = {r2:.4f}" in ax.get_title()
        assert ax.get_xlim() == (t[0], t[-1])
        assert len(ax.get_lines()) == 2
    # y labels on the left column, time on the bottom row, axes share x
    assert [ax.get_ylabel() for ax in axes] == ["Joint torque [N m]", ""] * 3
    assert [ax.get_xlabel() for ax in below] == [""] * 4 + ["Time [s]"] * 2
    assert axes[0].get_shared_x_axes().joined(axes[0], below[5])
    for res, j in zip(below, range(6), strict=True):
        assert np.array_equal(res.get_lines()[0].get_ydata(), y[:, j] - p[:, j])
    # one legend for the figure, none per axes
    assert len(fig.legends) == 1
    legend = [x.get_text() for x in fig.legends[0].get_texts()]
    assert legend == ["target_moment", "model", "target_moment - model"]
    assert all(ax.get_legend() is None for ax in fig.axes)
    assert isinstance(fig.canvas, FigureCanvasAgg)


def test_time_series_odd_joint_count_keeps_time_labels(tmp_path: Path) -> None:
    t, y, p = signals(2, n=5)
    fig = plots.time_series(t, y, p, joint_names=NAMES[:5], quantity="Motor current", unit="A")
    saved(fig, tmp_path / "current.png")
    axes = fig.axes
    assert len(axes) == 10  # 5 joints and their residuals; the spare cell of the grid left empty
    # both columns end with a residual panel whose time axis is labelled and shown
    assert [ax.get_xlabel() for ax in axes[5:]] == ["", "", "", "Time [s]", "Time [s]"]
    for ax in axes[8:]:
        assert all(lab.get_visible() for lab in ax.get_xticklabels())
    legend = [x.get_text() for x in fig.legends[0].get_texts()]
    assert legend == ["measured", "model", "measured - model"]
    # the residual panel holds measured - predicted
    _, y, p = signals(2, n=5)
    assert np.array_equal(axes[5].get_lines()[0].get_ydata(), y[:, 0] - p[:, 0])


def test_time_series_single_joint_and_constant_signal() -> None:
    t = np.linspace(0.0, 1.0, 50)
    y = np.full((50, 1), 3.0)  # SS_tot = 0: R² undefined
    fig = plots.time_series(t, y, y + 0.1, joint_names=["j1"], quantity="Torque", unit="N m")
    assert len(fig.axes) == 2  # the joint and its residual
    assert fig.axes[0].get_title() == "j1  (R² = n/a)"


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"predicted": np.zeros((800, 5))}, "predicted: expected shape (800, 6)"),
        ({"measured": np.zeros((799, 6))}, "measured: expected shape (800, 6)"),
        ({"joint_names": NAMES[:5]}, "measured: expected shape (800, 5)"),
        ({"joint_names": "base"}, "joint_names"),
        ({"joint_names": []}, "joint_names: empty"),
        ({"t": np.zeros((800, 1))}, "t: expected shape (N,)"),
        ({"t": np.r_[np.linspace(0, 1, 799), 0.5]}, "t: time stamps must increase"),
        ({"measured": np.full((800, 6), np.nan)}, "measured: contains NaN"),
    ],
)
def test_time_series_bad_input(change: dict, message: str) -> None:
    t, y, p = signals(3)
    args = {"t": t, "measured": y, "predicted": p, "joint_names": NAMES} | change
    with pytest.raises(KinergyError) as info:
        plots.time_series(
            args["t"],
            args["measured"],
            args["predicted"],
            joint_names=args["joint_names"],
            quantity="Torque",
            unit="N m",
        )
    assert message in str(info.value)
    assert "\n" not in str(info.value)


# -- error_boxplot -----------------------------------------------------------------------------


def test_error_boxplot_two_sets(tmp_path: Path) -> None:
    rng = np.random.default_rng(4)
    scale = np.array([0.4, 0.4, 0.07, 0.02, 0.01, 0.002])
    sets = {
        "test A": rng.normal(0.0, 1.0, (1500, 6)) * scale,
        "test B": rng.normal(0.05, 1.3, (900, 6)) * scale,
    }
    fig = plots.error_boxplot(sets, joint_names=NAMES, quantity="Torque", unit="N m")
    saved(fig, tmp_path / "box.png")

    axes = fig.axes
    assert [ax.get_title() for ax in axes] == ["test A", "test B"]
    assert axes[0].get_ylabel() == "Torque error [N m]"
    assert fig.get_suptitle() == "Torque error per joint"
    assert axes[0].get_shared_y_axes().joined(axes[0], axes[1])
    for ax, err in zip(axes, sets.values(), strict=True):
        assert [lab.get_text() for lab in ax.get_xticklabels()] == NAMES
        # the median lines sit at the sample medians, joint by joint
        medians = [
            np.asarray(line.get_ydata())[0]
            for line in ax.get_lines()
            if line.get_linewidth() == 1.5
        ]
        assert np.allclose(medians, np.median(err, axis=0))


def test_error_boxplot_title_reads_right() -> None:
    """The report passes the signal's name ("current"): the title says "error" once."""
    sets = {"test A": np.random.default_rng(5).normal(0.0, 1.0, (50, 6))}
    fig = plots.error_boxplot(sets, joint_names=NAMES, quantity="current", unit="A")
    assert fig.get_suptitle() == "Current error per joint"
    assert fig.axes[0].get_ylabel() == "Current error [A]"


@pytest.mark.parametrize(
    ("sets", "message"),
    [
        ({}, "errors_by_set: no data set"),
        (
            {"A": np.zeros((10, 6)), "B": np.zeros((10, 5))},
            "errors_by_set['B']: expected shape (N, 6)",
        ),
        ({"A": np.zeros((0, 6))}, "errors_by_set['A']: no samples"),
        ({"A": np.full((10, 6), np.inf)}, "errors_by_set['A']: contains NaN or infinite"),
    ],
)
def test_error_boxplot_bad_input(sets: dict, message: str) -> None:
    with pytest.raises(KinergyError, match=re.escape(message)):
        plots.error_boxplot(sets, joint_names=NAMES, quantity="Current", unit="A")


# -- power_energy ------------------------------------------------------------------------------


def test_power_energy_integrates_each_joint(tmp_path: Path) -> None:
    rng = np.random.default_rng(5)
    t = np.sort(rng.uniform(0.0, 8.0, 600))
    t[0], t[-1] = 0.0, 8.0
    # power linear in time: the trapezoid rule is exact, E_j(T) = a_j T + b_j T^2 / 2
    a = rng.uniform(-5.0, 60.0, 6)
    b = rng.uniform(-2.0, 4.0, 6)
    power = a + np.outer(t, b)
    expected = a * 8.0 + b * 32.0
    fig = plots.power_energy(t, power, joint_names=NAMES)
    saved(fig, tmp_path / "power.png")

    ax_p, ax_e = fig.axes
    assert ax_p.get_ylabel() == "Power [W]"
    assert ax_e.get_ylabel() == "Energy [J]"
    assert ax_e.get_xlabel() == "Time [s]"
    assert ax_p.get_shared_x_axes().joined(ax_p, ax_e)
    assert f"total {expected.sum():.1f} J" in ax_e.get_title()
    energy_lines = [x for x in ax_e.get_lines() if not str(x.get_label()).startswith("_")]
    assert len(energy_lines) == 6
    for line, name, e in zip(energy_lines, NAMES, expected, strict=True):
        assert line.get_label() == f"{name}: {e:.1f} J"
        energy = np.asarray(line.get_ydata())
        assert energy[0] == 0.0
        assert energy[-1] == pytest.approx(e, rel=1e-12, abs=1e-9)
    labels = [x.get_text() for x in fig.legends[0].get_texts()]
    assert labels == [f"{name}: {e:.1f} J" for name, e in zip(NAMES, expected, strict=True)]


def test_power_energy_bad_input() -> None:
    t = np.linspace(0.0, 1.0, 20)
    with pytest.raises(KinergyError, match=r"power: expected shape \(20, 6\), got \(20, 3\)"):
        plots.power_energy(t, np.zeros((20, 3)), joint_names=NAMES)
    with pytest.raises(KinergyError, match="t: need at least 2 samples"):
        plots.power_energy(t[:1], np.zeros((1, 6)), joint_names=NAMES)


# -- energy_breakdown --------------------------------------------------------------------------


def test_energy_breakdown_parts_and_total(tmp_path: Path) -> None:
    rng = np.random.default_rng(6)
    t = np.linspace(0.0, 6.0, 900)
    # each part a constant plus a sine with whole periods over [0, 6]: E = c T (up to the rule's error)
    c = {"inertial": 12.0, "gravity": -4.0, "friction": 25.0, "copper": 9.0}
    parts = {k: v + rng.uniform(1, 20) * np.sin(2 * np.pi * t / 3.0) for k, v in c.items()}
    fig = plots.energy_breakdown(t, parts)
    saved(fig, tmp_path / "breakdown.png")

    (ax,) = fig.axes
    assert ax.get_xlabel() == "Time [s]"
    assert ax.get_ylabel() == "Energy [J]"
    final = {
        str(x.get_label()).split(":")[0]: np.asarray(x.get_ydata())[-1] for x in ax.get_lines()
    }
    for k, v in c.items():
        assert final[k] == pytest.approx(6.0 * v, abs=1e-3)
    total = 6.0 * sum(c.values())
    assert final["total"] == pytest.approx(total, abs=1e-3)
    legend = ax.get_legend()
    assert legend is not None
    texts = [x.get_text() for x in legend.get_texts()]
    assert texts[:4] == [f"{k}: {6.0 * v:.1f} J" for k, v in c.items()]
    assert texts[-1] == f"total: {total:.1f} J"


def test_energy_breakdown_bad_input() -> None:
    t = np.linspace(0.0, 1.0, 20)
    with pytest.raises(
        KinergyError, match=r"parts\['gravity'\]: expected shape \(20,\), got \(19,\)"
    ):
        plots.energy_breakdown(t, {"inertial": np.zeros(20), "gravity": np.zeros(19)})
    with pytest.raises(KinergyError, match="parts: no energy part"):
        plots.energy_breakdown(t, {})


# -- pareto ------------------------------------------------------------------------------------


def test_pareto_front_and_marked_points(tmp_path: Path) -> None:
    rng = np.random.default_rng(7)
    times = rng.uniform(3.0, 9.0, 80)
    energies = 300.0 / times + rng.uniform(0.0, 30.0, 80)
    marked = {"as recorded": (4.0, 110.0), "optimised": (4.0, 80.0)}
    fig = plots.pareto(times, energies, marked=marked)
    saved(fig, tmp_path / "pareto.png")

    (ax,) = fig.axes
    assert ax.get_xlabel() == "Cycle time [s]"
    assert ax.get_ylabel() == "Energy [J]"
    # the front: points no other point beats in both time and energy, by brute force
    dominated = [
        any(times[k] <= times[i] and energies[k] < energies[i] for k in range(80))
        or any(times[k] < times[i] and energies[k] <= energies[i] for k in range(80))
        for i in range(80)
    ]
    front = np.flatnonzero(~np.asarray(dominated))
    front = front[np.argsort(times[front])]
    (step,) = [line for line in ax.get_lines() if line.get_label() == "Pareto front"]
    assert np.allclose(step.get_xdata(), times[front])
    assert np.allclose(step.get_ydata(), energies[front])
    notes = [c.get_text() for c in ax.texts]
    assert notes == ["as recorded\n4.00 s, 110.0 J", "optimised\n4.00 s, 80.0 J"]


def test_pareto_without_marks_and_bad_input() -> None:
    fig = plots.pareto([1.0, 2.0], [5.0, 3.0])
    assert len(fig.axes) == 1
    assert len(fig.axes[0].texts) == 0
    with pytest.raises(KinergyError, match=r"energies: expected shape \(3,\)"):
        plots.pareto([1.0, 2.0, 3.0], [1.0, 2.0])
    with pytest.raises(KinergyError, match="cycle_times: no candidate"):
        plots.pareto([], [])
    with pytest.raises(KinergyError, match=r"marked\['x'\]: expected \(cycle time, energy\)"):
        plots.pareto([1.0], [1.0], marked={"x": (1.0, 2.0, 3.0)})  # type: ignore[dict-item]


# -- save --------------------------------------------------------------------------------------


def test_save_is_atomic_and_overwrites(tmp_path: Path) -> None:
    t, _, p = signals(8)
    fig = plots.power_energy(t, np.abs(p), joint_names=NAMES)
    target = tmp_path / "new" / "dir" / "power.png"
    saved(fig, target)
    first = target.read_bytes()
    fig.axes[0].set_title("changed")
    saved(fig, target)  # the figure stays usable and the file is replaced
    assert target.read_bytes() != first
    assert sorted(x.name for x in target.parent.iterdir()) == ["power.png"]


def test_save_failure_is_one_line_and_leaves_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    fig = plots.pareto([1.0, 2.0], [2.0, 1.0])
    with pytest.raises(KinergyError, match="cannot write") as info:
        plots.save(fig, blocker / "out.png")
    assert "\n" not in str(info.value)

    # a write that fails half way leaves neither the target nor the temporary file
    def half_write(fh: BinaryIO, **kwargs: object) -> None:
        fh.write(b"\x89PNG half")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(fig, "savefig", half_write)
    with pytest.raises(KinergyError, match=r"a\.png: cannot write \(No space left on device\)"):
        plots.save(fig, tmp_path / "a.png")
    assert sorted(x.name for x in tmp_path.iterdir()) == ["file"]


def test_no_pyplot_state(tmp_path: Path) -> None:
    code = (
        "import sys, numpy as np\n"
        "from kinergy.report import plots\n"
        "t = np.linspace(0, 1, 10)\n"
        "plots.save(plots.power_energy(t, np.ones((10, 2)), joint_names=['a', 'b']), sys.argv[1])\n"
        "assert 'matplotlib.pyplot' not in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code, str(tmp_path / "p.png")], check=True)
    assert (tmp_path / "p.png").stat().st_size > 10_000
