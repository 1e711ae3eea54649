# The two entry points of README.md; each installs what it needs first.
VENV := .venv/bin
export OPENBLAS_NUM_THREADS ?= 1
export VTK_DEFAULT_OPENGL_WINDOW ?= vtkEGLRenderWindow

.PHONY: setup demo test bench
setup:
	bash scripts/setup.sh

demo: setup
	$(VENV)/pcbdyn build examples/six_part_card/board.toml --out out/six_part_card --json out/six_part_card/modes.json

test: setup
	$(VENV)/python -m pytest -q -n 2 --dist loadgroup

bench: setup
	for b in benchmarks/*.py; do $(VENV)/python $$b || exit 1; done
