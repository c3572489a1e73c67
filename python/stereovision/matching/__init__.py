"""Correspondence channels (algorithms.md A-D): Gabor phase disparity (A), multi-channel graph
matching (B), Hopfield network (C); and the census semi-global matcher the fused dense map is
completed with (``sgm``)."""

from stereovision.matching.gabor import GaborResult, gabor_disparity
from stereovision.matching.hopfield import hopfield_match, interest_points
from stereovision.matching.mcgm import mcgm_match
from stereovision.matching.sgm import sgm_disparity

__all__ = [
    "GaborResult",
    "gabor_disparity",
    "hopfield_match",
    "interest_points",
    "mcgm_match",
    "sgm_disparity",
]
