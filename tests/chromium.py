"""Headless Chromium for the report tests (Debian's ``chromium``): run it offline with a fresh
profile, and read what a small test-only script saw in a copy of a page.

A probe script appends a hidden ``<pre id=...>`` holding JSON to the page once it has loaded;
``--dump-dom`` prints the page with it, and :func:`probe` parses it back.
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest

#: what every table of a page measures at the window's width: its scroll width against the
#: width of the box it sits in (the report's ``.table-wrap``), and the page's own scroll width
TABLE_FIT = """<script>
window.addEventListener("load", function () {
  var out = document.createElement("pre");
  out.id = "table-fit";
  out.hidden = true;
  out.textContent = JSON.stringify({
    viewport: window.innerWidth,
    page: document.scrollingElement.scrollWidth,
    tables: Array.from(document.querySelectorAll("table"), function (t) {
      return {caption: t.caption ? t.caption.textContent : "", width: t.scrollWidth,
              room: t.parentElement.clientWidth};
    })
  });
  document.body.appendChild(out);
});
</script>
"""


def find_chromium() -> str:
    """The browser's path; the test is skipped where it is not installed."""
    path = shutil.which("chromium") or shutil.which("chromium-browser")
    if path is None:
        pytest.skip("headless Chromium not installed (Debian: apt-get install chromium)")
    return path


def run_chromium(chromium: str, work: Path, *args: str) -> subprocess.CompletedProcess[str]:
    """Run headless Chromium offline, with a fresh profile in ``work``."""
    profile = work / "profile"
    profile.mkdir(parents=True, exist_ok=True)
    flags = [
        "--headless",
        "--no-sandbox",  # needed as root, harmless otherwise
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
        f"--user-data-dir={profile}",
    ]
    env = {**os.environ, "HOME": str(work)}
    proc = subprocess.run(
        [chromium, *flags, *args],
        capture_output=True,
        text=True,
        timeout=180,
        env=env,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc


def probe(chromium: str, report: Path, work: Path, script: str, element: str, *args: str) -> Any:
    """Open a copy of ``report`` (same folder: same relative paths) with ``script`` in it and
    return the JSON the script left in ``<pre id=element>``."""
    text = report.read_text(encoding="utf-8")
    assert text.count("</body>") == 1
    copy = report.with_name(f"probe-{element}.html")
    copy.write_text(text.replace("</body>", script + "</body>"), encoding="utf-8")
    try:
        proc = run_chromium(
            chromium, work, *args, "--virtual-time-budget=10000", "--dump-dom", copy.as_uri()
        )
    finally:
        copy.unlink()
    found = re.findall(rf'<pre id="{element}"[^>]*>(.*?)</pre>', proc.stdout, re.S)
    assert len(found) == 1, f"probe did not run; stderr: {proc.stderr[-3000:]}"
    return json.loads(html.unescape(found[0]))


def table_overflow(chromium: str, report: Path, work: Path, width: int = 1280) -> list[str]:
    """The tables of ``report`` wider than the box they sit in, in a window ``width`` pixels
    wide (and the page, if it scrolls sideways): empty when everything fits."""
    seen = probe(chromium, report, work, TABLE_FIT, "table-fit", f"--window-size={width},2000")
    assert seen["viewport"] == width and seen["tables"], seen
    over = [
        f"{t['caption']}: {t['width']} px in {t['room']} px"
        for t in seen["tables"]
        if t["width"] > t["room"]
    ]
    if seen["page"] > seen["viewport"]:
        over.append(f"the page: {seen['page']} px in a {seen['viewport']} px window")
    return over
