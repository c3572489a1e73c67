# stereovision: one front door for build, demo, test, lint and bench.  `make help` lists targets.
SHELL := /bin/bash
VENV ?= .venv
PY := $(VENV)/bin/python
PIP := $(PY) -m pip
STAMP := $(VENV)/.deps-stamp
BUILD_STAMP := $(VENV)/.build-stamp
RUST_SRC := $(shell find rust -name '*.rs' -o -name Cargo.toml) Cargo.toml pyproject.toml
PY_SRC := $(shell find python -type f -not -name '*.so' -not -path '*/__pycache__/*')

# A fresh CI build never reuses rustc's incremental caches; not writing them cuts the core's debug
# test build by about 9 % of CPU (56.5/61.2 -> 51.4/56.2 s user+sys, alternated). Local builds keep them.
ifdef CI
export CARGO_INCREMENTAL ?= 0
endif

.PHONY: help system-deps setup build demo test test-rust test-py test-py-live lint fmt bench clean

help:  ## list targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | awk -F':.*## ' '{printf "  %-10s %s\n", $$1, $$2}'

SYS_STAMP := $(VENV)/.sys-stamp

# Headless Chromium for the browser tests (report and GUI pages). Debian's package: never a
# browser download. Skipped with a warning where apt is unavailable (tests then skip, not fail).
$(SYS_STAMP):
	@mkdir -p $(VENV)
	@if command -v chromium >/dev/null 2>&1; then echo "chromium: present"; \
	elif command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) \
	  || echo "warning: could not install chromium; browser tests will be skipped"; \
	else echo "warning: chromium missing and apt-get unavailable; browser tests will be skipped"; fi
	@touch $@

system-deps: $(SYS_STAMP)  ## install Debian packages the tests use (chromium)

$(STAMP): pyproject.toml requirements-dev.txt
	test -x $(PY) || python3 -m venv $(VENV)
	$(PIP) install -q --upgrade pip
	$(PIP) install -q -r requirements-dev.txt
	touch $@

setup: $(STAMP)  ## create .venv with the build and test tools

$(BUILD_STAMP): $(STAMP) $(RUST_SRC) $(PY_SRC)
	$(PY) -m maturin build --release --quiet -o target/wheels
	$(PIP) install -q --force-reinstall --no-deps $$(ls -t target/wheels/stereovision_rs-*.whl | head -1)
	$(PIP) install -q $$(ls -t target/wheels/stereovision_rs-*.whl | head -1)
	touch $@

build: $(BUILD_STAMP)  ## build the Rust extension (release) and install the package into .venv

demo: build  ## run the demo on the bundled scene (no camera, no network)
	$(VENV)/bin/stereovision demo -o demo_output

test-rust:  ## cargo test of the pure-Rust core
	cargo test --quiet

lint: $(STAMP)  ## cargo fmt/clippy, ruff, mypy
	cargo fmt --all -- --check
	cargo clippy --workspace --all-targets --quiet -- -D warnings
	$(VENV)/bin/ruff check python tests benches
	$(VENV)/bin/ruff format --check python tests benches
	$(VENV)/bin/mypy

PYTEST := $(PY) -m pytest -q -n auto --dist loadfile --durations=5

test-py: build  ## pytest (parity, API, CLI, accuracy)
	$(PYTEST)

# The core's debug test build and run and the linters overlap the venv's set-up and the release
# build: pip, mypy and the release build's link steps use one core, and cargo locks each
# profile's folder apart (clippy and cargo test share one: they take turns). pytest starts
# when the build is done, beside the linters if they still run (they finished last, and
# pytest waited for them with a core idle).
test: system-deps  ## everything CI runs
	$(MAKE) --no-print-directory -j2 --output-sync=target build test-rust lint test-py-live

# test-py inside make test's -Otarget: `+` shows pytest's progress as it goes instead of
# holding it to the end (the catch of `+`: `make -n test` runs pytest)
test-py-live: build
	+$(PYTEST)

fmt:  ## format Rust and Python in place
	cargo fmt --all
	$(VENV)/bin/ruff format python tests benches
	$(VENV)/bin/ruff check --fix python tests benches

bench: build  ## criterion benches of the kernels, then the Python benches against OpenCV
	cargo bench
	$(VENV)/bin/stereovision bench ../shared/data
	$(PY) benches/bench_gabor_vs_sgbm.py
	$(PY) benches/bench_hopfield.py
	$(PY) benches/bench_mcgm.py
	$(PY) benches/bench_fusion.py
	$(PY) benches/bench_scaling.py

clean:  ## remove build products (keeps .venv)
	rm -rf target $(BUILD_STAMP) demo_output
