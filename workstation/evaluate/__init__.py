"""``workstation evaluate``: the paper's experiments regenerated (simulated office, and the real
IPIN museum walks when ../shared/data is there), or leave-one-walk-out on any set of walks with
ground truth (``--walks``). Writes ``results.json``, ``results.md`` and PNG figures.

``results.json``: ``{"simulated": {...} | null, "walks": LooResult | null}`` (the built-in run
adds ``"walks_start_inferred"``: the museum walks with every start inferred); a LooResult holds
``"loo"``, one object per radio-map kind (``ours``, ``ours_unfiltered``, ``tap_oracle``,
``waypoint_pdr``, ``pdr_i``, and ``tap_oracle_in_map``, ``waypoint_pdr_in_map``: those two
from only the walks our maps hold) with ``floor_accuracy``, ``error_floor_right``
(mean/median/p75/p90 m), ``mean_with_floor_penalty_m``, ``evaal_p75_m``,
``reference_points_per_map``, ``queries`` and ``query_device_offsets_db``; ``placement`` (reference points against the ground truth: accepted,
trusted_segments, untrusted_closed, gap_fill, at_landmark); ``tracking`` (pooled fix metrics),
``tracking_each_walk_alone`` (start ``infer``: before walks that stood together decided their
start; per walk ``start_shared_with``), ``per_walk`` (per walk ``start_off_m``: its start
landmark's distance from its first fix's), ``walks_quarantined``, ``wrong_start_in_map``
(walks in our maps starting on another floor or more than 5 m from their first fix),
``other_start_landmark_in_map`` (those on another landmark nearer than that, by name) and
``matchers``: per method of ``fingerprints.matchers.METHODS``, per kind (``ours``,
``ours_unfiltered``, ``tap_oracle``), ``mean_with_floor_penalty_m`` and
``covered_mean_with_floor_penalty_m``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from workstation.evaluate import walks
from workstation.evaluate.figures import figures
from workstation.evaluate.report_walks import walks_markdown
from workstation.evaluate.robustness import density, robustness
from workstation.evaluate.sigma_check import reliability_figure
from workstation.evaluate.walks import ipin_museum, leave_one_out
from workstation.io.atomic import atomic_write_text
from workstation.params import Params

if TYPE_CHECKING:  # the CLI imports this package to build its parser: keep it light
    from workstation.evaluate.evaluation import Evaluation
    from workstation.evaluate.walks import LooResult
    from workstation.graph import LandmarkGraph
    from workstation.params import Params

__all__ = ["KINDS", "LooResult", "MapKindResult", "evaluate", "evaluate_walks", "leave_one_out"]


def __getattr__(name: str):
    if name in ("KINDS", "LooResult", "MapKindResult", "leave_one_out"):
        return getattr(walks, name)
    raise AttributeError(name)


def evaluate(
    out: str | Path,
    shared_data: str | Path | None = None,
    seed: int = 1,
    params: Params | None = None,
    model: str = "realistic",
    seeds: int = 10,
    progress=None,
) -> Evaluation:
    """The paper's experiments, the robustness and density tables (simulated, ``model``) and
    the museum leave-one-out when the data is there."""
    from workstation.evaluate.evaluation import Evaluation
    from workstation.evaluate.paper import simulated
    from workstation.evaluate.report import markdown

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    params = params or Params()
    say = progress or (lambda i, n, what: None)
    say(0, 1, f"paper's experiments on the simulated office ({model} model)")
    sim = simulated(seed, params, model)
    rob = robustness(seeds, model, params, say)
    den = density(seeds, model, params, say)
    real = inferred = None
    museum = ipin_museum(Path(shared_data)) if shared_data and Path(shared_data).is_dir() else None
    if museum is not None:
        real = leave_one_out(museum[0], museum[1], params, progress=say)
        inferred = leave_one_out(museum[0], museum[1], params, start="infer", progress=say)
    figs = figures(sim, out)
    if real is not None and reliability_figure(
        real.sigma_check.map_points if real.sigma_check else None, out / "sigma_reliability.png"
    ):
        figs["sigma_reliability"] = "sigma_reliability.png"
    result = Evaluation(model, sim, tuple(rob), tuple(den), real, inferred)
    _write(out, result.to_json(), markdown(sim, real, figs, rob, den, model, inferred))
    return result


def evaluate_walks(
    out: str | Path,
    walks: list[Path],
    graph: LandmarkGraph,
    params: Params | None = None,
    start: str = "first-fix",
    progress=None,
    queries_every: int = 0,
    end: str | None = None,
) -> LooResult:
    """Leave-one-walk-out on the given walks (a surveyor's own building), or a split
    (``queries_every``, ``end``: :func:`walks.leave_one_out`)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    res = leave_one_out(walks, graph, params, start, progress, queries_every, end=end)
    lines = walks_markdown(res, "Walks")
    points = res.sigma_check.map_points if res.sigma_check else None
    if reliability_figure(points, out / "sigma_reliability.png"):
        lines += ["", "![σ reliability: the share of the map's points within k σ of the truth]"
                  "(sigma_reliability.png)"]  # fmt: skip
    md = "\n".join(["# Results — leave one walk out", ""] + lines) + "\n"
    _write(out, {"simulated": None, "walks": res.to_dict()}, md)
    return res


def _write(out: Path, result: dict[str, Any], md: str) -> None:
    atomic_write_text(
        out / "results.json", json.dumps(result, indent=2, default=_json_default) + "\n"
    )
    atomic_write_text(out / "results.md", md)


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)
