"""Closed vocabularies read on both sides of a layer: the parameters (``params/``) offer them as
choices and the packages above act on them (``fingerprints/matchers.py``). A value outside one
is refused where the parameters are read, and mypy checks every use against its ``Literal``."""

from __future__ import annotations

from typing import Literal

#: a fingerprint distance (the paper's: euclidean)
MetricName = Literal["euclidean", "sorensen"]
#: fingerprint values: eq. 21's positive ones (the paper's), or powed
Representation = Literal["positive", "powed"]
#: how the k nearest reference points' positions are averaged
Weights = Literal["equal", "inverse-distance"]
