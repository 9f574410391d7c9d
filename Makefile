# Tempera: one entry point for humans and CI.
#   make demo    install deps, build, stylize the bundled demo scene in background Blender
#   make test    install deps, build, run C++, Python and in-Blender tests
# Other targets: deps, build, addon-zip, wheel, bench, bench-tracer, sanitize, clean.

PYTHON   := /usr/bin/python3
BLENDER  ?= blender
BUILD    ?= build
JOBS     ?= $(shell nproc)
VERSION  := $(shell sed -n 's/^project.tempera VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
ADDON_ZIP := dist/tempera-addon-$(VERSION).zip
DEMO_OUT ?= out/demo

.PHONY: all deps build addon-zip wheel test demo bench bench-tracer sanitize clean

all: build

deps:
	@tools/install_deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

addon-zip: build
	$(PYTHON) tools/make_addon_zip.py --out $(ADDON_ZIP)

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

sanitize: deps
	cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DTEMPERA_SANITIZE=ON \
	      -DTEMPERA_PYTHON_PACKAGE_DIR=$(CURDIR)/build-asan/python/tempera
	cmake --build build-asan -j $(JOBS) --target tempera_tests
	cd build-asan && ctest --output-on-failure

clean:
	rm -rf $(BUILD) build-asan dist addon/tempera/_native*.so
