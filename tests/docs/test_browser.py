"""A real browser (headless Chromium) renders the landing page, a tutorial and the
command reference: each page has text, and every image on it loaded."""
from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

PAGES = {"index.html": 1, "tutorials/own-part.html": 1, "reference/cli.html": 0}
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--virtual-time-budget=5000"]
# Appended to a copy of each page: after load, record how many images decoded.
PROBE = """<script>window.addEventListener("load", function () {
  var imgs = Array.from(document.images);
  var ok = imgs.filter(function (i) { return i.complete && i.naturalWidth > 0; }).length;
  document.body.setAttribute("data-images", ok + "/" + imgs.length);
  document.body.setAttribute("data-text", document.body.innerText.trim().length);
});</script>"""


def chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    pytest.skip("no Chromium on this machine (.ci/run installs the Debian package chromium)")


def render(browser: str, page: Path, profile: Path, *extra) -> subprocess.CompletedProcess:
    return subprocess.run([browser, *FLAGS, f"--user-data-dir={profile}", *extra, page.as_uri()],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("name,min_images", PAGES.items())
def test_page_renders_with_its_figures(built_docs, tmp_path, name, min_images):
    browser = chromium()
    page = built_docs / name
    probed = page.with_name("_probe_" + page.name)
    probed.write_text(page.read_text().replace("</body>", PROBE + "</body>"))
    dom = render(browser, probed, tmp_path / "profile", "--dump-dom").stdout
    found = re.search(r'data-images="(\d+)/(\d+)"', dom)
    assert found, f"the page did not finish loading:\n{dom[:500]}"
    loaded, total = map(int, found.groups())
    assert loaded == total >= min_images
    assert int(re.search(r'data-text="(\d+)"', dom).group(1)) > 500
    shot = tmp_path / "shot.png"
    render(browser, page, tmp_path / "profile2", f"--screenshot={shot}", "--window-size=1280,900")
    assert shot.exists() and shot.stat().st_size > 20_000   # a blank page compresses to a few kB
