# Two commands do all set-up on a fresh machine:  make demo   and   make test
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
OUT ?= out

.PHONY: install demo test bench lint layouts samples clean

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[dev]'
	-$(BIN)/rerun analytics disable >/dev/null 2>&1
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/python -m workstation demo --out $(OUT)

test: $(STAMP)
	$(BIN)/ruff check workstation tests benchmarks
	$(BIN)/mypy
	$(BIN)/python -m pytest -q -n auto --maxprocesses 4 --dist loadfile

bench: $(STAMP)
	$(BIN)/python benchmarks/run.py

layouts: $(STAMP)
	$(BIN)/workstation layouts --out layouts

samples: $(STAMP)
	for w in normal varied heldout survey5 survey10; do \
	  $(BIN)/workstation simulate --building office2f --walk $$w --seed 1 --out sample_sessions/office2f/$$w; done

lint: $(STAMP)  # also the first two steps of make test
	$(BIN)/ruff check workstation tests benchmarks
	$(BIN)/mypy

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache .hypothesis
