"""The libraries imported only inside the functions that use them (issue #31): each costs
0.2–1.5 s at start-up, and most commands never touch them (``workstation run`` draws no
figure, ``workstation --help`` starts no viewer). Every other import is at a module's top:
``tests/test_imports.py`` checks that an import inside a function loads one of these, directly
or through a module of ours whose top level does."""

HEAVY = (
    "dask",
    "fsspec",  # object stores (io/store.py): s3fs, botocore and aiohttp behind it
    "upath",  # paths in object stores (io/store.py; the optional [store] extra)
    "distributed",  # the campaign's workers
    "matplotlib",  # figures (evaluate, quality, plan)
    "networkx",  # the graph as a DiGraph: survey plans (70 ms, which every `run` paid)
    "numba",  # the compiled kernels (1-NN, route search)
    "pandas",
    "pyarrow",  # parquet exports and the bulk reader
    "PIL",  # plan images
    "playwright",  # screenshots
    "rerun",  # the viewer
    "scipy",
    "viser",  # the panel
    "websockets",  # viser's server, hooked for the origin check
)

# the subcommands: each imports what its body needs when it runs (issue #53: the parser loaded
# every command's modules, networkx and the campaign's among them, 0.5 s before `--help`)
LAZY = "workstation.commands."
