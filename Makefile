# Tempera: one entry point for humans and CI.
#   make demo    install deps, build, stylize the bundled demo scene in background Blender
#   make test    install deps, build, run C++, Python, in-Blender (3.4, 4.2, 4.5, 5.0, 5.2, 5.3),
#                wheel/farm and Flamenco tests
# Other targets: deps, build, kit, addon-zip, wheel, extension, demo-rigid, demo-fluids, bench, bench-shots, bench-tracer,
#                sanitize, clean.

PYTHON   := /usr/bin/python3
BLENDER  ?= blender
BUILD    ?= build
JOBS     ?= $(shell nproc)
VERSION  := $(shell sed -n 's/^project.tempera VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
ADDON_ZIP := dist/tempera-addon-$(VERSION).zip
EXTENSION_ZIP := dist/tempera-$(VERSION)-linux-x64.zip
# PyPI environments made by tools/setup_venvs.sh (part of `make deps`).
VENVS    ?= $(HOME)/.cache/tempera
BPY42    ?= $(VENVS)/venv-bpy42/bin/python
BPY45    ?= $(VENVS)/venv-bpy45/bin/python
BPY50    ?= $(VENVS)/venv-bpy50/bin/python
TOOLS_PY ?= $(VENVS)/venv-tools/bin/python
# CPython 3.13 (Blender 5.1+): made only where setup_venvs.sh finds a CPython 3.13.
BPY52    ?= $(VENVS)/venv-bpy52/bin/python
BPY53    ?= $(VENVS)/venv-bpy53/bin/python
TOOLS313_PY ?= $(VENVS)/venv-tools313/bin/python
# tools/build_wheel.py writes each repaired wheel's path here: cp311 (Blender 4.2-5.0), cp313 (5.1+).
WHEEL_LIST := dist/wheel-cp311.txt
WHEEL313_LIST := dist/wheel-cp313.txt
WHEEL_SOURCES := CMakeLists.txt pyproject.toml README.md native/python/tempera_native/__init__.py \
                 tools/build_wheel.py tools/wheel_deps.py tools/manylinux/link.py tools/manylinux/glibc_2_28_compat.c \
                 $(shell find native addon/tempera -name '*.cpp' -o -name '*.hpp' -o -name '*.py' \
                         -o -name CMakeLists.txt 2>/dev/null)
# The exemplar kit bundled in the add-on zip (scenes/exemplar_kit.py renders and paints it).
KIT      := $(BUILD)/kit/sphere_on_table
KIT_SOURCES := scenes/exemplar_kit.py scenes/scene_kit.py addon/tempera/methods/stylit/exemplar_paint.py \
               addon/tempera/blender/guide_render.py addon/tempera/app/guide_cache.py
DEMO_OUT ?= out/demo

.PHONY: all deps build kit addon-zip wheel extension test demo demo-rigid demo-fluids demo-fluids-stylize bench bench-shots bench-tracer sanitize fuzz clean

all: build

deps:
	@tools/install_deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

$(KIT)/kit.json: $(KIT_SOURCES) | build
	$(BLENDER) -b --factory-startup --python-exit-code 1 --python scenes/exemplar_kit.py -- \
	    --variant sphere_on_table --out $(KIT)

kit: build $(KIT)/kit.json

addon-zip: build $(KIT)/kit.json
	$(PYTHON) tools/make_addon_zip.py --out $(ADDON_ZIP) --kit $(KIT)

# The self-contained wheels: scikit-build-core, then auditwheel repair (tools/build_wheel.py), once
# per CPython. Without a CPython 3.13 the cp313 wheel is left out with a message (and the 5.2/5.3
# test levels report that they did not run).
$(WHEEL_LIST): $(WHEEL_SOURCES) | deps
	$(TOOLS_PY) tools/build_wheel.py --python $(TOOLS_PY) --out dist --jobs $(JOBS)

$(WHEEL313_LIST): $(WHEEL_SOURCES) | deps
	@if [ -x $(TOOLS313_PY) ]; then \
	    echo "$(TOOLS313_PY) tools/build_wheel.py --python $(TOOLS313_PY) --out dist --jobs $(JOBS)"; \
	    $(TOOLS313_PY) tools/build_wheel.py --python $(TOOLS313_PY) --out dist --jobs $(JOBS); \
	else \
	    echo "wheel: no $(TOOLS313_PY) (no CPython 3.13, see tools/setup_venvs.sh): no cp313 wheel"; \
	fi

wheel: deps $(WHEEL_LIST) $(WHEEL313_LIST)

# The Blender 4.2+ extension: manifest, shim, kit and the wheels (cp313 where it was built).
$(EXTENSION_ZIP): $(WHEEL_LIST) $(WHEEL313_LIST) $(KIT)/kit.json addon/extension/__init__.py \
                  addon/tempera/blender_manifest.toml tools/make_extension.py tools/make_addon_zip.py
	$(PYTHON) tools/make_extension.py --wheel "$$(cat $(WHEEL_LIST))" \
	    $$([ -f $(WHEEL313_LIST) ] && echo --wheel "$$(cat $(WHEEL313_LIST))") --kit $(KIT) --out $@

extension: build $(EXTENSION_ZIP)

test: build addon-zip extension
	$(PYTHON) tools/run_tests.py --build $(BUILD) --addon-zip $(ADDON_ZIP) --blender $(BLENDER) \
	    --extension-zip $(EXTENSION_ZIP) --wheel "$$(cat $(WHEEL_LIST))" \
	    $$([ -f $(WHEEL313_LIST) ] && echo --wheel313 "$$(cat $(WHEEL313_LIST))") \
	    --bpy42 $(BPY42) --bpy45 $(BPY45) --bpy50 $(BPY50) --bpy52 $(BPY52) --bpy53 $(BPY53) \
	    --tools-python $(TOOLS_PY) --tools-python313 $(TOOLS313_PY)

demo: build addon-zip
	$(PYTHON) tools/run_demo.py --addon-zip $(ADDON_ZIP) --blender $(BLENDER) --out $(DEMO_OUT)
	$(MAKE) demo-rigid
	$(MAKE) demo-fluids

# The rigid-body demo (scenes/rigid_demo.py): three balls and a box on ramps, hand-drawn.
DEMO_RIGID_OUT ?= out/demo-rigid
demo-rigid: build
	$(BLENDER) -b --factory-startup --python-exit-code 1 --python scenes/rigid_demo.py -- --out $(DEMO_RIGID_OUT)

# The fluid demos (docs/media_exemplars.md): the chimney-smoke shot (scenes/chimney_smoke.py) and the
# growing-ink shot (scenes/growing_ink.py) in background Blender and the project's own exemplars, then
# LazyFluids on the smoke and Fluidymation on the ink, composited over the plate and the paper.
DEMO_FLUIDS_OUT ?= out/demo-fluids
TEMPERA_PY := PYTHONPATH=addon TEMPERA_CLI=$(CURDIR)/$(BUILD)/bin/tempera $(PYTHON) -m tempera
demo-fluids: build
	$(BLENDER) -b --factory-startup --python-exit-code 1 --python scenes/chimney_smoke.py -- \
	    --out $(DEMO_FLUIDS_OUT)/chimney
	$(BLENDER) -b --factory-startup --python-exit-code 1 --python scenes/growing_ink.py -- \
	    --out $(DEMO_FLUIDS_OUT)/ink
	$(TEMPERA_PY) exemplar smoke --out $(DEMO_FLUIDS_OUT)/exemplars/smoke --size 128x128 --frames 24
	$(TEMPERA_PY) exemplar ink --out $(DEMO_FLUIDS_OUT)/exemplars/ink --size 160x160 --frames 24 --speed 2
	$(MAKE) demo-fluids-stylize

# The fluid demos' stylization from their renders, guides and exemplars in DEMO_FLUIDS_IN (the same
# folder by default): tools/demo_guard.py reruns it on a reference's renders.
DEMO_FLUIDS_IN ?= $(DEMO_FLUIDS_OUT)
demo-fluids-stylize: build
	$(BUILD)/bin/tempera stylize --method lazyfluids --guides $(DEMO_FLUIDS_IN)/chimney/guides \
	    --exemplar $(DEMO_FLUIDS_IN)/exemplars/smoke --frames 13-36 --out $(DEMO_FLUIDS_OUT)/chimney/lazyfluids
	$(PYTHON) tools/composite_over.py --over $(DEMO_FLUIDS_OUT)/chimney/lazyfluids/frames \
	    --under $(DEMO_FLUIDS_IN)/chimney/plate --frames 13-36 --out $(DEMO_FLUIDS_OUT)/chimney/composite \
	    --video $(DEMO_FLUIDS_OUT)/chimney/chimney_smoke.mp4
	$(BUILD)/bin/tempera stylize --method fluidymation --guides $(DEMO_FLUIDS_IN)/ink/guides \
	    --exemplar $(DEMO_FLUIDS_IN)/exemplars/ink --exemplar-masks $(DEMO_FLUIDS_IN)/exemplars/ink/masks \
	    --target-mask mask.OB_Ink --frames 1-24 --out $(DEMO_FLUIDS_OUT)/ink/fluidymation
	$(PYTHON) tools/composite_over.py --over $(DEMO_FLUIDS_OUT)/ink/fluidymation/frames \
	    --under $(DEMO_FLUIDS_IN)/ink/paper.png --frames 1-24 --out $(DEMO_FLUIDS_OUT)/ink/composite \
	    --video $(DEMO_FLUIDS_OUT)/ink/growing_ink.mp4

# The 1 Mpix run, the 0.25/1/4 Mpix sweep and, with COMPARE=REV (e.g. main), REV side by side.
bench: build
	PYTHONPATH=addon $(PYTHON) bench/bench_synthesis.py --size 1024 --json docs/bench_synthesis_1024.json
	PYTHONPATH=addon $(PYTHON) bench/bench_synthesis.py --sweep --json docs/bench_synthesis_sweep.json
ifdef COMPARE
	PYTHONPATH=addon $(PYTHON) bench/bench_synthesis.py --size 1024 --compare $(COMPARE) --repeats 2 \
	    --json docs/bench_synthesis_compare.json
endif

# Every method along a 24-frame shot at 0.25, 1 and 2 Mpix, cold and warm (issue 32; about 3 h
# on 2 cores); COMPARE=REV runs REV's module side by side.
bench-shots: build
	PYTHONPATH=addon $(PYTHON) bench/bench_shots.py --mpix 0.25,1,2 --frames 24 $(if $(COMPARE),--compare $(COMPARE)) \
	    --json docs/bench_shots.json

bench-tracer: build
	PYTHONPATH=addon $(PYTHON) bench/bench_tracer.py --size 1024 --samples 64 --json docs/bench_tracer_1024.json

build-asan/CMakeCache.txt:
	cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DTEMPERA_SANITIZE=ON -DTEMPERA_BUILD_PYTHON=OFF \
	      -DTEMPERA_PYTHON_PACKAGE_DIR=$(CURDIR)/build-asan/python/tempera

sanitize: deps build-asan/CMakeCache.txt
	cmake --build build-asan -j $(JOBS) --target tempera_tests tempera_fuzz
	cd build-asan && ctest --output-on-failure

# The fuzz harness for FUZZ_SECONDS each half (CI runs it before make test): the
# native half under AddressSanitizer and UBSan, then the command-level half (the
# rigid-body method's whole command on mutated tracks and options) on the
# normal build's CLI.
FUZZ_SECONDS ?= 60
fuzz: deps build-asan/CMakeCache.txt build
	cmake --build build-asan -j $(JOBS) --target tempera_fuzz
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
	LSAN_OPTIONS=suppressions=$(CURDIR)/tests/fuzz/lsan.supp \
	    build-asan/tests/fuzz/tempera_fuzz --seconds $(FUZZ_SECONDS)
	PYTHONPATH=addon $(PYTHON) tests/fuzz/fuzz_rigid.py --seconds $(FUZZ_SECONDS) --tempera $(BUILD)/bin/tempera

clean:
	rm -rf $(BUILD) build-asan dist addon/tempera/_native*.so
