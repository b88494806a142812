# tabletcad: two entry points for a fresh machine (see README).
#   make demo   set everything up, build the bundled sample into out/demo
#   make test   set everything up, run the whole test suite
VENV ?= .venv
PY := $(VENV)/bin/python
SAMPLE ?= samples/flat_faced_round.toml

.PHONY: setup demo test bench freecad-workbench

setup:
	bash .ci/setup

demo: setup
	$(VENV)/bin/tabletcad build $(SAMPLE) --out out/demo

test: setup
	bash .ci/test

bench: setup
	for b in benchmarks/bench_*.py; do echo "== $$b"; $(PY) $$b || exit 1; done

# link the FreeCAD workbench into FreeCAD's user Mod folder (see freecad_workbench/README.md)
freecad-workbench: setup
	bash freecad_workbench/install.sh
