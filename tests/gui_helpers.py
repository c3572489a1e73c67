"""Helpers shared by the GUI tests: test_gui_app.py (in process), test_gui_browser.py (chromium)
and test_gui_sources.py."""

from __future__ import annotations

import base64
from pathlib import Path

import cv2
import numpy as np

REPO = Path(__file__).resolve().parents[1]
CONES = REPO / "python" / "stereovision" / "data" / "cones"

#: Generated camera videos: this many frames, each rolled down by this many rows (both cameras
#: alike, so rows stay aligned and every capture shows a visibly different pair).
VIDEO_FRAMES = 3
VIDEO_ROLL = 25

#: Upper bound (s) for a started gui server to announce its address.
STARTUP_TIMEOUT_S = 60


def write_video(path: Path, image: np.ndarray, frames: int = VIDEO_FRAMES) -> Path:
    """Write ``frames`` MJPG frames of ``image``, each rolled ``VIDEO_ROLL`` rows further."""
    h, w = image.shape[:2]
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 5, (w, h))
    assert writer.isOpened(), "OpenCV cannot write MJPG video here"
    for k in range(frames):
        writer.write(np.roll(image, VIDEO_ROLL * k, axis=0))
    writer.release()
    return path


def decode_data_url(data_url: str) -> np.ndarray:
    """The BGR picture (int16) of a ``data:image/...;base64,`` URL as the page shows it."""
    raw = base64.b64decode(data_url.split(",", 1)[1])
    img = cv2.imdecode(np.frombuffer(raw, np.uint8), cv2.IMREAD_COLOR)
    assert img is not None
    return img.astype(np.int16)
