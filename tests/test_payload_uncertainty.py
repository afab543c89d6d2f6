"""Payload standard errors that hold on correlated residuals (block jackknife)."""

from __future__ import annotations

import numpy as np

from kinergy.identify.payload import block_std
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
