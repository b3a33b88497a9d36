# Two commands do all set-up (README): `make lab` opens the workbook, `make test` runs the tests.
# `make bench` runs the benchmarks of the packaged checkpoints (slow: tens of minutes on 2 cores).
# `make release` hands the workbook out as an nbgrader course, `make grade DIR=...` grades what comes back
# (notebooks/INSTRUCTORS.md). All create .venv on first use; nothing else needs installing by hand.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
INSTRUCTOR := $(VENV)/.instructor-installed

.PHONY: lab test bench env release grade clean-env

env: $(STAMP)

# torch==2.13.0 is pinned in requirements.txt (an unpinned torch pulls CUDA wheels).
$(STAMP): requirements.txt pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -r requirements.txt
	$(BIN)/python -m pip install --quiet --no-deps -e .
	@touch $(STAMP)

# nbgrader (requirements-instructor.txt) is for whoever hands out and grades the workbook, and for the tests of
# tools/release.py: it is installed on top of the students' environment, which never needs it.
$(INSTRUCTOR): requirements-instructor.txt $(STAMP)
	$(BIN)/python -m pip install --quiet -r requirements-instructor.txt
	@touch $(INSTRUCTOR)

# (--allow-root only where you are root, e.g. in a container; mslib.cpu_paths: the numeric code path
# the stored outputs were written with, meant to let an AVX-512 laptop print what they show)
lab: $(STAMP)
	$(BIN)/python -m mslib.cpu_paths $(BIN)/jupyter lab notebooks/ $(if $(filter 0,$(shell id -u)),--allow-root)

# Unit tests and strict nbval over every notebook, one pytest run; .ci/run runs this.
# The benchmarks (tests marked `bench`, see pyproject.toml) are left to `make bench`.
# tests/test_release.py grades with nbgrader, hence the instructor's packages.
test: $(STAMP) $(INSTRUCTOR)
	$(BIN)/python -m pytest tests notebooks --nbval --nbval-current-env \
		--nbval-sanitize-with nbval_sanitize.cfg -m "not bench" -q

# The benchmark table of every method on the default draw (the README's), then every method's bars.
bench: $(STAMP)
	$(BIN)/python -m mslib bench --method all --seed 0 --pairs 200 --markdown
	$(BIN)/python -m pytest tests -m bench -q

# The nbgrader course in course/ (git-ignored): the student version is course/release/workbook/.
# An existing course is rebuilt only with FORCE=1 (its submissions and grades stay).
release: $(INSTRUCTOR)
	$(BIN)/python tools/release.py release $(if $(FORCE),--force)

# DIR holds one folder per student with the notebooks handed back; prints the points per notebook.
# A student graded before is graded again only with FORCE=1.
grade: $(INSTRUCTOR)
	@test -n "$(DIR)" || { echo "usage: make grade DIR=SUBMISSIONS_DIR (one folder per student)" >&2; exit 2; }
	$(BIN)/python tools/release.py grade "$(DIR)" $(if $(FORCE),--force)

clean-env:
	rm -rf $(VENV)
