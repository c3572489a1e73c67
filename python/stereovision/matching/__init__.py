"""Correspondence channels (algorithms.md A-D): Gabor phase disparity (A), multi-channel graph
matching (B), Hopfield network (C); and the census semi-global matcher the fused dense map is
completed with (``sgm``).

A disparity range past the image: :func:`stereovision.match` and
:func:`stereovision.depth_map` refuse one not below the pair's width ("disparity range 200 is
not smaller than the image width 96: ..."), as a range that pair cannot hold; the functions
here search it to the image's edge without a word (``max_disparity`` 200 on a 96 px wide pair
gives the map of 96), by design: they also run on crops of a scene (the benches, the parity
tests), whose range may be wider than the crop, and a crop's result is what it can see. A
range wholly past the image (``min_disparity`` at or beyond the width) is refused by both, in
the same words.
"""

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
