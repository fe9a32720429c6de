# mechsys — set-up, demo, tests, benchmarks. Needs only python3 (3.11), cargo and pip.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.deps-stamp
BUILD  := $(VENV)/.build-stamp
CORE_SOURCES := $(shell find crates -name '*.rs' -o -name Cargo.toml) Cargo.toml Cargo.lock pyproject.toml

.PHONY: all demo test test-rust test-python bench bench-rust build clean

all: build

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet "maturin>=1.7,<2" numpy scipy matplotlib h5py click tqdm trimesh yourdfpy pytest sympy pandas xarray pin
	$(PY) -m pip install --quiet "dask[distributed]"  # parameter studies on a Dask cluster (tests/test_study.py)
	touch $(STAMP)

# The core in release mode, installed into the venv as an editable package.
$(BUILD): $(STAMP) $(CORE_SOURCES)
	VIRTUAL_ENV=$(abspath $(VENV)) PATH=$(abspath $(VENV))/bin:$$PATH $(VENV)/bin/maturin develop --release --quiet
	touch $(BUILD)

build: $(BUILD)

demo: $(BUILD)
	$(PY) examples/woodpecker.py

test: $(BUILD)
	cargo test -p mechsys-core
	$(PY) -m pytest -q tests

bench-rust:
	cargo bench -p mechsys-core --bench dynamics

bench: $(BUILD)
	$(PY) -m pip install --quiet pin mujoco exudyn pybullet
	$(PY) benches/peers.py --out docs/benchmarks.md
	$(PY) benches/constraints.py --out docs/benchmarks.md
	$(PY) benches/contacts.py --out docs/benchmarks.md
	$(PY) benches/stack.py --out docs/benchmarks.md
	$(PY) benches/event_driven.py --baseline benches/baselines/event_driven_50c2cb9.json --out docs/benchmarks.md
	$(PY) benches/linear.py --out docs/benchmarks.md
	$(PY) benches/linear_motion.py --out docs/benchmarks.md
	$(PY) benches/sensors.py --out docs/benchmarks.md
	$(PY) benches/stiff.py --out docs/benchmarks.md
	$(PY) benches/bearing.py --out docs/benchmarks.md
	$(PY) benches/planar.py --out docs/benchmarks.md
	$(PY) benches/study.py --out docs/benchmarks.md

clean:
	rm -rf $(VENV) target results
