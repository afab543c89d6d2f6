"""The HTML report: written, parsed back, and opened in a real browser.

Checked with the standard library's HTML parser: the page is HTML5 (doctype, ``lang``, UTF-8),
loads nothing from outside, every ``img src`` is a file beside the report with the caption as
its alternative text and its true pixel size, tables and figures are numbered in order with
their captions, the contents link to exactly the section ids, numeric columns (and only those)
are right-aligned, and text is escaped (a ``<script>`` in a section's text is shown, not run).
A missing figure is a KinergyError naming it, and no report (nor temporary file) is left.

Checked in headless Chromium (Debian's ``chromium``; skipped when absent): every image of the
report decodes (``naturalWidth`` equals the PNG's width), read by a small test-only script in a
copy of the page whose result ``--dump-dom`` prints; a corrupted image is reported as broken
(the probe can fail); a screenshot shows the page, with a test figure's solid colour in it; in a
1280 px window every table fits its card, however long its headers (a second probe, which sees a
table forced wider: ``tests/chromium.py``).
"""

from __future__ import annotations

import re
import struct
from html.parser import HTMLParser
from pathlib import Path
from typing import Any
from urllib.parse import unquote

import numpy as np
import pytest
from chromium import find_chromium, probe, run_chromium, table_overflow
from matplotlib.image import imread, imsave

from kinergy.errors import KinergyError
from kinergy.report import plots
from kinergy.report.html import Figure, Section, Table, write_report

NAMES = ["base", "shoulder", "elbow", "wrist1", "wrist2", "wrist3"]
#: A colour no other part of the page uses: the screenshot must show the figure drawn in it.
MAGENTA = (1.0, 0.0, 1.0)
SOLID_SIZE = (420, 160)  # width, height in pixels
HOSTILE = 'Errors are "measured - model". <script>alert("x")</script> & <b>not bold</b>'


class Page(HTMLParser):
    """What the tests look at in a page: elements with their attributes, and the text."""

    def __init__(self, text: str) -> None:
        super().__init__(convert_charrefs=True)
        self.decls: list[str] = []
        self.elements: list[tuple[str, dict[str, str], tuple[str, ...]]] = []
        self.data: list[str] = []
        self._stack: list[str] = []
        self._captures: list[tuple[str, list[str]]] = []  # open <caption>, <pre>, <figcaption>
        self.captured: dict[str, list[str]] = {"caption": [], "figcaption": [], "pre": []}
        self.feed(text)
        self.close()

    def handle_decl(self, decl: str) -> None:
        self.decls.append(decl)

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.elements.append((tag, {k: v or "" for k, v in attrs}, tuple(self._stack)))
        if tag in self.captured:
            self._captures.append((tag, []))
        if tag not in {"meta", "img", "br", "hr", "link", "input", "source"}:
            self._stack.append(tag)

    def handle_endtag(self, tag: str) -> None:
        if tag in self._stack:
            while self._stack.pop() != tag:
                pass
        if self._captures and self._captures[-1][0] == tag:
            name, parts = self._captures.pop()
            self.captured[name].append(" ".join("".join(parts).split()))

    def handle_data(self, data: str) -> None:
        self.data.append(data)
        for _, parts in self._captures:
            parts.append(data)

    def find(self, tag: str, **attrs: str) -> list[dict[str, str]]:
        return [
            a
            for t, a, _ in self.elements
            if t == tag and all(a.get(k.rstrip("_")) == v for k, v in attrs.items())
        ]

    def inside(self, tag: str, parent: str) -> list[dict[str, str]]:
        return [a for t, a, stack in self.elements if t == tag and parent in stack]

    @property
    def text(self) -> str:
        return "".join(self.data)


def png_size(path: Path) -> tuple[int, int]:
    with open(path, "rb") as fh:
        head = fh.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    w, h = struct.unpack(">II", head[16:24])
    return w, h


def make_figures(folder: Path) -> dict[str, Path]:
    """A kinergy plot and a solid-colour image (in a folder with a space, to test quoting)."""
    rng = np.random.default_rng(7)
    t = np.linspace(0.0, 4.0, 200)
    power = np.abs(rng.uniform(5.0, 60.0, 6) * np.sin(np.outer(t, rng.uniform(0.5, 2.0, 6))))
    energy = plots.save(
        plots.power_energy(t, power, joint_names=NAMES), folder / "figures" / "power.png"
    )
    solid = folder / "figures" / "solid colour.png"
    w, h = SOLID_SIZE
    imsave(solid, np.broadcast_to(np.array(MAGENTA), (h, w, 3)).copy())
    return {"power": energy, "solid": solid}


def sections_for(figures: dict[str, Path], folder: Path) -> list[Section]:
    rel = {k: p.relative_to(folder).as_posix() for k, p in figures.items()}
    accuracy = Table(
        "Torque error per joint, test B",
        ["Joint", "RMS [N m]", "R²", "Seed R²", "Comment"],
        [
            ["base", "1.530", "0.9890", "n/a", "ok"],
            ["shoulder", "12,345.6", "−0.25", "0.998", "<i>check</i>"],
            ["elbow", "2.1e-3", "0.9982", "—", "12.5"],
        ],
        note="Seed R² is Table V of the UR5e study.",
    )
    energy = Table(
        "Energy per joint",
        ["Joint", "E_elec [J]", "Efficiency"],
        [[n, f"{100.0 * (i + 1):.1f}", f"{50 + i:.1f} %"] for i, n in enumerate(NAMES)],
    )
    return [
        Section(
            "Model accuracy",
            "The model predicts the torques of the unseen run.\nSecond line, same paragraph.\n\n"
            + HOSTILE,
            tables=[accuracy],
            figures=[Figure(rel["solid"], "A solid test figure.")],
        ),
        Section(
            "Energy & power",
            "Signed integrals (UR5e eq 26).",
            tables=[energy],
            figures=[Figure(rel["power"], "Electrical power and cumulative energy per joint.")],
        ),
    ]


META = {"Robot": "ur5e", "Date": "2025-06-01", "kinergy version": "0.1.0", "Logs": "a.csv"}


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Path]]:
    folder = tmp_path_factory.mktemp("report")
    figures = make_figures(folder)
    out = write_report(
        folder / "report.html",
        title="UR5e <identification>",
        subtitle="test A → test B",
        sections=sections_for(figures, folder),
        meta=META,
    )
    assert out == folder / "report.html"
    return out, figures


@pytest.fixture(scope="module")
def page(built: tuple[Path, dict[str, Path]]) -> Page:
    return Page(built[0].read_text(encoding="utf-8"))


# -- the page, parsed ---------------------------------------------------------------------------


def test_html5_head(built: tuple[Path, dict[str, Path]], page: Page) -> None:
    raw = built[0].read_text(encoding="utf-8")
    assert raw.lstrip().lower().startswith("<!doctype html>")
    assert [d.lower() for d in page.decls] == ["doctype html"]
    assert page.find("html", lang="en")
    assert page.find("meta", charset="utf-8")
    assert page.find("title")
    assert oct(built[0].stat().st_mode & 0o777) == "0o644"


def test_nothing_loaded_from_outside(page: Page) -> None:
    assert not page.find("script")
    assert not page.find("link")
    assert not page.find("iframe")
    for _, attrs, _ in page.elements:
        for key in ("src", "href"):
            value = attrs.get(key, "")
            assert not re.match(r"^([a-z][a-z0-9+.-]*:|//)", value, re.I), value


def test_images_exist_with_caption_and_size(
    built: tuple[Path, dict[str, Path]], page: Page
) -> None:
    report, _ = built
    images = page.find("img")
    assert len(images) == 2
    assert [img["alt"] for img in images] == [
        "A solid test figure.",
        "Electrical power and cumulative energy per joint.",
    ]
    assert images[0]["src"] == "figures/solid%20colour.png"  # quoted as a URL
    for img in images:
        file = report.parent / unquote(img["src"])
        assert file.is_file(), img["src"]
        assert img["loading"] == "eager"
        assert (int(img["width"]), int(img["height"])) == png_size(file)
    assert len(page.inside("img", "figure")) == 2
    assert page.captured["figcaption"] == [
        "Figure 1. A solid test figure.",
        "Figure 2. Electrical power and cumulative energy per joint.",
    ]


def test_tables_numbered_with_captions_and_note(page: Page) -> None:
    assert len(page.find("table")) == 2
    assert page.captured["caption"] == [
        "Table 1. Torque error per joint, test B",
        "Table 2. Energy per joint",
    ]
    assert "Seed R² is Table V of the UR5e study." in page.text
    assert len(page.inside("td", "table")) == 5 * 3 + 3 * 6
    assert len(page.inside("th", "thead")) == 5 + 3


def test_numeric_columns_right_aligned(page: Page) -> None:
    """A column is numeric when each cell is a number or a placeholder (n/a, —)."""
    heads = page.inside("th", "thead")
    numeric = [h.get("class") == "num" for h in heads]
    #         Joint  RMS   R²    SeedR² Comment | Joint  E_elec Efficiency
    assert numeric == [False, True, True, True, False, False, True, True]
    cells = page.inside("td", "tbody")
    first = [c.get("class") == "num" for c in cells[:5]]
    assert first == [False, True, True, True, False]  # "12.5" alone does not make Comment numeric


def test_contents_link_to_every_section(page: Page) -> None:
    ids = [s["id"] for s in page.find("section")]
    assert len(ids) == 2
    assert len(set(ids)) == 2
    toc = [a["href"] for a in page.inside("a", "nav")]
    assert toc == [f"#{i}" for i in ids]
    assert all(re.fullmatch(r"[a-z][a-z0-9-]*", i) for i in ids)
    assert ids == ["model-accuracy", "energy-power"]


def test_text_is_escaped(built: tuple[Path, dict[str, Path]], page: Page) -> None:
    raw = built[0].read_text(encoding="utf-8")
    assert "<script>" not in raw
    assert "&lt;script&gt;alert(" in raw
    assert not page.find("script")
    assert not page.find("b")
    assert not page.find("i")
    assert HOSTILE in page.text  # shown as written
    assert "UR5e <identification>" in page.text
    assert "<i>check</i>" in page.text


def test_paragraphs_and_meta(page: Page) -> None:
    text = page.text
    assert "The model predicts the torques of the unseen run. Second line, same paragraph." in text
    assert len(page.inside("p", "section")) == 2 + 1 + 1  # two, one, plus the table note
    for key, value in META.items():
        assert key in text
        assert value in text
    assert "test A → test B" in text


def test_missing_figure_is_named_and_nothing_is_written(tmp_path: Path) -> None:
    figures = make_figures(tmp_path)
    sections = sections_for(figures, tmp_path)
    figures["power"].unlink()
    with pytest.raises(KinergyError, match=r"figures/power\.png") as info:
        write_report(tmp_path / "report.html", title="t", subtitle="s", sections=sections)
    assert "\n" not in str(info.value)
    assert not (tmp_path / "report.html").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["figures"]  # no temporary file

    # an earlier report stays as it was
    (tmp_path / "report.html").write_text("earlier", encoding="utf-8")
    with pytest.raises(KinergyError, match="power"):
        write_report(tmp_path / "report.html", title="t", subtitle="s", sections=sections)
    assert (tmp_path / "report.html").read_text(encoding="utf-8") == "earlier"


def test_figure_paths_are_relative_to_the_report(tmp_path: Path) -> None:
    make_figures(tmp_path / "out")
    sections = [Section("Plots", figures=[Figure("figures/power.png", "power")])]
    with pytest.raises(KinergyError, match="power.png"):  # resolved against tmp_path, not out/
        write_report(tmp_path / "report.html", title="t", subtitle="", sections=sections)
    write_report(tmp_path / "out" / "report.html", title="t", subtitle="", sections=sections)


@pytest.mark.parametrize(
    "path", ["/abs/fig.png", "C:\\figs\\fig.png", "https://example.org/fig.png", "data:x", " "]
)
def test_figure_path_must_be_relative(path: str) -> None:
    with pytest.raises(KinergyError, match="figure"):
        Figure(path, "caption")


def test_table_and_section_validate() -> None:
    with pytest.raises(KinergyError, match="row 1 has 1 cells, expected 2"):
        Table("t", ["a", "b"], [["1", "2"], ["3"]])
    with pytest.raises(KinergyError, match="row 0, column 1: expected text, got float"):
        Table("t", ["a", "b"], [["1", 2.0]])  # type: ignore[list-item]
    with pytest.raises(KinergyError, match="no column header"):
        Table("t", [], [])
    with pytest.raises(KinergyError, match="empty title"):
        Section("  ")
    with pytest.raises(KinergyError, match="expected Table"):
        Section("s", tables=["not a table"])  # type: ignore[list-item]


def test_duplicate_titles_get_unique_ids(tmp_path: Path) -> None:
    titles = ["Energy", "Energy", "3 results", "Ünïcode → test"]
    out = write_report(
        tmp_path / "sub" / "r.html",
        title="t",
        subtitle="",
        sections=[Section(t) for t in titles],
    )
    page = Page(out.read_text(encoding="utf-8"))
    ids = [s["id"] for s in page.find("section")]
    assert ids == ["energy", "energy-2", "s-3-results", "unicode-test"]
    assert [a["href"] for a in page.inside("a", "nav")] == [f"#{i}" for i in ids]


# -- in a real browser --------------------------------------------------------------------------

PROBE = """<script>
window.addEventListener("load", function () {
  var out = document.createElement("pre");
  out.id = "image-states";
  out.textContent = JSON.stringify(Array.from(document.images, function (img) {
    return {src: img.getAttribute("src"), complete: img.complete,
            width: img.naturalWidth, height: img.naturalHeight};
  }));
  document.body.appendChild(out);
});
</script>
"""


@pytest.fixture(scope="module")
def chromium() -> str:
    return find_chromium()


def image_states(chromium: str, report: Path, work: Path) -> list[dict[str, Any]]:
    """Open a copy of ``report`` with the probe script in it; return what the browser saw."""
    states: list[dict[str, Any]] = probe(chromium, report, work, PROBE, "image-states")
    return states


def test_browser_loads_every_image(
    chromium: str, built: tuple[Path, dict[str, Path]], tmp_path: Path
) -> None:
    report, _ = built
    states = image_states(chromium, report, tmp_path)
    srcs = [img["src"] for img in Page(report.read_text(encoding="utf-8")).find("img")]
    assert [s["src"] for s in states] == srcs
    for s in states:
        file = report.parent / unquote(s["src"])
        assert s["complete"], s
        assert s["width"] > 0, f"{s['src']} did not load"
        assert (s["width"], s["height"]) == png_size(file)


def test_browser_probe_sees_a_broken_image(chromium: str, tmp_path: Path) -> None:
    """The probe can fail: an image file that is not a PNG any more is reported as broken."""
    figures = make_figures(tmp_path)
    report = write_report(
        tmp_path / "report.html",
        title="t",
        subtitle="",
        sections=sections_for(figures, tmp_path),
    )
    figures["power"].write_bytes(b"not a png")
    states = {s["src"]: s for s in image_states(chromium, report, tmp_path / "work")}
    assert states["figures/power.png"]["width"] == 0
    assert states["figures/solid%20colour.png"]["width"] == SOLID_SIZE[0]


def test_browser_screenshot(
    chromium: str, built: tuple[Path, dict[str, Path]], tmp_path: Path
) -> None:
    report, _ = built
    shot = tmp_path / "report.png"
    width, height = 1280, 2200
    run_chromium(
        chromium,
        tmp_path,
        f"--window-size={width},{height}",
        f"--screenshot={shot}",
        report.as_uri(),
    )
    assert shot.stat().st_size > 30_000
    image = imread(shot)[..., :3]
    assert image.shape == (height, width, 3)

    # not blank: plenty of pixels differ from the page's background, and there is dark text
    colours, counts = np.unique(image.reshape(-1, 3), axis=0, return_counts=True)
    background = colours[np.argmax(counts)]
    assert np.mean(np.any(image != background, axis=-1)) > 0.2
    assert len(colours) > 200
    assert np.sum(image.mean(axis=-1) < 0.3) > 5_000

    # the solid test figure is drawn, scaled at most down, as one block of its colour
    magenta = np.all(np.abs(image - np.array(MAGENTA)) < 0.02, axis=-1)
    rows, cols = np.nonzero(magenta)
    assert rows.size > 0.8 * SOLID_SIZE[0] * SOLID_SIZE[1]
    assert cols.max() - cols.min() + 1 <= SOLID_SIZE[0]
    assert cols.max() < width


def wide_sections() -> list[Section]:
    """Tables as wide as kinergy writes them: long headers with units, long names with
    underscores, cells of identified (truth, error) and a dense numeric table."""
    params = [
        "coulomb_positive [N m]",
        "coulomb_negative [N m]",
        "viscous_positive [N m (s/rad)^exponent]",
        "viscous_negative [N m (s/rad)^exponent]",
        "exponent [1]",
        "smoothing [rad/s]",
    ]
    friction = Table(
        "Friction and torque constants, directional_power_law friction",
        ["joint", *params, "k_t [N m/A]"],
        [[f"shoulder_lift_{k}", *["0.01392"] * 6, "0.1114 (0.1112)"] for k in range(3)],
    )
    truth = Table(
        "The twin is not the model: truth against identified",
        ["joint", "k_t [N m/A]", "J_m + J_r [kg m²]", "friction chosen", "held-out current R²"],
        [
            [n, "0.09832 (0.09862, -0.3 %)", "0.0001911 (0.0001913, -0.1 %)", m, "0.9994"]
            for n, m in zip(NAMES, ["directional_power_law"] * 6, strict=True)
        ],
    )
    parts = ["inertial", "gravity", "friction", "copper", "standby", "E_elec", "E_supply"]
    dense = Table(
        "Where the energy goes",
        ["motion", *(f"{p} [J]" for p in parts), "peak power [W]", "mean power [W]"],
        [["test A", *[f"{1000.0 + k:.1f}" for k in range(9)]]],
    )
    return [Section("Wide tables", "Tables wider than the card's text.", [friction, truth, dense])]


def test_browser_tables_fit_the_card_at_1280_px(chromium: str, tmp_path: Path) -> None:
    """Every table is at most as wide as its box (so nothing scrolls or runs off the card) in a
    1280 px window, however long its headers: they wrap at spaces and after ``_`` and ``/``."""
    report = write_report(
        tmp_path / "report.html", title="t", subtitle="", sections=wide_sections()
    )
    assert "coulomb_<wbr>positive [N m]" in report.read_text(encoding="utf-8")
    assert table_overflow(chromium, report, tmp_path / "work") == []


def test_browser_table_fit_probe_sees_an_overflow(chromium: str, tmp_path: Path) -> None:
    """The probe can fail: a table forced wider than the card is reported, by caption."""
    report = write_report(
        tmp_path / "report.html", title="t", subtitle="", sections=wide_sections()
    )
    text = report.read_text(encoding="utf-8")
    forced = text.replace("</style>", "table { min-width: 1500px; }\n</style>")
    report.write_text(forced, encoding="utf-8")
    over = table_overflow(chromium, report, tmp_path / "work")
    assert len(over) == 3  # each table (its box scrolls: the page itself does not)
    assert over[0].startswith("Table 1. Friction and torque constants")
