"""The Python API reference (docs/api.md) documents every public name of ``kinergy``.

Each name of ``kinergy.__all__`` must be rendered on the page by a mkdocstrings directive
(``::: module.name``) whose target is the very object ``kinergy.name`` is, so a name documented
under a module that no longer defines it, or a new public name nobody documented, fails here
(``mkdocs build --strict`` in CI fails on a target that does not import). Data that has no
docstring of its own (``__version__``) must appear on the page by its full name.
"""

from __future__ import annotations

import importlib
import re
import types
from pathlib import Path

import pytest

import kinergy

PAGE = Path(__file__).resolve().parents[1] / "docs" / "api.md"
DIRECTIVE = re.compile(r"^::: ([\w.]+)\s*$", re.M)


def _public(name: str) -> object:
    """``kinergy.name`` as the package defines it. Two public functions share their names with
    sub-packages (``identify``, ``simulate``): once such a sub-package is imported, Python binds
    the module to the package's attribute, so the package's own resolver is asked instead."""
    value = vars(kinergy).get(name)
    if value is None or isinstance(value, types.ModuleType):
        value = kinergy.__getattr__(name)
    return value


def _directives() -> dict[str, object]:
    """Every ``::: dotted.path`` on the page and the object it names."""
    found = {}
    for target in DIRECTIVE.findall(PAGE.read_text(encoding="utf-8")):
        module, _, attr = target.rpartition(".")
        found[target] = getattr(importlib.import_module(module), attr)
    return found


def test_every_directive_names_an_object() -> None:
    assert len(_directives()) >= len(kinergy.__all__) - 1


@pytest.mark.parametrize("name", kinergy.__all__)
def test_every_public_name_is_documented(name: str) -> None:
    value = _public(name)
    if isinstance(value, str):
        assert f"`kinergy.{name}`" in PAGE.read_text(encoding="utf-8"), name
        return
    documented = [target for target, obj in _directives().items() if obj is value]
    assert documented, f"kinergy.{name} is not in docs/api.md (add '::: module.{name}')"


def test_a_missing_name_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """The check can fail: a public name the page lacks is reported."""
    monkeypatch.setattr(kinergy, "__all__", [*kinergy.__all__, "undocumented_function"])
    monkeypatch.setattr(kinergy, "undocumented_function", lambda: None, raising=False)
    with pytest.raises(AssertionError, match="undocumented_function"):
        test_every_public_name_is_documented("undocumented_function")
