"""Redraw the README and docs pictures that come from the demo, the refinement and the GUI.

- ``demo``: ``docs/images/demo_disparity.png``, ``demo_render.png`` and ``demo_overview.png``,
  the ``disparity.png``, ``render.png`` and ``overview.png`` of ``stereovision demo`` (the
  bundled cones, as ``make demo`` writes them; the overview, 1106 x 848 px, as a palette PNG).
- ``refine``: ``docs/images/refine_depth_error.png``, ``|dZ|/Z`` per pixel against the GT on
  ETH3D terrace and KITTI 2015 000005 (``../shared/data``) for ``method="gabor",
  refine=False`` (the Gabor channel as it comes), ``method="gabor"`` (refined, its default) and
  OpenCV SGBM-3WAY; depth where the method reports one (its filled pixels have none).
- ``gui``: ``docs/images/gui-3d.png`` and ``gui-methods.png``, screenshots of ``stereovision
  gui`` on the bundled cones in headless chromium (Debian's ``/usr/bin/chromium``, driven by
  Playwright): the page after Check rows with the 3-D view turned 15 degrees right and moved
  1 m left, then the page after the Gabor method button and Save. The GUI is started as the
  README tells users to, with ``--data`` on a folder holding a copy of the cones (in a
  temporary folder), so that its Save field offers a folder to write into.

Every picture is written as an optimised PNG, with a dithered 256-colour palette where the
full-colour file is larger than :data:`MAX_BYTES`, undithered if that is still larger (then
larger still is an error). Usage: ``python benches/plot_docs_pictures.py [--only demo refine gui]
[--out-dir DIR]``
"""

from __future__ import annotations

import argparse
import io
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
from _common import DATA

ROOT = Path(__file__).resolve().parents[1]
OUT_DIR = ROOT / "docs" / "images"
PICTURES = ("demo", "refine", "gui")
#: Largest PNG written (bytes): larger ones are written with a 256-colour palette.
MAX_BYTES = 300_000

#: refine: the scenes (rows), the colour scale's top and the panels' width in pixels.
REFINE_SCENES = ("eth3d/terrace", "kitti2015/000005_10")
REFINE_TOP = 0.10
PANEL_WIDTH = 420

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--no-first-run",
    "--disable-component-update",
    "--disable-sync",
]
VIEWPORT = {"width": 1500, "height": 950}
TIMEOUT_S = 120


def save_png(image: Any, out: Path) -> Path:
    """Write a PIL image (or an ``(H, W, 3)`` RGB ``uint8`` array) to ``out`` as an optimised
    PNG, with a 256-colour palette when the full-colour file exceeds :data:`MAX_BYTES`."""
    from PIL import Image

    im = Image.fromarray(image) if isinstance(image, np.ndarray) else image.convert("RGB")
    buf = io.BytesIO()
    im.save(buf, "PNG", optimize=True)
    palette = None  # made only for a file too large (seconds of CPU: 2 s for demo_render)
    for dither in (Image.Dither.FLOYDSTEINBERG, Image.Dither.NONE):  # dithered if it fits
        if buf.tell() <= MAX_BYTES:
            break
        if palette is None:
            palette = im.quantize(256, method=Image.Quantize.MEDIANCUT, kmeans=2)
        buf = io.BytesIO()
        im.quantize(palette=palette, dither=dither).save(buf, "PNG", optimize=True)
    if buf.tell() > MAX_BYTES:
        raise ValueError(f"{out.name}: {buf.tell()} bytes even with 256 colours (> {MAX_BYTES})")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(buf.getvalue())
    print(f"{out} ({out.stat().st_size // 1000} KB)")
    return out


# ------------------------------------------------------------------------------------ demo


def draw_demo(out_dir: Path) -> None:
    """``stereovision demo``'s disparity.png, render.png and overview.png, as the demo writes
    them."""
    from PIL import Image

    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "stereovision", "demo", "-o", tmp]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        for name in ("disparity", "render", "overview"):
            save_png(Image.open(Path(tmp) / f"{name}.png"), out_dir / f"demo_{name}.png")


# ---------------------------------------------------------------------------------- refine


def _error_panel(left: np.ndarray, depth: np.ndarray, gt: np.ndarray) -> np.ndarray:
    """RGB ``uint8``: the darkened grey left image, ``|dZ|/Z`` in turbo where both depths are."""
    import matplotlib

    grey = left.mean(axis=-1) / 255.0 * 0.35
    rgb = np.repeat(grey[..., None], 3, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        both = np.isfinite(depth) & (depth > 0) & np.isfinite(gt) & (gt > 0)
        rel = np.where(both, np.abs(depth - gt) / gt, 0.0)
    colours = matplotlib.colormaps["turbo"](np.clip(rel / REFINE_TOP, 0, 1))[..., :3]
    rgb[both] = colours[both]
    return (255 * rgb).astype(np.uint8)


def draw_refine(out_dir: Path) -> None:
    """The depth-error figure of refine.md, gabor.md and the README."""
    import matplotlib

    matplotlib.use("Agg")
    import cv2
    import matplotlib.pyplot as plt

    from stereovision.baselines import opencv_sgbm
    from stereovision.depth import depth_map
    from stereovision.evaluate import depth_metrics, gt_depth, saturated_gt_depth
    from stereovision.io import load_scene
    from stereovision.triangulation import depth_from_disparity

    rows: list[list[tuple[str, np.ndarray]]] = []
    for name in REFINE_SCENES:
        sc = load_scene(DATA / name)
        assert sc.gt is not None and sc.calib is not None, name
        md = sc.max_disparity
        gt = gt_depth(sc.gt, sc.calib)
        # float16's largest depth (TartanAir's sky, 65504 m) is a clamp, not a distance: no GT,
        # as `stereovision eval` has it (its error panel and figures left out alike)
        gt[saturated_gt_depth(gt)] = np.nan
        maps = {
            "gabor, refine=False": depth_map(
                sc.left, sc.right, sc.calib, max_disparity=md, method="gabor", refine=False
            ).depth,
            "gabor (refined, its default)": depth_map(
                sc.left, sc.right, sc.calib, max_disparity=md, method="gabor"
            ).depth,
            "OpenCV SGBM-3WAY": depth_from_disparity(opencv_sgbm(sc.left, sc.right, md), sc.calib),
        }
        row = []
        family = name.split("/")[0]
        for label, depth in maps.items():
            assert depth is not None, label
            m = depth_metrics(depth, gt)
            title = (
                f"{family} {label}: median {m.median_rel:.2f} %, >5 %: {m.share_off_5:.1f} %, "
                f"{m.n} px"
            )
            panel = _error_panel(sc.left[..., ::-1], depth, gt)
            h, w = panel.shape[:2]
            size = (PANEL_WIDTH, round(h * PANEL_WIDTH / w))
            row.append((title, cv2.resize(panel, size, interpolation=cv2.INTER_AREA)))
        rows.append(row)
    heights = [r[0][1].shape[0] for r in rows]
    dpi = 100
    cols = len(rows[0])
    title_px, bar_px = 22, 40
    fig_w = cols * PANEL_WIDTH / dpi
    fig_h = (sum(heights) + title_px * len(rows) + bar_px) / dpi
    fig = plt.figure(figsize=(fig_w, fig_h), dpi=dpi)
    top = fig_h * dpi
    for row, h in zip(rows, heights, strict=True):
        top -= title_px + h
        for c, (title, img) in enumerate(row):
            ax = fig.add_axes((c / cols, top / (fig_h * dpi), 1 / cols, h / (fig_h * dpi)))
            ax.imshow(img, interpolation="nearest")
            ax.set_axis_off()
            ax.set_title(title, fontsize=7.5, loc="left", pad=3)
    cax = fig.add_axes((0.08, 12 / (fig_h * dpi), 0.25, 12 / (fig_h * dpi)))
    scale = matplotlib.colormaps["turbo"](np.linspace(0, 1, 256))[None, :, :3]
    cax.imshow(scale, aspect="auto", extent=(0, 100 * REFINE_TOP, 0, 1))
    cax.set_yticks([])
    cax.tick_params(labelsize=7, length=2, pad=1)
    fig.text(0.005, 14 / (fig_h * dpi), "|dZ|/Z (%)", fontsize=7.5)
    fig.text(
        0.345,
        14 / (fig_h * dpi),
        f">= {100 * REFINE_TOP:g} % in the top colour; dark: no depth reported or no GT",
        fontsize=7.5,
    )
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    from PIL import Image

    save_png(Image.open(buf), out_dir / "refine_depth_error.png")


# ------------------------------------------------------------------------------------- gui


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


#: The ``--data`` folder of the GUI pictures, relative to the server's working folder (a
#: temporary one): it holds a copy of the bundled cones, as the README's ``--data ~/scenes``.
GUI_DATA = "scenes"


def gui_command(workdir: Path, port: int) -> list[str]:
    """The ``stereovision gui`` command of the pictures, run in ``workdir``.

    Copies the bundled cones into ``workdir/scenes/cones`` and gives ``--data scenes``, as the
    README tells users to start the GUI: its Save field offers ``scenes/saved`` (relative to
    the working folder, as the page shows a folder under it).
    """
    import shutil

    from stereovision.gui import bundled_data_dir

    shutil.copytree(bundled_data_dir() / "cones", workdir / GUI_DATA / "cones")
    gui = [sys.executable, "-m", "stereovision.gui", "--port", str(port), "--no-browser"]
    return [*gui, "--data", GUI_DATA]


@contextmanager
def gui_server(workdir: Path) -> Iterator[str]:
    """``stereovision gui --data scenes`` (:func:`gui_command`) in ``workdir`` on a free local
    port; yields its URL."""
    port = _free_port()
    cmd = gui_command(workdir, port)
    proc = subprocess.Popen(
        cmd, cwd=workdir, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    try:
        end = time.monotonic() + TIMEOUT_S
        while True:
            if proc.poll() is not None:
                out = proc.stdout.read() if proc.stdout else ""
                raise RuntimeError(f"gui server exited early:\n{out}")
            with socket.socket() as s:
                if s.connect_ex(("127.0.0.1", port)) == 0:
                    break
            if time.monotonic() > end:
                raise TimeoutError(f"gui server did not listen on {port} within {TIMEOUT_S} s")
            time.sleep(0.1)  # polling a condition
        yield f"http://127.0.0.1:{port}/"
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def _wait_ready(pg: Any, computations: int) -> None:
    pg.wait_for_function(
        f"Number(document.querySelector('#computations')?.textContent) >= {computations}"
        " && document.querySelector('#status')?.textContent.trim() === 'ready'"
    )


def _view(pg: Any) -> np.ndarray:
    from PIL import Image

    shot = pg.locator("#view-3d").screenshot()
    return np.asarray(Image.open(io.BytesIO(shot)).convert("RGB"), dtype=np.int16)


def _wait_view_change(pg: Any, before: np.ndarray, min_change: float = 5.0) -> None:
    """Poll the streamed 3-D frame until it differs from ``before`` (the server renders it)."""
    end = time.monotonic() + TIMEOUT_S
    while time.monotonic() < end:
        now = _view(pg)
        if now.shape != before.shape or float(np.abs(now - before).mean()) > min_change:
            time.sleep(0.5)  # the last of the stream's frames (a still picture from here on)
            return
    raise TimeoutError("the 3-D view did not change")


def _slide(pg: Any, name: str, key: str, steps: int, value: str) -> None:
    thumb = f"#slider-{name} [role=slider]"
    pg.focus(thumb)
    for _ in range(steps):
        pg.keyboard.press(key)
    pg.wait_for_function(
        f"document.querySelector('{thumb}').getAttribute('aria-valuenow') === '{value}'"
    )


def draw_gui(out_dir: Path) -> None:
    """The two GUI screenshots of the README."""
    from PIL import Image
    from playwright.sync_api import sync_playwright

    if not CHROMIUM.exists():
        raise FileNotFoundError(f"{CHROMIUM} not found (apt-get install -y chromium)")
    # the Save field shows scenes/saved, relative to this working folder
    with (
        tempfile.TemporaryDirectory(prefix="sv-") as work,
        gui_server(Path(work)) as url,
        sync_playwright() as p,
    ):
        browser = p.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        pg = browser.new_page(viewport=VIEWPORT)
        pg.set_default_timeout(TIMEOUT_S * 1000)
        pg.goto(url)
        _wait_ready(pg, 1)
        pg.wait_for_function(
            "[...document.querySelectorAll('#view-3d img')].some(i => i.src && i.naturalWidth > 0)"
        )
        pg.click("#check-rows-btn")
        pg.wait_for_function(
            "document.querySelector('#rows-label')?.textContent.includes('rectification')"
        )
        first = _view(pg)
        _slide(pg, "yaw", "ArrowRight", 15, "15")
        _slide(pg, "right", "ArrowLeft", 20, "-1")
        pg.locator("body").click(position={"x": 5, "y": 5})  # no focus ring on a thumb
        _wait_view_change(pg, first)
        save_png(Image.open(io.BytesIO(pg.screenshot())), out_dir / "gui-3d.png")
        turned = _view(pg)
        pg.click("#reset-camera")
        pg.click("#method-gabor")
        _wait_ready(pg, 2)
        _wait_view_change(pg, turned)  # back at the left camera, the Gabor map's surface
        pg.click("#save-btn")  # into the offered folder: scenes/saved
        pg.wait_for_function(
            "document.querySelector('#save-label')?.textContent.startsWith('saved ')"
        )
        pg.locator("body").click(position={"x": 5, "y": 5})
        save_png(Image.open(io.BytesIO(pg.screenshot())), out_dir / "gui-methods.png")
        browser.close()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="+", choices=PICTURES, default=list(PICTURES))
    ap.add_argument("--out-dir", type=Path, default=OUT_DIR)
    args = ap.parse_args()
    draw = {"demo": draw_demo, "refine": draw_refine, "gui": draw_gui}
    for name in PICTURES:
        if name in args.only:
            draw[name](args.out_dir)


if __name__ == "__main__":
    main()
