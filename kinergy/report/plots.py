"""Figures of a model's accuracy and of the energy a motion draws: plain functions over arrays.

Each function takes numpy arrays (plus names and units) and returns a :class:`matplotlib.figure.Figure`
drawn on the non-interactive Agg canvas; nothing touches pyplot's global state, so the figures are
safe to build in scripts, servers and tests and are freed like any other object. :func:`save`
writes one as a PNG atomically.

==========================  ==================================================================
:func:`time_series`         measured vs predicted per joint over time, R² in each title, residuals
                            (UR5e Figs 8-9 for torques, Figs 11-12 for currents)
:func:`error_boxplot`       box plots of the errors per joint, one panel per data set
                            (UR5e Figs 10 and 13)
:func:`power_energy`        electrical power and cumulative energy per joint (UR5e Figs 14-15)
:func:`energy_breakdown`    cumulative energy of the inertial, gravity, friction and copper parts
                            and their total (framework Fig. 4)
:func:`pareto`              energy against cycle time, the Pareto front and named motions
:func:`supply_power`        the arm's supply power over time, predicted against measured, with
                            the energy of each
==========================  ==================================================================
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_trapezoid

from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.files import atomic_write
from kinergy.identification.metrics import r_squared

__all__ = [
    "DPI",
    "energy_breakdown",
    "error_boxplot",
    "pareto",
    "power_energy",
    "save",
    "supply_power",
    "time_series",
    "timing_pareto",
]


DPI = 110
"""Resolution :func:`save` writes at, dots per inch: a 11 x 8 in figure is 1210 x 880 px."""

_BOX_STYLE: dict[str, Any] = {
    "medianprops": {"color": "black", "linewidth": 1.5},
    "whiskerprops": {"color": "0.2"},
    "capprops": {"color": "0.2"},
    "flierprops": {"marker": ".", "markersize": 3.0, "markerfacecolor": "0.3",
                   "markeredgecolor": "none", "alpha": 0.5},
}  # fmt: skip
"""Box-plot artists' style besides the box colour (:func:`error_boxplot`)."""

# Font sizes, points. Set on every artist rather than through rcParams, which are global.
_TITLE = 11
_SUPTITLE = 13
_LABEL = 10
_TICK = 9
_LEGEND = 9

_MEASURED: dict[str, Any] = {"color": "tab:green", "linewidth": 1.6, "alpha": 0.85}
_PREDICTED: dict[str, Any] = {"color": "tab:orange", "linewidth": 1.0, "linestyle": "--"}
_RESIDUAL: dict[str, Any] = {"color": "tab:purple", "linewidth": 0.8}

# Colours of the energy parts, so a part has the same colour in every figure.
_PART_COLOURS = {
    "inertial": "tab:blue",
    "gravity": "tab:green",
    "friction": "tab:red",
    "copper": "tab:orange",
}


# -- validation at the boundary -----------------------------------------------------------------


def _vector(x: ArrayLike, name: str) -> Array:
    """``x`` as a finite float vector, shape (N,)."""
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise KinergyError(f"{name}: not an array of numbers ({exc})") from None
    if a.ndim != 1:
        raise KinergyError(f"{name}: expected shape (N,), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise KinergyError(f"{name}: contains NaN or infinite values")
    return a


def _time(t: ArrayLike) -> Array:
    """Time stamps, s, shape (N,) with N >= 2 and strictly increasing."""
    ts = _vector(t, "t")
    if ts.size < 2:
        raise KinergyError(f"t: need at least 2 samples, got {ts.size}")
    if np.any(np.diff(ts) <= 0):
        i = int(np.argmax(np.diff(ts) <= 0))
        raise KinergyError(
            f"t: time stamps must increase strictly (sample {i + 1}: {ts[i + 1]:g} s)"
        )
    return ts


def _matrix(x: ArrayLike, name: str, rows: int | None, cols: int) -> Array:
    """``x`` as a finite float array of shape (rows, cols); a vector counts as one column."""
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise KinergyError(f"{name}: not an array of numbers ({exc})") from None
    if a.ndim == 1 and cols == 1:
        a = a[:, None]
    expected = f"({rows if rows is not None else 'N'}, {cols})"
    if a.ndim != 2 or a.shape[1] != cols or (rows is not None and a.shape[0] != rows):
        raise KinergyError(f"{name}: expected shape {expected}, got {a.shape}")
    if a.shape[0] == 0:
        raise KinergyError(f"{name}: no samples")
    if not np.all(np.isfinite(a)):
        raise KinergyError(f"{name}: contains NaN or infinite values")
    return a


def _names(joint_names: Sequence[str]) -> list[str]:
    """The joint names as a non-empty list of strings."""
    if isinstance(joint_names, str):
        raise KinergyError("joint_names: expected a sequence of names, got one string")
    names = [str(s) for s in joint_names]
    if not names:
        raise KinergyError("joint_names: empty")
    return names


# -- layout helpers ------------------------------------------------------------------------------


def _joint_signals(
    t: ArrayLike, joint_names: Sequence[str], **signals: ArrayLike
) -> tuple[list[str], Array, list[Array]]:
    """Checked joint names (n), times ``(N,)`` and each signal as ``(N, n)``, in keyword order."""
    names = _names(joint_names)
    ts = _time(t)
    return names, ts, [_matrix(v, key, ts.size, len(names)) for key, v in signals.items()]


def _figure(width: float, height: float) -> Figure:
    """A figure on its own Agg canvas with constrained layout (nothing clipped, no overlaps)."""
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _style(ax: Axes) -> None:
    ax.tick_params(labelsize=_TICK)
    ax.grid(True, linewidth=0.5, alpha=0.4)


def _ncols(n: int) -> int:
    """Columns of the joint grid: one for a single joint, two up to eight, then three."""
    return 1 if n == 1 else 2 if n <= 8 else 3


def _joint_grid(fig: Figure, n: int) -> list[Axes]:
    """``n`` axes on a grid of two columns (one for a single joint), sharing the x axis.

    The grid is filled row by row; the spare cell of an odd ``n`` is removed, and the axis above
    it gets its x tick labels back.
    """
    ncols = _ncols(n)
    nrows = math.ceil(n / ncols)
    grid = np.atleast_2d(fig.subplots(nrows, ncols, sharex=True, squeeze=False))
    axes = list(grid.ravel())
    for ax in axes[n:]:
        fig.delaxes(ax)
    axes = axes[:n]
    for col in range(ncols):
        column = [axes[i] for i in range(col, n, ncols)]
        if column:
            bottom = column[-1]
            bottom.xaxis.set_tick_params(labelbottom=True)
            bottom.set_xlabel("Time [s]", fontsize=_LABEL)
    return axes


def _residual_grid(fig: Figure, n: int) -> tuple[list[Axes], list[Axes]]:
    """``n`` joint panels on :func:`_joint_grid`'s grid, each with a residual panel a third of
    its height below it sharing its time axis: the joint panels first in ``fig.axes`` (joint
    order), then the residual panels; the time axis is labelled on each column's last one."""
    ncols = _ncols(n)
    nrows = math.ceil(n / ncols)
    outer = fig.add_gridspec(nrows, ncols)
    cells = [outer[j // ncols, j % ncols].subgridspec(2, 1, height_ratios=[3, 1]) for j in range(n)]
    axes: list[Axes] = []
    for cell in cells:
        axes.append(fig.add_subplot(cell[0], sharex=axes[0] if axes else None))
    below = [fig.add_subplot(cell[1], sharex=ax) for cell, ax in zip(cells, axes, strict=True)]
    for j, (ax, res) in enumerate(zip(axes, below, strict=True)):
        ax.xaxis.set_tick_params(labelbottom=False)
        last = j + ncols >= n
        res.xaxis.set_tick_params(labelbottom=last)
        if last:
            res.set_xlabel("Time [s]", fontsize=_LABEL)
    return axes, below


def _grid_size(n: int) -> tuple[float, float]:
    """Figure size, inches, for ``n`` joint panels: 11 x 8 for six."""
    ncols = _ncols(n)
    nrows = math.ceil(n / ncols)
    width = 7.0 if ncols == 1 else 11.0 if ncols == 2 else 14.0
    return width, 2.4 * nrows + 0.8


# -- figures ----------------------------------------------------------------------------------


def time_series(
    t: ArrayLike,
    measured: ArrayLike,
    predicted: ArrayLike,
    *,
    joint_names: Sequence[str],
    quantity: str,
    unit: str,
    measured_label: str = "measured",
    predicted_label: str = "model",
    band: ArrayLike | None = None,
) -> Figure:
    """Measured against predicted signal per joint over time, with R² per joint and each
    joint's residual ``measured - predicted`` in a panel below it; with ``band``, the
    prediction's 95 % band shaded about it (and about zero under the residual).

    One panel per joint (a 3 x 2 grid for six joints) sharing the time axis, the measured signal
    solid and the prediction dashed on top of it, as in UR5e Figs 8-9 (``target_moment`` against
    the inverse dynamic model, eq 2) and Figs 11-12 (measured against estimated motor current,
    eq 18). Each title carries the joint name and the coefficient of determination
    ``R² = 1 - SS_res / SS_tot`` of that joint (UR5e Tables V and VII), to four decimals. Below
    each joint's panel, on the same time axis, its residual (measured - predicted): where the
    two lines lie on top of each other, the residual shows what they hide.

    Parameters
    ----------
    t : array_like, shape (N,)
        Time stamps, s, strictly increasing.
    measured, predicted : array_like, shape (N, n)
        The signal per joint, in ``unit``.
    joint_names : sequence of str, length n
    quantity : str
        What is plotted, e.g. ``"Joint torque"``; used in the y labels and the figure title.
    unit : str
        Its unit, e.g. ``"N m"`` or ``"A"``.
    measured_label, predicted_label : str
        Legend entries of the two signals.
    band : array_like, shape (N, n), optional
        The prediction band's half-width per sample (``validate``'s 95 % band), in ``unit``.

    Returns
    -------
    matplotlib.figure.Figure
        ``2 n`` axes: the ``n`` joint panels in joint order, then their ``n`` residual panels.

    Raises
    ------
    KinergyError
        If the shapes disagree, the number of names is not ``n``, ``t`` does not increase or a
        value is not finite.
    """
    names, ts, (y, p) = _joint_signals(t, joint_names, measured=measured, predicted=predicted)
    n = len(names)
    r2 = r_squared(y, p)
    half = None if band is None else _matrix(band, "band", len(ts), n)

    fig = _figure(*_grid_size(n))
    axes, below = _residual_grid(fig, n)
    for j, (ax, res) in enumerate(zip(axes, below, strict=True)):
        if half is not None:
            low, high = p[:, j] - half[:, j], p[:, j] + half[:, j]
            ax.fill_between(ts, low, high, color="C1", alpha=0.25, linewidth=0, label="95 %")
            res.fill_between(ts, -half[:, j], half[:, j], color="C1", alpha=0.25, linewidth=0)
        ax.plot(ts, y[:, j], label=measured_label, **_MEASURED)
        ax.plot(ts, p[:, j], label=predicted_label, **_PREDICTED)
        res.plot(ts, y[:, j] - p[:, j], label=f"{measured_label} - {predicted_label}", **_RESIDUAL)
        res.axhline(0.0, color="0.5", linewidth=0.6)
        score = "n/a" if np.isnan(r2[j]) else f"{r2[j]:.4f}"
        ax.set_title(f"{names[j]}  (R² = {score})", fontsize=_TITLE)
        if j % _ncols(n) == 0:
            ax.set_ylabel(f"{quantity} [{unit}]", fontsize=_LABEL)
            res.set_ylabel(f"residual [{unit}]", fontsize=_TICK)
        ax.set_xlim(ts[0], ts[-1])
        _style(ax)
        _style(res)
    handles, labels = axes[0].get_legend_handles_labels()
    more, more_labels = below[0].get_legend_handles_labels()
    handles, labels = [*handles, *more], [*labels, *more_labels]
    fig.legend(
        handles, labels, loc="outside lower center", ncols=3, fontsize=_LEGEND, frameon=False
    )
    fig.suptitle(f"{quantity}: {measured_label} vs {predicted_label}", fontsize=_SUPTITLE)
    return fig


def error_boxplot(
    errors_by_set: Mapping[str, ArrayLike],
    *,
    joint_names: Sequence[str],
    quantity: str,
    unit: str,
) -> Figure:
    """Box plots of the prediction errors per joint, one panel per data set.

    As UR5e Figs 10 (torque errors) and 13 (current errors): the box spans the first to third
    quartile with the median marked, the whiskers reach the most extreme sample within 1.5
    inter-quartile ranges, and samples beyond are drawn as small dots. The panels (e.g. the
    identification run "test A" and the unseen run "test B") sit side by side and share the
    y axis, so the sets compare at a glance.

    Parameters
    ----------
    errors_by_set : mapping of str to array_like, shape (N_s, n)
        Error samples (measured - predicted) per set, in ``unit``; the sets may have different
        numbers of samples but the same joints.
    joint_names : sequence of str, length n
    quantity : str
        What the errors are of, e.g. ``"torque"``: the title reads ``"Torque error per joint"``
        and the y label ``"Torque error [unit]"`` (the first letter capitalised).
    unit : str

    Returns
    -------
    matplotlib.figure.Figure
        One axes per set, titled with the set's name, in the mapping's order.

    Raises
    ------
    KinergyError
        If there is no set, a set is not (N_s, n), or holds non-finite values.
    """
    names = _names(joint_names)
    n = len(names)
    if not errors_by_set:
        raise KinergyError("errors_by_set: no data set given")
    sets = {str(k): _matrix(v, f"errors_by_set[{k!r}]", None, n) for k, v in errors_by_set.items()}

    what = quantity[:1].upper() + quantity[1:]  # "torque" -> "Torque error per joint"
    k = len(sets)
    width = min(max((1.2 + 0.75 * n) * k, 7.0), 18.0)
    fig = _figure(width, 5.0)
    axes = fig.subplots(1, k, sharey=True, squeeze=False)[0]
    colours = [f"C{i}" for i in range(k)]
    for i, (ax, (name, err)) in enumerate(zip(axes, sets.items(), strict=True)):
        ax.axhline(0.0, color="0.5", linewidth=0.8, zorder=0)
        ax.boxplot(
            [err[:, j] for j in range(n)],
            tick_labels=names,
            patch_artist=True,
            widths=0.6,
            boxprops={"facecolor": colours[i], "alpha": 0.45, "edgecolor": "0.2"},
            **_BOX_STYLE,
        )
        ax.set_title(name, fontsize=_TITLE)
        ax.set_xlabel("Joint", fontsize=_LABEL)
        if i == 0:
            ax.set_ylabel(f"{what} error [{unit}]", fontsize=_LABEL)
        _style(ax)
        ax.grid(False, axis="x")
        if max(len(s) for s in names) * n > 48:
            ax.tick_params(axis="x", labelrotation=30)
    fig.suptitle(f"{what} error per joint", fontsize=_SUPTITLE)
    return fig


def power_energy(t: ArrayLike, power: ArrayLike, *, joint_names: Sequence[str]) -> Figure:
    """Electrical power per joint over time and the energy it adds up to (UR5e Figs 14-15).

    The energy is the signed cumulative trapezoidal integral ``E_j(t) = int_0^t W_j dt``
    (UR5e eq 26), so braking phases, where power flows back to the bus, lower it. The legend
    gives each joint's energy over the whole motion, the lower title the total.

    Parameters
    ----------
    t : array_like, shape (N,)
        Time stamps, s, strictly increasing.
    power : array_like, shape (N, n)
        Electrical power per motor, W, positive when drawn from the supply (UR5e eq 23).
    joint_names : sequence of str, length n

    Returns
    -------
    matplotlib.figure.Figure
        Two axes sharing the time axis: power [W] on top, cumulative energy [J] below.

    Raises
    ------
    KinergyError
        If the shapes disagree, the number of names is not ``n``, ``t`` does not increase or a
        value is not finite.
    """
    names, ts, (w,) = _joint_signals(t, joint_names, power=power)
    n = len(names)
    e = cumulative_trapezoid(w, ts, axis=0, initial=0.0)

    fig = _figure(11.0, 7.5)
    ax_p, ax_e = fig.subplots(2, 1, sharex=True)
    for j in range(n):
        colour = f"C{j % 10}"
        ax_p.plot(ts, w[:, j], color=colour, linewidth=1.0)
        ax_e.plot(ts, e[:, j], color=colour, linewidth=1.5, label=f"{names[j]}: {e[-1, j]:.1f} J")
    for ax in (ax_p, ax_e):
        ax.axhline(0.0, color="0.5", linewidth=0.8, zorder=0)
        ax.set_xlim(ts[0], ts[-1])
        _style(ax)
    ax_p.set_title("Electrical power per joint", fontsize=_TITLE)
    ax_p.set_ylabel("Power [W]", fontsize=_LABEL)
    ax_e.set_title(f"Cumulative electrical energy (total {e[-1].sum():.1f} J)", fontsize=_TITLE)
    ax_e.set_ylabel("Energy [J]", fontsize=_LABEL)
    ax_e.set_xlabel("Time [s]", fontsize=_LABEL)
    fig.legend(
        loc="outside right center",
        fontsize=_LEGEND,
        title="Joint: energy",
        title_fontsize=_LEGEND,
        frameon=False,
    )
    return fig


def supply_power(
    t: ArrayLike,
    predicted: ArrayLike,
    *,
    energy: float,
    measured: ArrayLike | None = None,
    measured_energy: float | None = None,
    standing: float = 0.0,
    band: ArrayLike | None = None,
) -> Figure:
    """The power the arm draws from its supply over time, predicted (the bus model plus the
    standing draw, :mod:`kinergy.drives.bus`) against measured (``actual_robot_voltage x
    actual_robot_current``), the legend giving the energy of each over the whole motion; with
    ``band``, the prediction's 95 % band shaded about it.

    Parameters
    ----------
    t : array_like, shape (N,)
        Time stamps, s, strictly increasing (the samples plotted: a long log's every k-th).
    predicted : array_like, shape (N,)
        W.
    energy : float
        The predicted supply energy of the whole motion, J (from every sample, not the plotted).
    measured : array_like, shape (N,), optional
        W.
    measured_energy : float, optional
        J, with ``measured``.
    standing : float
        The model's standing draw, W, drawn as a line where it is above 0.
    band : array_like, shape (N,), optional
        The 95 % band's half-width per sample, W (a model with parameter errors).

    Raises
    ------
    KinergyError
        If the shapes disagree, ``t`` does not increase or a value is not finite.
    """
    ts = _time(t)
    pred = _vector(predicted, "predicted")
    if pred.size != ts.size:
        raise KinergyError(f"predicted has {pred.size} samples, t has {ts.size}")
    fig = _figure(11.0, 4.5)
    ax = fig.subplots()
    if measured is not None:
        meas = _vector(measured, "measured")
        if meas.size != ts.size:
            raise KinergyError(f"measured has {meas.size} samples, t has {ts.size}")
        label = "measured" + ("" if measured_energy is None else f": {measured_energy:.1f} J")
        ax.plot(ts - ts[0], meas, label=label, **_MEASURED)
    if band is not None:
        half = _vector(band, "band")
        if half.size != ts.size:
            raise KinergyError(f"band has {half.size} samples, t has {ts.size}")
        ax.fill_between(ts - ts[0], pred - half, pred + half, color="C1", alpha=0.25,
                        linewidth=0, label="predicted: 95 % band")  # fmt: skip
    ax.plot(ts - ts[0], pred, label=f"predicted: {energy:.1f} J", **_PREDICTED)
    if standing > 0.0:
        ax.axhline(standing, color="0.5", linewidth=0.8, linestyle=":", zorder=0,
                   label=f"standing draw {standing:.3g} W")  # fmt: skip
    ax.set_xlim(0.0, ts[-1] - ts[0] if ts.size > 1 else 1.0)
    ax.set_ylim(bottom=0.0)
    _style(ax)
    ax.set_title("Power drawn from the arm's supply", fontsize=_TITLE)
    ax.set_ylabel("Power [W]", fontsize=_LABEL)
    ax.set_xlabel("Time from the first sample [s]", fontsize=_LABEL)
    ax.legend(loc="upper right", fontsize=_LEGEND, framealpha=0.9)
    return fig


def energy_breakdown(t: ArrayLike, parts: Mapping[str, ArrayLike]) -> Figure:
    """Where the electrical energy goes over time: one line per part and their total.

    Each part's power is integrated (signed, cumulative trapezoid) into its energy over time and
    drawn as a line; the total, the sum of the parts, is the thick black line, as in framework
    Fig. 4. Lines rather than stacked areas, because a part can be negative (gravity while the
    arm comes down, inertia while it brakes). With the parts of
    :func:`kinergy.accounting.energy.energy` (``inertial``, ``gravity``, ``friction``,
    ``copper``) the total is the electrical energy of UR5e eq 26.

    Parameters
    ----------
    t : array_like, shape (N,)
        Time stamps, s, strictly increasing.
    parts : mapping of str to array_like, shape (N,)
        Power of each part summed over the joints, W.

    Returns
    -------
    matplotlib.figure.Figure
        One axes: energy [J] against time [s]; the legend gives each part's final energy.

    Raises
    ------
    KinergyError
        If there is no part, a part is not (N,), ``t`` does not increase or a value is not finite.
    """
    ts = _time(t)
    if not parts:
        raise KinergyError("parts: no energy part given")
    power = {str(k): _vector(v, f"parts[{k!r}]") for k, v in parts.items()}
    for k, v in power.items():
        if v.size != ts.size:
            raise KinergyError(f"parts[{k!r}]: expected shape ({ts.size},), got {v.shape}")
    energy = {k: cumulative_trapezoid(v, ts, initial=0.0) for k, v in power.items()}
    total = np.sum(list(energy.values()), axis=0)

    fig = _figure(9.0, 5.5)
    ax = fig.subplots()
    ax.axhline(0.0, color="0.5", linewidth=0.8, zorder=0)
    spare = (f"C{i}" for i in range(4, 100))
    for k, e in energy.items():
        colour = _PART_COLOURS.get(k.lower()) or next(spare)
        ax.plot(ts, e, color=colour, linewidth=1.5, label=f"{k}: {e[-1]:.1f} J")
    ax.plot(ts, total, color="black", linewidth=2.4, label=f"total: {total[-1]:.1f} J")
    ax.set_xlim(ts[0], ts[-1])
    ax.set_xlabel("Time [s]", fontsize=_LABEL)
    ax.set_ylabel("Energy [J]", fontsize=_LABEL)
    ax.set_title("Electrical energy over time by contribution", fontsize=_TITLE)
    ax.legend(loc="upper left", fontsize=_LEGEND, framealpha=0.9)
    _style(ax)
    return fig


def _pareto_front(x: Array, y: Array) -> NDArray[np.intp]:
    """Indices of the points no other point beats in both x and y, by increasing x."""
    order = np.lexsort((y, x))
    front: list[int] = []
    best = np.inf
    for i in order:
        if y[i] < best:
            front.append(int(i))
            best = y[i]
    return np.asarray(front, dtype=np.intp)


def _pareto_inputs(
    cycle_times: ArrayLike,
    energies: ArrayLike,
    marked: Mapping[str, tuple[float, float]] | None,
) -> tuple[Array, Array, dict[str, tuple[float, float]]]:
    """Checked ``(x (M,), y (M,), named points)`` of :func:`pareto`."""
    x = _vector(cycle_times, "cycle_times")
    y = _vector(energies, "energies")
    if x.size != y.size:
        raise KinergyError(f"energies: expected shape ({x.size},) like cycle_times, got {y.shape}")
    if x.size == 0:
        raise KinergyError("cycle_times: no candidate given")
    points: dict[str, tuple[float, float]] = {}
    for name, xy in (marked or {}).items():
        v = _vector(xy, f"marked[{name!r}]")
        if v.size != 2:
            raise KinergyError(
                f"marked[{name!r}]: expected (cycle time, energy), got {v.size} values"
            )
        points[str(name)] = (float(v[0]), float(v[1]))
    return x, y, points


def _star(
    ax: Axes, name: str, xy: tuple[float, float], middle: tuple[float, float], colour: str
) -> None:
    """A named point as a star, its label pointing away from the edges nearest to it."""
    px, py = xy
    ax.scatter([px], [py], s=140, marker="*", color=colour, edgecolors="black",
               linewidths=0.6, zorder=5)  # fmt: skip
    right, up = px <= middle[0], py <= middle[1]
    ax.annotate(
        f"{name}\n{px:.2f} s, {py:.1f} J",
        (px, py),
        xytext=(10 if right else -10, 10 if up else -10),
        textcoords="offset points",
        ha="left" if right else "right",
        va="bottom" if up else "top",
        fontsize=_LEGEND,
        bbox={"boxstyle": "round,pad=0.25", "facecolor": "white", "alpha": 0.85, "lw": 0.5},
        zorder=6,
    )


def pareto(
    cycle_times: ArrayLike,
    energies: ArrayLike,
    *,
    marked: Mapping[str, tuple[float, float]] | None = None,
) -> Figure:
    """Energy against cycle time of candidate motions, with their Pareto front and named points.

    The front joins the motions no other is both faster and cheaper than (a staircase, by
    increasing cycle time); named motions (e.g. ``"as recorded"``, ``"optimised"``) are drawn as
    stars with their names beside them.

    Parameters
    ----------
    cycle_times : array_like, shape (M,)
        Cycle time of each candidate, s.
    energies : array_like, shape (M,)
        Its energy, J.
    marked : mapping of str to (float, float), optional
        Named points ``name -> (cycle time [s], energy [J])``.

    Returns
    -------
    matplotlib.figure.Figure
        One axes: energy [J] against cycle time [s].

    Raises
    ------
    KinergyError
        If the two arrays differ in length, are empty, or a value is not finite.
    """
    x, y, points = _pareto_inputs(cycle_times, energies, marked)
    fig = _figure(8.0, 5.5)
    ax = fig.subplots()
    ax.scatter(x, y, s=18, color="0.55", alpha=0.7, label="candidates", zorder=2)
    front = _pareto_front(x, y)
    if front.size > 1:
        ax.step(x[front], y[front], where="post", color="tab:blue", linewidth=1.4,
                label="Pareto front", zorder=3)  # fmt: skip
    # Labels point into the plot, away from the nearest edges, so none leaves the axes.
    xs = np.concatenate([x, [p[0] for p in points.values()]])
    ys = np.concatenate([y, [p[1] for p in points.values()]])
    middle = (0.5 * (xs.min() + xs.max()), 0.5 * (ys.min() + ys.max()))
    for i, (name, xy) in enumerate(points.items()):
        _star(ax, name, xy, middle, f"C{(i + 1) % 10}")
    ax.set_xlabel("Cycle time [s]", fontsize=_LABEL)
    ax.set_ylabel("Energy [J]", fontsize=_LABEL)
    ax.set_title("Energy against cycle time", fontsize=_TITLE)
    ax.legend(loc="upper right", fontsize=_LEGEND, framealpha=0.9)
    ax.margins(0.08)
    _style(ax)
    return fig


# -- output -------------------------------------------------------------------------------------


def timing_pareto(result: Any) -> Figure:
    """The Pareto plot of an optimisation (:class:`kinergy.optimize.ProgramOptimization` with its
    front): the supply energy of the optimised path re-timed against the cycle time, the program
    as written uniformly scaled, and the program as written and the optimum marked."""
    front = [p for p in result.pareto if p.optimized is not None]
    x = np.array([p.cycle_time for p in front])
    own, opt = result.program.result, result.optimized.result
    marked = {"program as written": (own.cycle_time, own.e_supply)}
    marked["optimised"] = (opt.cycle_time, opt.e_supply)
    fig = pareto(x, np.array([p.optimized for p in front]), marked=marked)
    ax = fig.axes[0]
    for points in ax.collections:
        if points.get_label() == "candidates":
            points.set_label("optimised path, re-timed")
    ok = [p for p in result.pareto if p.uniform_ok]
    if ok:
        ax.plot(
            np.array([p.cycle_time for p in ok]),
            np.array([p.uniform for p in ok]),
            color="0.4",
            linestyle="--",
            linewidth=1.2,
            marker="o",
            markersize=3,
            label="program as written, uniform time scaling",
            zorder=2,
        )
    ax.set_ylabel("Supply energy per cycle [J]")
    ax.legend(loc="upper right", fontsize=9, framealpha=0.9)
    ax.set_title("Energy against cycle time: the optimised program and uniform scaling")
    return fig


def save(fig: Figure, path: str | os.PathLike[str]) -> Path:
    """Write ``fig`` as a PNG at :data:`DPI` dots per inch, atomically.

    The image goes to a temporary file in the target's folder, which then replaces ``path`` in
    one step (:func:`os.replace`): a reader never sees a half-written file and a failure leaves
    none behind. The folder is created if missing. The figure stays open and usable.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : str or os.PathLike
        Where to write; the image is PNG whatever the suffix.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    KinergyError
        If the folder cannot be created or the file cannot be written.
    """
    return atomic_write(
        path,
        lambda fh: fig.savefig(fh, format="png", dpi=DPI, metadata={"Software": "kinergy"}),
        binary=True,
    )
