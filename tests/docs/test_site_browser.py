"""The documentation site opened from disk (``file://``, as the README says) in headless Chromium: every
navigation link opens a page of the site (not a directory listing), the pages load their figures, and long code
lines wrap inside the page at 1280 px. Skipped, with the reason, without Chromium (``scripts/ensure-chromium``
installs it)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from stewart_drake.report.browser import Browser, find_chromium

pytestmark = pytest.mark.skipif(
    find_chromium() is None, reason="Chromium or websocket-client not installed: run scripts/ensure-chromium"
)
SHOTS = os.environ.get("STEWART_SCREENSHOTS")  # a folder: also save the screenshots there


@pytest.fixture(scope="module")
def browser():
    with Browser(width=1280, height=900) as b:
        yield b


def test_navigation_from_disk_opens_pages(site, browser):
    """From ``index.html`` opened as a file, each link of the navigation leads to a page of the site with its
    content (a directory listing has none), every image of that page loaded."""
    browser.open(str(site[0] / "index.html"))
    links = json.loads(
        browser.evaluate("JSON.stringify([...document.querySelectorAll('nav a.md-nav__link')].map(a => a.href))")
    )
    pages = sorted({link.split("#")[0] for link in links if link.startswith("file://")})
    assert len(pages) >= 15
    for url in pages:
        browser.open(url, settle=0.1)
        assert browser.evaluate("!!document.querySelector('article.md-content__inner')"), url
        broken = browser.evaluate("[...document.images].filter(i => !(i.complete && i.naturalWidth > 0)).length")
        assert broken == 0, url


def test_code_blocks_wrap_inside_the_page(site, browser):
    """No code block of the getting-started and API pages scrolls sideways at 1280 px: its lines wrap."""
    for page in ("getting-started.html", "api.html", "presets.html"):
        browser.open(str(site[0] / page), settle=0.2)
        wide = browser.evaluate(
            "[...document.querySelectorAll('pre > code')].filter(c => c.scrollWidth > c.clientWidth + 1).length"
        )
        assert wide == 0, page
        if SHOTS:
            browser.screenshot(Path(SHOTS) / f"docs-{Path(page).stem}.png", full_page=False)
