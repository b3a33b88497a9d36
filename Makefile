# Two commands do all set-up (README): `make lab` opens the workbook, `make test` runs the tests.
# `make bench` runs the benchmarks of the packaged checkpoints (slow: tens of minutes on 2 cores).
# All create .venv on first use; nothing else needs installing by hand.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: lab test bench env clean-env

env: $(STAMP)

# torch==2.13.0 is pinned in requirements.txt (an unpinned torch pulls CUDA wheels).
$(STAMP): requirements.txt pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -r requirements.txt
	$(BIN)/python -m pip install --quiet --no-deps -e .
	@touch $(STAMP)

# (--allow-root only where you are root, e.g. in a container; mslib.cpu_paths: the numeric code path
# the stored outputs were written with, meant to let an AVX-512 laptop print what they show)
lab: $(STAMP)
	$(BIN)/python -m mslib.cpu_paths $(BIN)/jupyter lab notebooks/ $(if $(filter 0,$(shell id -u)),--allow-root)

# Unit tests and strict nbval over every notebook, one pytest run; .ci/run runs this.
# The benchmarks (tests marked `bench`, see pyproject.toml) are left to `make bench`.
test: $(STAMP)
	$(BIN)/python -m pytest tests notebooks --nbval --nbval-current-env \
		--nbval-sanitize-with nbval_sanitize.cfg -m "not bench" -q

# The benchmark table of every method on the default draw (the README's), then every method's bars.
bench: $(STAMP)
	$(BIN)/python -m mslib bench --method all --seed 0 --pairs 200 --markdown
	$(BIN)/python -m pytest tests -m bench -q

clean-env:
	rm -rf $(VENV)
