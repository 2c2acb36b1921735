"""Every tunable of the pipeline, with the paper's defaults (Table I), grouped like Table I.

``Params`` is frozen; change it with :func:`dataclasses.replace` or :meth:`Params.updated`.
It round-trips to YAML; unknown keys and out-of-range values are refused with a message that
names the key (and the file when loading one).
"""

from workstation.params.model import (
    COMPASS_HEADING,
    GROUPS,
    GYRO_HEADING,
    AccLandmarkParams,
    BaroLandmarkParams,
    BeliefParams,
    GyroLandmarkParams,
    HeadingParams,
    LocalizeParams,
    Params,
    PDRParams,
    RadioMapParams,
    StepParams,
)

__all__ = ["AccLandmarkParams", "BaroLandmarkParams", "BeliefParams", "COMPASS_HEADING", "GROUPS",
           "GYRO_HEADING", "GyroLandmarkParams", "HeadingParams", "LocalizeParams", "PDRParams",
           "Params", "RadioMapParams", "StepParams"]  # fmt: skip
