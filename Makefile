# Tempera: one entry point for humans and CI.
#   make demo    install deps, build, stylize the bundled demo scene in background Blender
#   make test    install deps, build, run C++, Python and in-Blender tests
# Other targets: deps, build, kit, addon-zip, wheel, bench, bench-tracer, sanitize, clean.

PYTHON   := /usr/bin/python3
BLENDER  ?= blender
BUILD    ?= build
JOBS     ?= $(shell nproc)
VERSION  := $(shell sed -n 's/^project.tempera VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
ADDON_ZIP := dist/tempera-addon-$(VERSION).zip
# The exemplar kit bundled in the add-on zip (scenes/exemplar_kit.py renders and paints it).
KIT      := $(BUILD)/kit/sphere_on_table
KIT_SOURCES := scenes/exemplar_kit.py scenes/scene_kit.py addon/tempera/exemplar_paint.py \
               addon/tempera/blender/guide_render.py addon/tempera/guide_cache.py
DEMO_OUT ?= out/demo

.PHONY: all deps build kit addon-zip wheel test demo bench bench-tracer sanitize fuzz clean

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

wheel: deps
	$(PYTHON) -m pip wheel --no-build-isolation --no-deps -w dist .

test: build addon-zip
	$(PYTHON) tools/run_tests.py --build $(BUILD) --addon-zip $(ADDON_ZIP) --blender $(BLENDER)

demo: build addon-zip
	$(PYTHON) tools/run_demo.py --addon-zip $(ADDON_ZIP) --blender $(BLENDER) --out $(DEMO_OUT)

bench: build
	PYTHONPATH=addon $(PYTHON) bench/bench_synthesis.py --size 1024 --json docs/bench_synthesis_1024.json

bench-tracer: build
	PYTHONPATH=addon $(PYTHON) bench/bench_tracer.py --size 1024 --samples 64 --json docs/bench_tracer_1024.json

build-asan/CMakeCache.txt:
	cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DTEMPERA_SANITIZE=ON -DTEMPERA_BUILD_PYTHON=OFF \
	      -DTEMPERA_PYTHON_PACKAGE_DIR=$(CURDIR)/build-asan/python/tempera

sanitize: deps build-asan/CMakeCache.txt
	cmake --build build-asan -j $(JOBS) --target tempera_tests tempera_fuzz
	cd build-asan && ctest --output-on-failure

# The fuzz harness under AddressSanitizer and UBSan for FUZZ_SECONDS (CI runs it after make test).
FUZZ_SECONDS ?= 60
fuzz: deps build-asan/CMakeCache.txt
	cmake --build build-asan -j $(JOBS) --target tempera_fuzz
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
	LSAN_OPTIONS=suppressions=$(CURDIR)/tests/fuzz/lsan.supp \
	    build-asan/tests/fuzz/tempera_fuzz --seconds $(FUZZ_SECONDS)

clean:
	rm -rf $(BUILD) build-asan dist addon/tempera/_native*.so
