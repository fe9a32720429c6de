# mechsys — set-up, demo, tests, benchmarks. Needs only python3 (3.11), cargo and pip.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.deps-stamp
BUILD  := $(VENV)/.build-stamp
CORE_SOURCES := $(shell find crates -name '*.rs' -o -name Cargo.toml) Cargo.toml Cargo.lock pyproject.toml .cargo/config.toml

.PHONY: all demo test test-rust test-python bench bench-rust build clean viewer docs

all: build

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet "maturin>=1.7,<2" numpy scipy matplotlib h5py click tqdm trimesh yourdfpy pytest sympy pandas xarray pin playwright mujoco exudyn mkdocs "mkdocstrings[python]"
	$(PY) -m pip install --quiet "dask[distributed]"  # parameter studies on a Dask cluster (tests/test_study.py)
	touch $(STAMP)

# The core in release mode, installed into the venv as an editable package.
$(BUILD): $(STAMP) $(CORE_SOURCES)
	VIRTUAL_ENV=$(abspath $(VENV)) PATH=$(abspath $(VENV))/bin:$$PATH $(VENV)/bin/maturin develop --release --quiet
	touch $(BUILD)

# The browser viewer's JavaScript (three.js, uPlot and viewer/src), bundled from the pinned npm
# packages into the Python package's data; skipped with a note where npm is missing.
VIEWER_JS := python/mechsys/viewer/_bundle/viewer.js
$(VIEWER_JS): viewer/package.json viewer/package-lock.json $(wildcard viewer/src/*.js)
	@if command -v npm >/dev/null 2>&1; then \
		cd viewer && npm ci --no-audit --no-fund --loglevel=error && npm run --silent build && \
		cp node_modules/uplot/dist/uPlot.min.css ../python/mechsys/viewer/_bundle/; \
	else echo "note: npm not found, the browser viewer (mechsys view) is not built"; fi

viewer: $(VIEWER_JS)

build: $(BUILD) viewer

# The guides and the API reference from the docstrings into site/; --strict fails on a broken link or reference.
docs: $(STAMP)
	$(VENV)/bin/mkdocs build --strict

demo: build
	$(PY) examples/woodpecker.py

test: build
	cargo test -p mechsys-core
	$(PY) -m pytest -q tests

bench-rust:
	cargo bench -p mechsys-core --bench dynamics

bench: $(BUILD)
	$(PY) -m pip install --quiet pin mujoco exudyn pybullet
	$(PY) benches/run_all.py --out docs/benchmarks.md

clean:
	rm -rf $(VENV) target results site
