# feelmysign — one Makefile for every part. `make test` works on a fresh Debian
# machine: it installs what it needs (system packages through apt-get, Python
# packages into .venv) and then runs lint, type checks and every test.
#
# `make test` runs side by side: first every install at once (apt-get, pip, npm ci,
# go install: independent, mostly network), then the checks in TEST_JOBS lanes: pytest in
# one, the browser tests (which mostly wait on timers) in another, the short checks (lint,
# type checks, vectors, vitest units) one after another in the third. Each part's output
# is held back and printed whole when it ends (make's --output-sync), so parallel parts
# never interleave; every part runs even when another fails (--keep-going), and `make
# test` fails if any did. `make check` runs the same checks one at a time.

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
BIN := $(VENV)/bin
# What running needs (make up), then everything: research tools and development tools (make test).
RUN_STAMP := $(VENV)/.installed-run-stamp
STAMP := $(VENV)/.installed-stamp
PIP_INSTALL := $(PY) -m pip install --disable-pip-version-check --progress-bar off
# Options for `feelmysign up`, e.g. make up ARGS="--http-port 8080"
ARGS ?=
SYSTEM_PACKAGES := mosquitto mosquitto-clients
# Lanes of `make test`: pytest, the browser tests, the short checks. The machine has two
# cores; pytest and the browser tests each leave much of theirs idle.
TEST_JOBS ?= 3

.PHONY: help up research test check install lint typecheck pytest vectors vectors-check bench bench-study bench-study-calibration system clean
.PHONY: bench-prepare bench-timed bench-prepare-python bench-timed-python

help:
	@echo "make up      set up and start everything (broker, sleeve simulator, drawing client);"
	@echo "             options for 'feelmysign up' go in ARGS, e.g. make up ARGS=\"--http-port 8080\""
	@echo "make research  install what the recognition study needs (its statistics and plots in"
	@echo "             .venv, the page built), without building the Java port or the Go tools"
	@echo "make test    install what is needed, then lint, type-check and run every test,"
	@echo "             side by side (TEST_JOBS=3 lanes; each part's output printed whole when it ends)"
	@echo "make check   the same parts one at a time"
	@echo "make bench   print performance figures (at most 5 minutes on a quiet 2-core machine: what they"
	@echo "             need built side by side, then one timed part at a time)"
	@echo "make bench-study  the study analysis's interval coverage over 400 simulated studies"
	@echo "             per case (about 50 minutes; RUNS=40 for a quick look)"
	@echo "make bench-study-calibration  the shape test's false-positive rate and the interval"
	@echo "             coverage at 4, 8, 12, 24 participants (TEST_RUNS=400, COVERAGE_RUNS=100; 0 leaves a column out; SIZES='12 24')"
	@echo "make load    N sleeves and N senders at once on Mosquitto and NATS (N = 20, 100, 200; N='20 100')"
	@echo "make vectors regenerate testdata/ from the Python reference"
	@echo "make java-build  build the Java port (java/bin/feelmysign-java); make java-test tests it"
	@echo "make processing-library  the Processing library: java/processing/target/dist/feelmysign.zip"
	@echo "make sleeve  on a Raspberry Pi: only what the sleeve needs (python3-venv, i2c-tools, the"
	@echo "             Python package in SLEEVE_PREFIX=/opt/feelmysign); no browser, Node or Java"
	@echo "make sleeve-unit  the systemd unit for that install, in SLEEVE_UNIT_DIR=/etc/systemd/system"

$(RUN_STAMP): python/pyproject.toml
	@echo "==> Python packages to run feelmysign (python/pyproject.toml: dependencies) into $(VENV):"
	$(PYTHON) -m venv $(VENV)
	$(PIP_INSTALL) --quiet --upgrade pip
	$(PIP_INSTALL) -e python
	touch $@

$(STAMP): $(RUN_STAMP)
	@echo "==> Research and development tools (python/pyproject.toml: [research] and [dev]) into $(VENV):"
	$(PIP_INSTALL) -e 'python[research,dev]'
	touch $@

# System packages come from Debian's archive; installed only when missing.
system:
	@missing=""; for p in $(SYSTEM_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi; \
	  echo "==> System packages from Debian's archive (apt-get, about a minute):$$missing"; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing; \
	fi

lint: $(STAMP)
	cd python && ../$(BIN)/ruff check . ../testdata && ../$(BIN)/ruff format --check . ../testdata

typecheck: $(STAMP)
	cd python && ../$(BIN)/mypy

vectors: $(STAMP)
	$(PY) testdata/generate.py

vectors-check: $(STAMP)
	$(PY) testdata/generate.py --check

# The ten slowest tests are listed before pytest's summary, to keep an eye on what makes
# `make test` long; e.g. make pytest PYTEST_ARGS="-x tests/test_planner.py".
PYTEST_ARGS ?= --durations=10
# pytest's processes (pytest-xdist; 0: pytest alone). Most slow tests wait on a sleeve that
# plays in real time or a broker that restarts, so two overlap on two cores; each idle one
# takes the next test (worksteal), every test with its own ports and temporary state.
PYTEST_WORKERS ?= 2

# OpenBLAS on one thread in each worker: the study statistics' small matrix products are
# slower spread over threads that spin on two shared cores (the coverage tests took 1.7x the
# time with its default threads), and the workers already keep both cores busy.
pytest: $(STAMP) system
	cd python && OPENBLAS_NUM_THREADS=1 ../$(BIN)/pytest -n $(PYTEST_WORKERS) --dist worksteal $(PYTEST_ARGS)

# What a researcher needs for `feelmysign study` (docs/study.md): the statistics and plots
# (python[research], installed with python[dev] in one step), the system packages and the
# page the study is served on; the Java port
# and the Go tools (NATS) are not built.
research: $(STAMP) system web-build

# Everything `make test` installs; independent of each other, so `make -j` runs them at once.
install: system $(STAMP)

# The longest parts first (pytest, then the browser tests of web/ below), so that they start
# at once when the checks run side by side and the short ones share the third lane.
check: pytest web-browser-test java-test lint typecheck vectors-check

# (java-test, the Java port's tests, is in the Java section at the end.)

# Installs at once, then the checks side by side (see the top of this file). The nested
# makes get their own -j: side by side is what `make test` means, with or without -j.
test:
	@echo "==> make test: installing what is missing (side by side), then the checks in $(TEST_JOBS) lanes;"
	@echo "    each part's output is printed whole when the part ends."
	@$(MAKE) --no-print-directory -j4 --output-sync=target --keep-going install
	@$(MAKE) --no-print-directory -j$(TEST_JOBS) --output-sync=target --keep-going check \
	  || { echo "==> make test: FAILED (the parts marked Error above)" >&2; exit 1; }
	@echo "==> make test: every part passed"

# make bench: first what the figures need, built side by side (`bench-prepare`: the page,
# the LASA frames, the Java jar, and the felt-drawing group, whose figures are simulated
# times, not timings); then every timed part one after another (`bench-timed`), so that no
# two timings share the cores. The total wall time is printed at the end, against the budget
# (a quiet 2-core machine; under other load the parts that compute take longer: a note, not
# a failure).
BENCH_BUDGET_S := 300
bench: $(STAMP) system
	@echo "==> make bench: what the figures need, side by side (each part's output printed whole when it"
	@echo "    ends); then the timed parts one at a time. Load average now: $$(cut -d' ' -f1-3 /proc/loadavg)"
	@started=$$(date +%s); \
	$(MAKE) --no-print-directory -j3 --output-sync=target bench-prepare \
	  && $(MAKE) --no-print-directory -j1 bench-timed; status=$$?; \
	took=$$(( $$(date +%s) - started )); \
	if [ $$took -le $(BENCH_BUDGET_S) ]; then verdict="within"; else verdict="OVER"; fi; \
	echo "make bench: $$took s in all, $$verdict the budget of $(BENCH_BUDGET_S) s (5 minutes on a quiet" \
	  "2-core machine; load average now: $$(cut -d' ' -f1-3 /proc/loadavg))"; \
	exit $$status

# The Python groups, untimed first (bench-prepare), then the timed ones (bench-timed).
bench-prepare-python: $(STAMP)
	$(PY) -m feelmysign.bench simplifier_timing

bench-timed-python: $(STAMP) system
	$(PY) -m feelmysign.bench --without simplifier_timing

# The study analysis's coverage over many seeded simulated studies (python -m
# feelmysign.bench.study_recovery; about 50 minutes at 400 runs), apart from make bench.
RUNS ?= 400
bench-study: $(STAMP)
	$(PY) -m feelmysign.bench.study_recovery $(RUNS)

TEST_RUNS ?= 400
COVERAGE_RUNS ?= 100
SIZES ?= 4 8 12 24
bench-study-calibration: $(STAMP)
	$(PY) -m feelmysign.bench.study_calibration $(TEST_RUNS) $(COVERAGE_RUNS) --sizes $(SIZES)

up: $(RUN_STAMP) system
	@echo "==> Starting feelmysign up $(ARGS)"
	$(BIN)/feelmysign up $(ARGS)

clean:
	rm -rf $(VENV) python/src/*.egg-info

# ==== web: the drawing client (web/) ====================================================
# TypeScript + Vite; every npm package pinned by web/package-lock.json and installed by
# `npm ci`. Node.js >= 20.19 and npm come from the machine. The browser tests drive
# Debian's chromium (installed by `system`) against a real Mosquitto (`feelmysign broker`
# from the venv). Output of the browser tests (screenshots) lands in web/test-results/.

WEB := web
WEB_STAMP := $(WEB)/node_modules/.installed-stamp
# The tools straight from node_modules: no npm start-up, no npm notices in the output.
WEB_BIN := node_modules/.bin
NPM_QUIET := --no-audit --no-fund --loglevel=error
SYSTEM_PACKAGES += chromium

.PHONY: web-build web-test web-typecheck web-format-check web-unit web-browser-test web-bench web-clean
.PHONY: bench-timed-web

$(WEB_STAMP): $(WEB)/package.json $(WEB)/package-lock.json
	@command -v npm >/dev/null || { echo "Error: npm not found; install Node.js 20.19 or newer with npm, then run make again." >&2; exit 1; }
	@echo "==> The drawing client's npm packages (web/package-lock.json, npm ci) into web/node_modules:"
	cd $(WEB) && npm ci $(NPM_QUIET)
	touch $@

web-build: $(WEB_STAMP)
	@echo "==> Building the drawing client into web/dist (vite)"
	cd $(WEB) && $(WEB_BIN)/vite build --logLevel warn

web-typecheck: $(WEB_STAMP)
	cd $(WEB) && $(WEB_BIN)/tsc --noEmit

web-format-check: $(WEB_STAMP)
	cd $(WEB) && $(WEB_BIN)/prettier --check --log-level warn .

web-unit: $(WEB_STAMP)
	cd $(WEB) && $(WEB_BIN)/vitest run

web-browser-test: web-build $(STAMP) system
	cd $(WEB) && $(WEB_BIN)/vitest run --config vitest.browser.config.ts

web-test: web-typecheck web-format-check web-unit web-browser-test

# The LASA points the web bench times its simplifiers and simplify-js on: 60 fps frames,
# written by the Python importer from the venv before the web bench reads them.
LASA_FRAMES := $(WEB)/bench/.lasa-frames.json

$(LASA_FRAMES): $(STAMP) python/src/feelmysign/bench/lasa_points.py python/src/feelmysign/research/lasa.py python/src/feelmysign/simplify/frames.py
	$(PY) -m feelmysign.bench.lasa_points $@

WEB_BENCH := cd $(WEB) && $(WEB_BIN)/tsx bench/run.ts

web-bench: web-build system $(LASA_FRAMES)
	$(WEB_BENCH)

# In make bench: built in bench-prepare, run in bench-timed.
bench-timed-web:
	$(WEB_BENCH)

web-clean:
	rm -rf $(WEB)/node_modules $(WEB)/dist $(WEB)/test-results

# The web client joins the project-wide targets (extra prerequisites; their recipes stay above).
# make install builds the page too, so that `feelmysign up` serves it right after.
install: web-build
check: web-test
bench: $(WEB_STAMP)
bench-prepare: web-build $(LASA_FRAMES)
up: web-build
# Tests of the sleeve's wearer page and of up serve the built client (web/dist): built before
# pytest starts, not left to race the browser tests' lane, which builds it too.
pytest: web-build
clean: web-clean
# ==== end of web ===========================================================================

# ==== NATS: the pinned nats-server of the cluster tests and the load benchmark ============
# Built from source through the Go module proxy into .cache/ (ignored by git), once per
# checkout: GOPATH, the module cache and the build cache stay inside the repository.
NATS_VERSION := v2.15.2
GO_DIR := $(CURDIR)/.cache/go
NATS_BIN := .cache/go-bin/nats-server
NATS_STAMP := .cache/go-bin/.nats-server-$(NATS_VERSION)

.PHONY: nats
nats: $(NATS_STAMP)

$(NATS_STAMP):
	@command -v go >/dev/null || { echo "Error: go not found; install Go (e.g. 'sudo apt-get install golang'), then run make again." >&2; exit 1; }
	GOPATH=$(GO_DIR) GOMODCACHE=$(GO_DIR)/mod GOCACHE=$(GO_DIR)/build GOFLAGS=-modcacherw \
	  GOBIN=$(CURDIR)/.cache/go-bin go install github.com/nats-io/nats-server/v2@$(NATS_VERSION)
	touch $@

pytest: $(NATS_STAMP)
web-browser-test: $(NATS_STAMP)
install: $(NATS_STAMP)

# N sleeves and N senders at once on Mosquitto and on the NATS cluster (N = 20, 100, 200,
# or make load N='20 100'), against a bare publish -> receive baseline of the same run.
# Several minutes.
.PHONY: load
load: $(STAMP) system $(NATS_STAMP)
	$(PY) -m feelmysign.bench.load $(N)
# ==== end of NATS =========================================================================

# ==== Java: the Java port (java/: core, client, cli) =================================================
# Maven, Java 17; every dependency and plugin pinned in java/pom.xml. Maven's local repository
# is .cache/m2 in the checkout (ignored by git), so a fresh clone downloads what it needs once
# and nothing outside the repository changes. Maven and the JDK come from Debian (`system`).
# java/bin/feelmysign-java runs the command line built here.

JAVA_DIR := java
MVN := mvn -B -q -Dstyle.color=never -Dmaven.repo.local=$(CURDIR)/.cache/m2 -f $(JAVA_DIR)/pom.xml
JAVA_POMS := $(JAVA_DIR)/pom.xml $(wildcard $(JAVA_DIR)/*/pom.xml)
JAVA_STAMP := .cache/m2/.installed-stamp
SYSTEM_PACKAGES += maven openjdk-17-jdk-headless
# Xvfb (and xauth, for xvfb-run): the Processing library's example sketch runs on a virtual screen.
SYSTEM_PACKAGES += xvfb xauth

.PHONY: java-build java-test java-bench java-soak java-clean processing-library java-bench-jar bench-timed-java

# Resolves every dependency and plugin (a build without tests) once per change of a pom.
$(JAVA_STAMP): $(JAVA_POMS) | system
	@echo "==> The Java port's Maven packages (java/pom.xml) into .cache/m2:"
	$(MVN) -DskipTests package
	touch $@

java-build: $(JAVA_STAMP)
	@echo "==> Building the Java port (java/bin/feelmysign-java)"
	$(MVN) -DskipTests package

# Compiles once and runs every JUnit test (one JVM per module): the shared vectors, the client
# against a real Mosquitto and sleeve simulator, and the command line against the Python
# reference (both from the .venv). Maven is quiet; the totals of Surefire's reports follow it.
# The Processing library's tests (failsafe, after its zip is built) run an example sketch on
# Xvfb's virtual screen, started by xvfb-run for the whole build.
java-test: $(JAVA_STAMP) $(STAMP) system
	rm -rf $(JAVA_DIR)/*/target/surefire-reports $(JAVA_DIR)/*/target/failsafe-reports
	xvfb-run -a -s "-screen 0 1920x1080x24" $(MVN) verify
	@cat $(JAVA_DIR)/*/target/surefire-reports/*.txt $(JAVA_DIR)/*/target/failsafe-reports/*.txt | awk '/^Tests run:/ { \
	  gsub(",", ""); run += $$3; failed += $$5 + $$7; skipped += $$9 } \
	  END { printf "java: %d passed, %d failed, %d skipped\n", run - failed - skipped, failed, skipped }'

# The Java simplifiers' throughput on the LASA frames of the web bench, beside a baseline
# measured in the same JVM run.
# Only the command line's jar is built for it (not the Processing library's zip and javadoc).
JAVA_BENCH := java -cp $(JAVA_DIR)/cli/target/feelmysign-java.jar feelmysign.cli.Bench $(LASA_FRAMES)

java-bench: java-bench-jar $(LASA_FRAMES)
	$(JAVA_BENCH)

java-bench-jar: $(JAVA_STAMP)
	$(MVN) -DskipTests -pl cli -am package

# In make bench: built in bench-prepare, run in bench-timed.
bench-timed-java:
	$(JAVA_BENCH)

# The Processing library for Processing 4's Contribution Manager (docs/processing.md):
# java/processing/target/dist/feelmysign.zip and feelmysign.txt beside it.
processing-library: $(JAVA_STAMP)
	$(MVN) -DskipTests package

# A long session (docs/processing.md, "Long sessions"): ModernSketch and PaperSketch under Xvfb,
# a scripted mouse drawing path after path to a real broker and sleeve simulator for
# SOAK_MINUTES; a CSV row a minute (heap after GC, RSS, draw() time, frame interval, strokes)
# in java/processing/target/soak.csv, then the last five minutes against the first five.
# Not part of test or bench: it takes an hour by default. Run nice'd: it shares the machine.
SOAK_MINUTES ?= 60
java-soak: $(JAVA_STAMP) $(STAMP) system
	$(MVN) -DskipTests -pl processing -am package dependency:build-classpath \
	  -Dmdep.outputFile=target/soak-classpath.txt -Dmdep.includeScope=test
	cd $(JAVA_DIR)/processing && nice -n 10 xvfb-run -a -s "-screen 0 1920x1080x24" \
	  java -Djava.awt.headless=false -Xmx512m \
	  -cp "target/test-classes:target/classes:$$(cat target/soak-classpath.txt)" \
	  feelmysign.processing.SoakSketches $(SOAK_MINUTES) target/soak.csv

java-clean:
	rm -rf $(JAVA_DIR)/*/target $(JAVA_DIR)/target

install: $(JAVA_STAMP)
bench: $(JAVA_STAMP)
bench-prepare: java-bench-jar
clean: java-clean
# ==== end of Java ==========================================================================

# ==== make bench, all parts together (see the bench target at the top) ======================
# bench-prepare's parts are listed with each part above; the timed ones run in this order.
bench-prepare: bench-prepare-python
bench-timed: bench-timed-web bench-timed-java bench-timed-python

# ==== sleeve: a Raspberry Pi that runs only the sleeve (docs/sleeve-hardware.md) ============
# `make sleeve` installs what the sleeve daemon needs and nothing for the page, the research
# tools or the tests: python3-venv and i2c-tools from Debian's archive (i2c-tools' udev rule
# makes the i2c group the unit runs in), then the feelmysign package with its own
# dependencies only (paho-mqtt, smbus2, ...) into a venv at SLEEVE_PREFIX, where the
# systemd unit expects it. Run it again after 'git pull' to upgrade. `make sleeve-unit`
# writes the unit with SLEEVE_PREFIX in its paths.
SLEEVE_PREFIX ?= /opt/feelmysign
SLEEVE_UNIT_DIR ?= /etc/systemd/system
SLEEVE_SYSTEM_PACKAGES := python3-venv i2c-tools
# sudo where needed: root, or a prefix the user may write, needs none.
SLEEVE_SUDO ?= $(shell [ "$$(id -u)" = 0 ] && echo "" || echo sudo)
# The tests check the unit with systemd-analyze, and make and use an install as `make sleeve` does.
SYSTEM_PACKAGES += systemd $(SLEEVE_SYSTEM_PACKAGES)

.PHONY: sleeve sleeve-system sleeve-unit

sleeve-system:
	@missing=""; for p in $(SLEEVE_SYSTEM_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "==> System packages for the sleeve from Debian's archive (apt-get):$$missing"; \
	  $(SLEEVE_SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SLEEVE_SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi

sleeve: sleeve-system
	@echo "==> The sleeve's Python package (python/pyproject.toml: dependencies only) into $(SLEEVE_PREFIX):"
	$(SLEEVE_SUDO) $(PYTHON) -m venv $(SLEEVE_PREFIX)
	$(SLEEVE_SUDO) $(SLEEVE_PREFIX)/bin/python -m pip install --disable-pip-version-check --progress-bar off --quiet --upgrade ./python
	@# pip builds the package in the checkout: leave no (root-owned) build folder behind.
	$(SLEEVE_SUDO) rm -rf python/build
	@echo "==> Installed: $(SLEEVE_PREFIX)/bin/feelmysign ($$($(SLEEVE_PREFIX)/bin/feelmysign --version 2>/dev/null || echo '?'))."
	@echo "    Next: the layout in /etc/feelmysign/layout.toml, 'make sleeve-unit', the join token (docs/sleeve-hardware.md)."

sleeve-unit:
	@echo "==> The systemd unit for $(SLEEVE_PREFIX) into $(SLEEVE_UNIT_DIR)/feelmysign-sleeve.service"
	sed 's|/opt/feelmysign/|$(SLEEVE_PREFIX)/|g' deploy/feelmysign-sleeve.service \
	  | $(SLEEVE_SUDO) tee $(SLEEVE_UNIT_DIR)/feelmysign-sleeve.service >/dev/null
# ==== end of sleeve =========================================================================
