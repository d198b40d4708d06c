# Course kit: `make lab` to learn, `make test` to prove it works. Both set up .venv first.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# Jupyter refuses to run as root without --allow-root; only pass it when we are root.
ROOT_FLAG := $(shell [ "$$(id -u)" = 0 ] && echo --allow-root)
# Extra flags for `make lab`, e.g. LAB_ARGS="--no-browser --port=8899".
LAB_ARGS ?=
FIRST_NOTEBOOK := notebooks/01_vector_fields.ipynb

.PHONY: setup lab test test-unit test-nbval test-solutions test-notebooks test-rounding fuzz lint \
	student execute grade bench lock clean

# ... and the kit's own modules compiled (quick when nothing changed; see PYTEST below).
setup: $(STAMP)
	@$(BIN)/python -m compileall -q -j 0 course_lib tests tools benchmarks > /dev/null

# The pinned requirements go in with uv (a pinned wheel from PyPI; it installs in parallel:
# 7 s here against pip's 90) and, if uv cannot be had or fails, with pip, as before.
# --compile-bytecode: the packages' .pyc files are written once, here, as pip does by default
# (uv does not). Without them, where PYTHONDONTWRITEBYTECODE is set (as on this VM and in
# many CI images), every Python that make test starts (kernels, pytest workers, grading
# sandboxes) compiled IPython, pytest, dask... from source again: a kernel started in 4.0 s of
# CPU against 2.3 s with them, measured. It adds about 5 s to the first setup.
UV_VERSION := 0.13.9
PIP := $(BIN)/python -m pip install --quiet --disable-pip-version-check
$(STAMP): requirements.txt pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	@{ $(PIP) uv==$(UV_VERSION) >/dev/null 2>&1 && \
	   $(BIN)/uv pip install --quiet --compile-bytecode --python $(BIN)/python -r requirements.txt && \
	   $(BIN)/uv pip install --quiet --python $(BIN)/python --no-deps -e . && \
	   echo "setup: installed with uv $(UV_VERSION)"; } || \
	 { echo "setup: installing with pip"; $(PIP) -r requirements.txt && $(PIP) --no-deps -e .; }
	@touch $(STAMP)

# jupyter_config/ holds the course's Jupyter settings (a quiet first launch); yours still apply.
lab: $(STAMP)
	JUPYTER_CONFIG_PATH=$(CURDIR)/jupyter_config$${JUPYTER_CONFIG_PATH:+:$$JUPYTER_CONFIG_PATH} \
	$(BIN)/jupyter lab --ServerApp.ip=127.0.0.1 --ServerApp.root_dir=$(CURDIR) \
		--LabApp.default_url=/lab/tree/$(FIRST_NOTEBOOK) $(ROOT_FLAG) $(LAB_ARGS)

# Every test, in stages (each timed; a table at the end says where the time went):
#   setup, lint, unit (unit and property tests, doctests), notebooks (strict nbval of the
#   solutions, each re-run bottom to top in its kernel), second rounding (with NumPy's SIMD
#   kernels one level down, tests/roundings.py: the tests marked roundoff, and each student
#   version paired with its solution, tests/paired.py: the student's cells run top to
#   bottom, those it shares with the solution compared with the solution's stored outputs,
#   then the solution's answers, compared too; so every solution cell is compared strictly
#   and every student cell run, in one kernel per notebook), browser.
# Figures are rasterized once, in the strict pass of the solutions (and in the browser):
# the second rounding runs every cell but draws each PNG as a blank pixel
# (--nbval-skip-raster, tests/skip_raster_startup.py), a third of its running time.
# A failing stage does not stop the later ones; `make test` fails if any failed.
# pytest exits 5 when it collects nothing; tools/stage.py counts that as a pass.
# One BLAS thread per process: two pytest-xdist workers on two cores already fill the
# machine, and OpenBLAS's own threads would fight them (notebook 11's eigenvalue cells
# measured 0.69 s with its threads, 0.05 s without, on a loaded 2-core machine).
# Bytecode: make setup compiles the kit's own modules (compileall) and make test lets
# its Pythons cache what they compile (pytest's rewritten test modules, a kernel's imports) in
# the git-ignored __pycache__ folders even where PYTHONDONTWRITEBYTECODE is set: the suite
# starts some 200 Pythons, and each compiled the same sources again (pytest's collection of
# the unit tests: 15 s of CPU per worker without the caches, 9 s with them, measured).
PYTEST := env -u PYTHONDONTWRITEBYTECODE OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 \
	$(BIN)/python -m pytest
NBVAL  := --nbval-current-env --nbval-sanitize-with tests/sanitize.cfg -p no:cacheprovider
STAGE  := $(PYTHON) tools/stage.py
# Parallel test processes (pytest-xdist); --dist loadfile keeps a file's tests (a
# notebook's cells, a module's shared fixture) on one worker.
# Files start in the order of tests/schedule.py (the costliest first), not xdist's default
# (the files with the most tests first).
JOBS   ?= 2
XDIST  := -n $(JOBS) --dist loadfile --no-loadscope-reorder
# Hypothesis: derandomized in make test (reproducible anywhere), random in make fuzz.
CI_HYPOTHESIS := HYPOTHESIS_PROFILE=ci
ROUNDOFF_TESTS = $(shell grep -l "mark.roundoff" tests/test_*.py)
# Re-runs of each solution after Run All: reverse (every cell after all the later ones
# ran again) keeps make test within 10 minutes; RERUN_ORDERS=reverse,random adds a shuffle.
RERUN_ORDERS ?= reverse
# ... leaving out the cells whose Run All took over RERUN_MAX_SECONDS (the long simulations:
# four fifths of the running time, and rarely where a hidden-state bug lives); inf: all.
RERUN_MAX_SECONDS ?= 1
TEST_STAGES := lint test-unit test-nbval test-rounding test-browser

# Chromium (for the browser stage) and nbgrader's own venv (for the export's tests) are
# made in the background while pip sets up .venv; the tests wait for them on lock files.
# Two stages run alongside others (ALONGSIDE: "stage:from" pairs; the stage starts in the
# background when the loop reaches "from"): the browser stage, which mostly waits (servers,
# pages, kernels), beside the unit tests; the second rounding beside the strict notebook
# stage, whose two workers each wait for their kernel and leave a third of the machine
# idle. Their output is kept in build/alongside-STAGE.log and printed after the loop; the
# summary gives each stage's own times and the elapsed time (less than their sum).
# `make test ALONGSIDE=` runs every stage in turn.
ALONGSIDE ?= test-browser:test-unit test-rounding:test-nbval
BESIDE := $(foreach pair,$(ALONGSIDE),$(firstword $(subst :, ,$(pair))))
test:
	@$(STAGE) reset
	@mkdir -p build && ($(PYTHON) tools/chromium.py > build/chromium-install.log 2>&1 &)
	@($(PYTHON) course_lib/instructor/nbgrader_venv.py .venv-nbgrader > build/nbgrader-venv.log 2>&1 &)
	@$(STAGE) run setup -- $(MAKE) --no-print-directory setup
	@trap 'kill 0' INT TERM; status=0; rm -f build/alongside-*; \
	for stage in $(filter-out $(BESIDE),$(TEST_STAGES)); do \
		for pair in $(ALONGSIDE); do \
			if [ "$${pair#*:}" = "$$stage" ]; then other=$${pair%%:*}; \
				{ $(MAKE) --no-print-directory $$other > build/alongside-$$other.log 2>&1; \
				  echo $$? > build/alongside-$$other.rc; } & fi; done; \
		$(MAKE) --no-print-directory $$stage || status=1; done; \
	wait; for other in $(BESIDE); do \
		echo "== $$other, run alongside the other stages:"; cat build/alongside-$$other.log; \
		[ "$$(cat build/alongside-$$other.rc 2>/dev/null)" = 0 ] || status=1; done; \
	$(STAGE) summary || status=1; exit $$status

test-unit: $(STAMP)
	@$(STAGE) run unit -- env $(CI_HYPOTHESIS) $(PYTEST) $(XDIST) -p no:cacheprovider \
		tests --ignore=tests/browser --doctest-modules course_lib

# Solutions, strict, then re-run in RERUN_ORDERS (the student versions run in test-rounding).
test-nbval: $(STAMP)
	@$(STAGE) run notebooks -- $(PYTEST) $(XDIST) --nbval $(NBVAL) --nbval-rerun=solutions \
		--nbval-rerun-orders=$(RERUN_ORDERS) --nbval-rerun-max-seconds=$(RERUN_MAX_SECONDS) \
		solutions

test-solutions: $(STAMP)
	@$(STAGE) run solutions -- $(PYTEST) $(XDIST) --nbval $(NBVAL) solutions

test-notebooks: $(STAMP)
	@$(STAGE) run student-versions -- $(PYTEST) $(XDIST) --nbval-lax $(NBVAL) notebooks

# The second rounding: prints the rounding each pass uses, then runs under the lower one
# the roundoff tests and the paired notebooks (build/paired, written by tests/paired.py).
PAIRED := build/paired
test-rounding: $(STAMP)
	@$(BIN)/python tests/roundings.py
	@rm -rf $(PAIRED) && $(BIN)/python tests/paired.py $(PAIRED) solutions notebooks
	@$(STAGE) run second-rounding -- $(BIN)/python tests/roundings.py run \
		env $(CI_HYPOTHESIS) $(PYTEST) $(XDIST) -m roundoff --nbval $(NBVAL) \
		--nbval-skip-raster=$(PAIRED) $(ROUNDOFF_TESTS) $(PAIRED)

# Property tests with Hypothesis's random search and FUZZ_FACTOR (10) times the examples;
# failures are kept in .hypothesis/ and replayed first next time.
fuzz: $(STAMP)
	HYPOTHESIS_PROFILE=fuzz $(PYTEST) -n $(JOBS) -p no:cacheprovider -m hypothesis \
		tests --ignore=tests/browser

lint: $(STAMP)
	@$(STAGE) run lint -- $(BIN)/ruff check course_lib tests benchmarks tools

# Instructor tools.
student: $(STAMP)
	$(BIN)/python -m course_lib.instructor student solutions notebooks

execute: $(STAMP)
	$(BIN)/python -m course_lib.instructor execute $(or $(NB),solutions/*.ipynb)

# Grade a class folder (one subfolder per student): gradebook, feedback, class report.
grade: $(STAMP)
	$(BIN)/python -m course_lib.instructor grade $(SUBMISSIONS) --out $(or $(OUT),grades.csv) \
		$(if $(ASSIGNMENTS),--assignment $(ASSIGNMENTS))

.PHONY: release nbgrader
# What students receive (no solutions), and an nbgrader course folder.
release: $(STAMP)
	$(BIN)/python -m course_lib.instructor release $(or $(OUT),dist/student)

nbgrader: $(STAMP)
	$(BIN)/python -m course_lib.instructor nbgrader $(or $(OUT),nbgrader)

bench: $(STAMP)
	@test -x .venv-bench/bin/python || $(PYTHON) -m venv .venv-bench
	@test .venv-bench/.installed -nt requirements.txt || { .venv-bench/bin/python -m pip install --quiet --disable-pip-version-check -r requirements.txt && touch .venv-bench/.installed; }
	@.venv-bench/bin/python -c "import numba" 2>/dev/null || .venv-bench/bin/python -m pip install --quiet --disable-pip-version-check numba==0.68.1 || echo "make bench: numba could not be installed; the numba column is skipped"
	PYTHONPATH=$(CURDIR) .venv-bench/bin/python -m benchmarks $(BENCH_ARGS)

# Re-resolve the lock from requirements.in in a scratch venv.
lock:
	rm -rf .venv-lock && $(PYTHON) -m venv .venv-lock
	.venv-lock/bin/python -m pip install --quiet -r requirements.in
	{ echo "# Full lock of requirements.in, generated by \`make lock\` (pip freeze of a fresh .venv)."; \
	  .venv-lock/bin/python -m pip freeze | grep -v '^-e'; } > requirements.txt
	rm -rf .venv-lock

clean:
	rm -rf $(VENV) .pytest_cache .hypothesis build *.egg-info

# Delivery: a static offline site of the executed notebooks (build/site), lecture mode
# (Voila on 127.0.0.1 with a token), and the browser tests (Playwright driving Debian's
# Chromium; skipped with a message saying how to enable them when it is not installed).
.PHONY: site present test-browser
site: $(STAMP)
	$(BIN)/python -m course_lib.instructor.site $(SITE_ARGS)

present: $(STAMP)
	$(BIN)/python -m course_lib.instructor.present $(NB) $(PRESENT_ARGS)

test-browser: $(STAMP)
	@mkdir -p build
	@$(STAGE) run browser -- $(PYTEST) -n $(JOBS) --dist loadgroup tests/browser -p no:cacheprovider \
		--basetemp=build/browser-tmp

# Each notebook's showcase animation as an MP4 clip in clips/ (git-ignored), with the ffmpeg
# of imageio-ffmpeg; e.g. CLIPS_ARGS="--only 08 13 --format gif", or "--list".
.PHONY: clips
clips: $(STAMP)
	$(BIN)/python -m course_lib.instructor clips clips $(CLIPS_ARGS)
