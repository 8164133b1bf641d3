# Thin wrappers; every step is a script or command you can run alone.
#   make demo    set up, build, make the sample scenes, run the demo -> out/
#   make test    set up, build, run every test tier, print a summary
#   make addon   set up, build -> dist/kodawari.zip
#   make bench   set up, build, run the benchmarks (figures and ratios, no pass/fail)
VENV     ?= $(CURDIR)/.venv
VENV5    ?= $(CURDIR)/.venv-bpy5
BUILD    ?= $(CURDIR)/build
BLENDER  ?= blender
PY       := $(VENV)/bin/python
export VENV VENV5 BUILD BLENDER

.PHONY: setup native addon test demo bench clean

setup:
	@bash tools/setup.sh

native: setup
	@$(VENV)/bin/cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DKODAWARI_PYTHON=ON -DKODAWARI_TESTS=ON -DKODAWARI_BENCH=ON \
	  -DCMAKE_MAKE_PROGRAM=$(VENV)/bin/ninja \
	  -DPython_EXECUTABLE=$(PY) -Dpybind11_DIR=$$($(PY) -m pybind11 --cmakedir) >/dev/null
	@$(VENV)/bin/cmake --build $(BUILD) -j 2
	@rm -f addon/kodawari/kodawari_native*.so
	@cp $(BUILD)/kodawari_native*.so addon/kodawari/

addon: native
	@$(PY) tools/make_addon_zip.py

test: addon
	@bash tools/run_tests.sh

demo: addon
	@bash tools/run_demo.sh

bench: addon
	@bash tools/run_bench.sh

clean:
	rm -rf $(BUILD) dist out addon/kodawari/kodawari_native*.so
