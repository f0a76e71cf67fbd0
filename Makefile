# Two commands do all set-up on a fresh Debian machine: `make run` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
export VTK_DEFAULT_OPENGL_WINDOW ?= vtkOSOpenGLRenderWindow

.PHONY: run test bench system-deps venv clean

system-deps:
	@bash scripts/install-system-deps.sh

$(STAMP): pyproject.toml
	@bash scripts/install-system-deps.sh
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[test]'
	$(BIN)/python -m calib_core.solver.compile_kernels  # numba's cache: the first Calibrate does not wait 2-9 s for it
	@touch $(STAMP)

venv: $(STAMP)

# The Foxglove ecosystem's MCAP reader (@mcap/core), which tests read recordings with. Without npm the
# tests that need it are skipped and say why.
NODE_STAMP := tests/node/node_modules/.installed
$(NODE_STAMP): tests/node/package.json tests/node/package-lock.json
	@if command -v npm >/dev/null 2>&1; then \
	  npm ci --prefix tests/node --no-audit --no-fund --loglevel=error && touch $@ || echo "npm ci failed: the tests that read recordings with @mcap/core will be skipped"; \
	else echo "npm not found: the tests that read recordings with @mcap/core will be skipped"; fi

# With a display: the window. Without one: the window driven through a whole calibration offscreen,
# its screenshots and report.json in out/demo (open them with any image viewer).
run: $(STAMP)
	@if [ -n "$$DISPLAY$$WAYLAND_DISPLAY" ]; then $(BIN)/videocal gui; \
	else echo "no display: running the calibration demo offscreen; screenshots and report.json go to out/demo"; \
	$(BIN)/videocal demo --offscreen --out out/demo; fi

# The suite in three processes: on two cores a third keeps them busy while the others wait on child processes,
# simulated controllers and far links (12.6 min with two, 9.5 with three, about 20 in one). `TEST_WORKERS=0` runs
# it in this process; a test that runs alone runs as always (`.venv/bin/python -m pytest tests/...`).
TEST_WORKERS ?= 3
test: $(STAMP) $(NODE_STAMP)
	QT_QPA_PLATFORM=offscreen $(BIN)/python -m pytest -n $(TEST_WORKERS) --dist worksteal

bench: $(STAMP)
	@bash scripts/install-system-deps.sh --bench  # ViSP, a peer of the real-photo bench
	QT_QPA_PLATFORM=offscreen $(BIN)/python -m bench

clean:
	rm -rf $(VENV) build *.egg-info
