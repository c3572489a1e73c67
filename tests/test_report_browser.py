"""The calibration report opens in a real browser (headless Debian chromium via playwright).

Needs ``apt-get install -y chromium`` and ``pip install playwright`` (never ``playwright
install``: the system browser is used). Skipped, with the reason, when either is missing.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import pytest

from stereovision.calibrate import calibrate

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--no-first-run",
    "--disable-component-update",
    "--disable-sync",
]
DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "chessboard"
#: A few sample pairs are enough for a complete report (every section and picture).
PAIR_IDS = ("01", "02", "03", "04")
#: Page load budget (ms); a self-contained file loads in well under a second.
LOAD_TIMEOUT_MS = 30_000


def _playwright():  # type: ignore[no-untyped-def]
    if not Path(CHROMIUM).exists() and shutil.which("chromium") is None:
        pytest.skip(f"chromium not installed ({CHROMIUM}): apt-get install -y chromium")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("playwright not installed: pip install playwright (no `playwright install`)")
    return sync_playwright


def test_report_opens_in_headless_chromium(tmp_path: Path) -> None:
    sync_playwright = _playwright()
    if not DATA.is_dir():
        pytest.skip(f"chessboard data not found at {DATA}")
    _, rep = calibrate(
        [DATA / f"left{i}.jpg" for i in PAIR_IDS],
        [DATA / f"right{i}.jpg" for i in PAIR_IDS],
        pattern=(9, 6),
        square_size=1.0,
    )
    html_path = rep.write(tmp_path / "report")["html"]
    requests: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1100, "height": 900})
            page.on("request", lambda r: requests.append(r.url))
            page.goto(html_path.resolve().as_uri(), wait_until="load", timeout=LOAD_TIMEOUT_MS)
            images = page.evaluate(
                "Array.from(document.images).map(i => ({alt: i.alt, complete: i.complete,"
                " w: i.naturalWidth, h: i.naturalHeight}))"
            )
            text = page.inner_text("body")
            title = page.title()
            shot = tmp_path / "report.png"
            page.screenshot(path=str(shot), full_page=True)
        finally:
            browser.close()
    assert title == "Stereo calibration report"
    assert [i["alt"] for i in images] == [
        "Per-pair reprojection error",
        "Corner coverage",
        "Rectified pair with epipolar lines",
        "Rig extrinsics",
    ]
    for img in images:
        assert img["complete"] and img["w"] > 0 and img["h"] > 0, img
    # Key figures are on the page as text.
    assert f"{rep.rms:.3f} px" in text
    assert f"{rep.epipolar_mean_dy:.3f} px" in text
    assert f"{rep.baseline:.5g} m" in text
    assert "4 of 4" in text
    for name in rep.used_pairs:
        assert name in text
    # Self-contained: the page loads nothing but itself and its data: URIs.
    assert all(u.startswith(("file:", "data:")) for u in requests), requests
    screenshot = cv2.imread(str(shot))
    assert screenshot is not None and screenshot.shape[1] == 1100 and screenshot.shape[0] > 900
    print(f"\nscreenshot: {shot}")
