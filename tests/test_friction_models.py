"""Friction models of issue 13: power law, load- and temperature-dependent, per direction.

Properties every model of the registry keeps (hypothesis): its regressor columns times its linear
values give its torque, with any load and temperature; it dissipates (``tau wm >= 0``) for
physical parameters; and the closed forms each module's docstring writes.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinergy.errors import KinergyError
from kinergy.friction.registry import MODELS, get_model

#: test parameters of the models issue 13 adds (tests/test_drives.py covers the others)
NEW_MODELS: dict[str, dict[str, float]] = {
    "power_law": {"coulomb": 0.05, "viscous": 4e-3, "exponent": 0.6, "smoothing": 1e-3},
    "directional_power_law": {
        "coulomb_positive": 0.05,
        "coulomb_negative": 0.06,
        "viscous_positive": 4e-3,
        "viscous_negative": 5e-3,
        "exponent": 0.55,
        "smoothing": 1e-3,
    },
    "load_coulomb": {"coulomb": 0.05, "load": 0.03, "viscous": 3e-4, "smoothing": 1e-3},
    "thermal_viscous": {
        "coulomb": 0.05,
        "viscous": 5e-4,
        "viscous_temperature": -4e-6,
        "reference_temperature": 25.0,
        "smoothing": 1e-3,
    },
    "load_thermal_power_law": {
        "coulomb": 0.05,
        "load": 0.02,
        "viscous": 4e-3,
        "viscous_temperature": -3e-5,
        "exponent": 0.6,
        "reference_temperature": 25.0,
        "smoothing": 1e-3,
    },
}


def _params(model: str) -> dict[str, float]:
    from test_drives import PARAMS

    return dict(PARAMS[model])


signals = st.integers(min_value=0, max_value=2**31 - 1)


@settings(max_examples=25, deadline=None)
@given(seed=signals, scale=st.floats(0.1, 10.0))
@pytest.mark.parametrize("model", sorted(MODELS))
def test_columns_times_values_is_the_torque(model: str, seed: int, scale: float) -> None:
    rng = np.random.default_rng(seed)
    wm = rng.normal(0, 100, 200)
    load = rng.normal(0, 1, 200)
    temperature = rng.uniform(15, 60, 200)
    params = _params(model)
    values = get_model(model).values_of(params) * scale
    updated = get_model(model).with_values(params, values)
    cols = get_model(model).friction_columns(updated, wm, load, temperature=temperature)
    torque = get_model(model).friction_torque(updated, wm, load, temperature=temperature)
    np.testing.assert_allclose(cols @ values, torque, rtol=1e-10, atol=1e-14)


@settings(max_examples=40, deadline=None)
@given(seed=signals, level=st.floats(0.0, 0.3), exponent=st.floats(0.2, 1.5))
@pytest.mark.parametrize("model", sorted(NEW_MODELS))
def test_friction_dissipates_for_physical_parameters(
    model: str, seed: int, level: float, exponent: float
) -> None:
    rng = np.random.default_rng(seed)
    spec = get_model(model)
    params = _params(model)
    for name in spec.linear:
        params[name] = level * rng.uniform(0, 1) * (1e-2 if "viscous" in name else 1.0)
    if "exponent" in params:
        params["exponent"] = exponent
    if "viscous_temperature" in params:
        # falling with temperature, but still >= 0 up to 80 deg C (the physical range)
        params["viscous_temperature"] = -params["viscous"] / 55.0 * rng.uniform(0, 1)
    wm = rng.normal(0, 200, 300)
    tau = get_model(model).friction_torque(
        params, wm, rng.normal(0, 2, 300), temperature=rng.uniform(-10, 80, 300)
    )
    assert np.all(tau * wm >= -1e-15)


def test_power_law_closed_form_and_its_exponent_one_is_viscous_coulomb() -> None:
    p = NEW_MODELS["power_law"]
    wm = np.array([-300.0, -1.0, 50.0, 320.0])
    want = (0.05 + 4e-3 * np.abs(wm) ** 0.6) * np.tanh(wm / 1e-3)
    np.testing.assert_allclose(get_model("power_law").friction_torque(p, wm), want, rtol=1e-12)
    linear = {**p, "exponent": 1.0}
    vc = {"coulomb": 0.05, "viscous": 4e-3, "smoothing": 1e-3}
    np.testing.assert_allclose(
        get_model("power_law").friction_torque(linear, wm),
        get_model("viscous_coulomb").friction_torque(vc, wm),
    )


def test_load_coulomb_rises_with_the_load_either_way() -> None:
    p = NEW_MODELS["load_coulomb"]
    wm = np.array([100.0, 100.0, 100.0])
    tau = get_model("load_coulomb").friction_torque(p, wm, np.array([0.0, 1.0, -1.0]))
    assert tau[1] == pytest.approx(tau[0] + 0.03) and tau[2] == pytest.approx(tau[1])
    with pytest.raises(KinergyError, match="load_coulomb.*needs the load torque"):
        get_model("load_coulomb").friction_torque(p, wm)


def test_thermal_viscous_falls_as_the_joint_warms_and_needs_no_temperature() -> None:
    p = NEW_MODELS["thermal_viscous"]
    wm = np.full(3, 200.0)
    warm = get_model("thermal_viscous").friction_torque(
        p, wm, temperature=np.array([25.0, 45.0, 65.0])
    )
    assert warm[0] > warm[1] > warm[2]
    # 20 K warmer: the viscous part falls by 20 * 4e-6 / 5e-4 = 16 %
    assert (warm[0] - warm[1]) / (5e-4 * 200.0) == pytest.approx(0.16)
    # no temperature: the reference temperature
    assert get_model("thermal_viscous").friction_torque(p, wm)[0] == pytest.approx(warm[0])


def test_directional_power_law_takes_each_directions_levels() -> None:
    p = NEW_MODELS["directional_power_law"]
    tau = get_model("directional_power_law").friction_torque(p, np.array([100.0, -100.0]))
    assert tau[0] == pytest.approx(0.05 + 4e-3 * 100**0.55)
    assert tau[1] == pytest.approx(-(0.06 + 5e-3 * 100**0.55))


def test_every_new_model_names_its_citation_and_search() -> None:
    for name in NEW_MODELS:
        assert get_model(name).citation
    assert get_model("power_law").search == {"exponent": (0.2, 1.5)}


def test_a_filter_overshoot_at_a_stop_does_not_set_the_held_friction() -> None:
    params = {"coulomb": 1.0, "viscous": 0.0, "smoothing": 0.01, "standstill": 0.5}
    wm = np.concatenate([np.full(20, -5.0), [0.6, 0.55], np.zeros(10)])  # ringing: 2 samples
    cols = get_model("viscous_coulomb").friction_columns(params, wm, dwm=np.zeros_like(wm))
    held = cols[-10:, 1]  # the Coulomb column
    assert np.allclose(held, -1.0)


def test_the_standstill_hold_does_not_cross_from_one_log_into_the_next() -> None:
    from kinergy.identification.drive_steps import _columns, _Signals

    wm = np.concatenate([np.full(10, 5.0), np.zeros(10), np.zeros(10), np.full(10, 5.0)])
    z = np.zeros_like(wm)
    piece = np.repeat([0, 1], 20)
    params = {"coulomb": 1.0, "viscous": 0.0, "smoothing": 0.01, "standstill": 0.5}
    cols = _columns(get_model("viscous_coulomb"), params, _Signals(z, wm, z, z, None, piece))
    assert np.allclose(cols[10:20, 2], 1.0)  # the first log's stop holds its last motion
    assert np.allclose(cols[20:30, 2], 0.0)  # the second log starts at rest: nothing to hold
