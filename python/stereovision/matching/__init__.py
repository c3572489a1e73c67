"""Correspondence channels (algorithms.md A-D). Today: the Gabor phase-disparity channel."""

from stereovision.matching.gabor import GaborResult, gabor_disparity

__all__ = ["GaborResult", "gabor_disparity"]
