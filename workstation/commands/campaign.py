"""``workstation campaign run``: every walk of many buildings, in parallel."""

from __future__ import annotations

from workstation.io.store import path_or_url


def add_parser(sub) -> None:
    from workstation.fingerprints.kinds import DEFAULT_KIND, KINDS

    c = sub.add_parser(
        "campaign",
        help="many walks of many buildings, on Dask (or a local process pool)",
        description="CAMPAIGN is a folder buildings/<name>/{graph.yaml, walks/} or a YAML file "
        "listing buildings (see workstation/campaign/layout.py). Unchanged walks are not re-run.",
    )
    cs = c.add_subparsers(dest="campaign_command", required=True)
    r = cs.add_parser("run", help="run (or resume) a campaign")
    r.add_argument("campaign", type=path_or_url, help="a folder, a YAML file or a store URL "
                   "(s3://bucket/campaign/; pip install -e .[store])")
    r.add_argument("--out", type=path_or_url, required=True,
                   help="the output folder, or a store prefix (s3://bucket/out/)")
    r.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler (tcp://…)")
    r.add_argument("--workers", type=int, help="local workers (default: one per core)")
    r.add_argument("--force", action="store_true", help="re-run every walk")
    r.add_argument("--kind", default=DEFAULT_KIND, choices=list(KINDS),
                   help="the kind of map each building's radiomap/ is, built from its walks' "
                   f"points (default {DEFAULT_KIND}; fingerprints/kinds.py)")  # fmt: skip
    r.set_defaults(func=_run)


def _run(args) -> int:
    from workstation.campaign import run_campaign
    from workstation.progress import Progress
    bar = Progress()
    try:
        rep = run_campaign(args.campaign, args.out, args.scheduler, args.workers, args.force,
                           say=bar.write, progress=bar, kind=args.kind)  # fmt: skip
    except OSError as e:  # a full disk, a folder not writable: which file, and that it resumes
        bar.close()
        raise OSError(
            e.errno,
            f"{e.strerror or e} — every walk finished before this is stored in {args.out}; "
            "free the space and run the same command again: it resumes where it stopped",
            e.filename or str(args.out),
        ) from e
    bar.close()
    for name, b in rep.buildings.items():
        lo = b.leave_one_out or {}
        extra = (
            f", leave-one-out {lo.get('mean_m')} m (floor right), "
            f"{lo.get('mean_with_floor_penalty_m')} m with floor penalty"
            if lo
            else ""
        )
        print(
            f"  {name}: {b.walks_ok}/{b.walks} walks, {b.reference_points} RPs{extra}"
            + (
                f"; {b.walks_quarantined} need the surveyor (campaign.md)"
                if b.walks_quarantined
                else ""
            )  # fmt: skip
        )
    return 0 if rep.failed == 0 else 1
