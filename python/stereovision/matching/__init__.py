"""Correspondence channels (algorithms.md A-D): Gabor phase disparity (A), multi-channel graph
matching (B), Hopfield network (C)."""

from stereovision.matching.gabor import GaborResult, gabor_disparity
from stereovision.matching.hopfield import hopfield_match, interest_points
from stereovision.matching.mcgm import mcgm_match

__all__ = [
    "GaborResult",
    "gabor_disparity",
    "hopfield_match",
    "interest_points",
    "mcgm_match",
]
