"""The energy map of a base-placement search: supply energy per cycle over the candidates.

:func:`placement_map` draws a :class:`~kinergy.optimize.placement.PlacementSearch` as a heat map
over the base's x and y shift (one panel per height and yaw searched; beyond twelve of them,
the least energy over height and yaw at each x, y): every reachable candidate coloured by the
optimised program's supply energy per cycle, every other one grey with the letter of why
(``R`` a target out of reach, ``C`` the cycle time cannot be kept within the caps, ``L`` a limit
broken, ``T`` a target missed), today's placement a star and the best a ring. Built from the
typed result only, on its own Agg canvas (:func:`kinergy.report.plots.save` writes it).
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from kinergy.optimize.placement import Candidate, PlacementSearch

__all__ = ["placement_map"]


#: the most panels drawn (one per height and yaw); beyond, the least energy over them
_PANELS = 12


def _panel(
    ax: Axes,
    cells: list[Candidate],
    norm: Normalize,
    search: PlacementSearch,
    key: tuple[float, float],
) -> object:
    """One x-y panel of candidates at height and yaw ``key`` (NaN: all of them): the coloured
    grid, the reasons, today's placement and the best where they lie in it."""
    xs = np.unique([c.placement.x for c in cells])
    ys = np.unique([c.placement.y for c in cells])
    energy = np.full((ys.size, xs.size), np.nan)
    codes: dict[tuple[int, int], str] = {}
    for c in cells:
        i, j = int(np.searchsorted(ys, c.placement.y)), int(np.searchsorted(xs, c.placement.x))
        value = c.e_supply
        if value is not None and (np.isnan(energy[i, j]) or value < energy[i, j]):
            energy[i, j] = value
        elif value is None and np.isnan(energy[i, j]):
            codes[(i, j)] = c.reason.code
    dx = float(np.min(np.diff(xs))) if xs.size > 1 else 0.1
    dy = float(np.min(np.diff(ys))) if ys.size > 1 else 0.1
    ax.set_facecolor("0.82")
    mesh = ax.pcolormesh(
        np.append(xs - dx / 2, xs[-1] + dx / 2),
        np.append(ys - dy / 2, ys[-1] + dy / 2),
        np.ma.masked_invalid(energy),
        cmap="viridis",
        norm=norm,
        shading="flat",
    )
    for (i, j), code in codes.items():
        if np.isnan(energy[i, j]):
            ax.text(xs[j], ys[i], code, ha="center", va="center", fontsize=8, color="0.25")

    def here(p: object) -> bool:
        z, yaw = key
        return math.isnan(z) or (p.z, p.yaw) == (z, yaw)  # type: ignore[attr-defined]

    today, best = search.today.placement, search.best.placement
    if here(today):
        ax.plot(today.x, today.y, marker="*", markersize=14, color="white",
                markeredgecolor="black", linestyle="none", label="today")  # fmt: skip
    if here(best):
        ax.plot(best.x, best.y, marker="o", markersize=14, markerfacecolor="none",
                markeredgecolor="red", markeredgewidth=2.0, linestyle="none",
                label="best")  # fmt: skip
    ax.set_xlabel("base shift x [m]", fontsize=10)
    ax.set_ylabel("base shift y [m]", fontsize=10)
    ax.set_aspect("equal")
    ax.tick_params(labelsize=9)
    return mesh


def placement_map(search: PlacementSearch, *, title: str = "") -> Figure:
    """The energy map of a placement search (module docstring).

    Parameters
    ----------
    search : PlacementSearch
    title : str
        The program and robot, put above the map.

    Returns
    -------
    matplotlib.figure.Figure
    """
    cells = list(search.candidates)
    groups: dict[tuple[float, float], list[Candidate]] = {}
    for c in cells:
        groups.setdefault((c.placement.z, c.placement.yaw), []).append(c)
    if len(groups) > _PANELS:
        groups = {(math.nan, math.nan): cells}
    values = [c.e_supply for c in (*cells, search.today) if c.e_supply is not None]
    low, high = (min(values), max(values)) if values else (0.0, 1.0)
    norm = Normalize(vmin=low, vmax=max(high, low + 1e-9))
    ncols = min(3, len(groups))
    nrows = math.ceil(len(groups) / ncols)
    fig = Figure(figsize=(max(4.6 * ncols + 1.4, 7.0), 4.2 * nrows + 1.4), layout="constrained")
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    mesh = None
    for ax, ((z, yaw), group) in zip(axes, sorted(groups.items()), strict=False):
        mesh = _panel(ax, group, norm, search, (z, yaw))
        if not math.isnan(z):
            ax.set_title(f"z {z:+.3f} m, yaw {math.degrees(yaw):+.1f} deg", fontsize=10)
        else:
            ax.set_title("least energy over the heights and yaws searched", fontsize=10)
    for ax in axes[len(groups) :]:
        fig.delaxes(ax)
    if mesh is not None:
        bar = fig.colorbar(mesh, ax=list(axes[: len(groups)]), shrink=0.9)  # type: ignore[arg-type]
        bar.set_label("supply energy per cycle, optimised [J]", fontsize=10)
    if axes[0].get_legend_handles_labels()[0]:  # below the axes: no cell is hidden
        axes[0].legend(
            loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=8, frameon=False
        )
    today, best = search.today.e_supply, search.best.e_supply
    lines = [f"{title}: supply energy per cycle over base placements" if title else
             "Supply energy per cycle over base placements"]  # fmt: skip
    if today is not None and best is not None:
        lines.append(
            f"best {best:.1f} J, today's {today:.1f} J ({100 * (1 - best / today):.1f} % less)"
        )
    lines.append("grey: not reachable (R reach, C cycle time, L limit, T target)")
    fig.suptitle("\n".join(lines), fontsize=10)
    return fig
