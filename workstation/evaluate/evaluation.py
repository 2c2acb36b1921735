"""What the built-in ``workstation evaluate`` gives (results.json's document): the paper's
experiments on the simulated office, the robustness and density tables, and the museum's walks
left out one at a time, with their starts given and inferred."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from workstation.evaluate.paper import Simulated
from workstation.evaluate.robustness import DensityRow, RobustnessRow
from workstation.evaluate.walks import LooResult


@dataclass(frozen=True)
class Evaluation:
    """The built-in run's results (module docstring); :meth:`to_json` is results.json."""

    model: str  # the simulator's model
    simulated: Simulated
    robustness: tuple[RobustnessRow, ...]
    density: tuple[DensityRow, ...]
    walks: LooResult | None  # the museum (None: ../shared/data absent)
    walks_start_inferred: LooResult | None

    def to_json(self) -> dict[str, Any]:
        """results.json."""
        return {
            "model": self.model,
            "simulated": self.simulated.to_json(),
            "robustness": [dataclasses.asdict(r) for r in self.robustness],
            "density": [dataclasses.asdict(r) for r in self.density],
            "walks": self.walks.to_dict() if self.walks else None,
            "walks_start_inferred": (
                self.walks_start_inferred.to_dict() if self.walks_start_inferred else None
            ),
        }
