"""Correspondence channels (algorithms.md A-D). Gabor phase disparity (A), Hopfield network (C)."""

from stereovision.matching.gabor import GaborResult, gabor_disparity
from stereovision.matching.hopfield import hopfield_match, interest_points

__all__ = ["GaborResult", "gabor_disparity", "hopfield_match", "interest_points"]
