# feelmysign — one Makefile for every part. `make test` works on a fresh Debian
# machine: it installs what it needs (system packages through apt-get, Python
# packages into .venv) and then runs lint, type checks and every test.

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
SYSTEM_PACKAGES := mosquitto mosquitto-clients

.PHONY: help up test lint typecheck pytest vectors vectors-check bench system clean

help:
	@echo "make up      set up and start everything (broker, sleeve simulator, drawing client)"
	@echo "make test    install what is needed, then lint, type-check and run every test"
	@echo "make bench   print performance figures"
	@echo "make vectors regenerate testdata/ from the Python reference"

$(STAMP): python/pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e 'python[dev]'
	touch $@

# System packages come from Debian's archive; installed only when missing.
system:
	@missing=""; for p in $(SYSTEM_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi; \
	  echo "Installing system packages:$$missing"; \
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

pytest: $(STAMP) system
	cd python && ../$(BIN)/pytest

test: system $(STAMP) lint typecheck vectors-check pytest

bench: $(STAMP) system
	$(PY) -m feelmysign.bench

up: $(STAMP) system
	$(BIN)/feelmysign up

clean:
	rm -rf $(VENV) python/src/*.egg-info
