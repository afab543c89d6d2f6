"""Payload standard errors that hold on correlated residuals (block jackknife)."""

from __future__ import annotations

import numpy as np

from kinergy.identification.payload import _disagreement, block_std
from kinergy.linalg import scaled_lstsq


def _problem(noise: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(0.0, 50.0, noise.size)
    a = np.column_stack([np.ones_like(t), np.sin(0.7 * t), np.cos(1.3 * t)])
    return a, a @ np.array([1.0, 2.0, -1.0]) + noise


def test_jackknife_agrees_with_the_white_noise_formula_on_white_noise() -> None:
    a, b = _problem(np.random.default_rng(0).normal(0.0, 0.1, 5000))
    white = scaled_lstsq(a, b)[1]
    jack = block_std(a, b, n=1)
    assert np.all(jack > 0.4 * white) and np.all(jack < 2.5 * white)


def test_jackknife_widens_the_error_bars_of_correlated_residuals() -> None:
    walk = np.cumsum(np.random.default_rng(1).normal(0.0, 0.01, 5000))  # slow model error
    a, b = _problem(walk - walk.mean())
    white = scaled_lstsq(a, b)[1]
    assert np.all(block_std(a, b, n=1) > 3.0 * white)


def test_two_logs_with_the_payload_turned_half_a_turn_are_called_so() -> None:
    std = np.full(3, 0.005)
    fits = [(np.array([0.0, 0.2, 0.05]), std), (np.array([0.0, -0.2, 0.05]), std)]
    notes, axes = _disagreement(fits)
    assert axes == {"y"} and len(notes) == 1
    assert "0.200 and 0.200 m from the flange axis, 180 deg apart" in notes[0]
    assert _disagreement([fits[0], fits[0]]) == ((), set())
