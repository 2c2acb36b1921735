"""Campaigns: many walks of many buildings, run in parallel on Dask distributed (a LocalCluster
sized to the machine, or an existing scheduler), or on a local process pool when Dask is not
installed. ``workstation campaign run CAMPAIGN --out DIR``.

- Incremental: a walk whose inputs (walk, graph, params, building file) and code are unchanged
  is not re-run, failed or not (content digests in ``DIR/state.json``); ``force`` re-runs all.
- Faults: a walk that fails is recorded with its error and the others go on; each result is
  written as it arrives (atomically), so a killed run resumes where it stopped.
- A second pass: each walk whose start is given runs again with the map of its building's other
  walks (their first runs, ``first.parquet``; quarantined walks have none) as evidence on its
  chain of matches (:mod:`..pipeline.map_prior`).
- Walks recorded one after another: then an ambiguous walk recorded right after a certain one
  has its start searched within walking reach of where that one ended (:mod:`.handover`).
- In object storage (issue #54): the campaign, its walks and ``--out`` may be fsspec URLs
  (``s3://bucket/campaign/``, ``--out s3://bucket/out/``); the workers read each walk from the
  store and write its maps there (:mod:`.jobs`), the client gathers only summaries. One run at a
  time writes to an output (:mod:`.lock`); ``state.json`` is written after a walk's files, so
  what it lists is whole; walks are known unchanged by ETag there, by content here.
- Outputs: ``walks/<building>/<walk>/`` (summary.json, map.parquet, queries.parquet), the
  merged radio map per building as a Parquet dataset partitioned by building and floor
  (``radiomap/building=…/floor=…/``, device offsets aligned), ``campaign.json`` and
  ``campaign.md`` (per walk: status, steps, matches, RPs, errors; per building: map size and the
  leave-one-walk-out figures where walks have ground truth).
"""

from workstation.campaign.layout import BuildingSpec, load_campaign
from workstation.campaign.run import plan_jobs, run_campaign, walk_keys

__all__ = ["BuildingSpec", "load_campaign", "plan_jobs", "run_campaign", "walk_keys"]
