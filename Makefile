# crater — the two commands: `make run` and `make test`.
# Both install missing Debian packages first (tools/setup-deps.sh), then build with CMake presets.

BUILD   := build/release
JOBS    ?= $(shell nproc 2>/dev/null || echo 2)
CRATER  := $(BUILD)/bin/crater
DEMO    ?= paper-20cm
OUT     ?= out
PREFIX  ?= /usr/local

.PHONY: all deps configure build cli install run test test-slow bench format docs clean

all: build

deps:
	@tools/setup-deps.sh

configure: deps
	@cmake --preset release >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# Only the binary (and the libraries it links): what `make run` needs, not the tests and benchmarks.
cli: configure
	@cmake --build $(BUILD) -j $(JOBS) --target crater_cli

# The binary, the bundled scenarios and the verification cases under $(PREFIX) (bin/, share/crater/).
install: cli
	cmake --install $(BUILD) --prefix $(PREFIX)

# The paper's scene at its demo level, then its report ($(OUT)/report/report.md and PNGs).
# Measured: 70 s for the whole target on 2 cores once built (60 s of it the run; 2026-11-27).
run: cli
	@echo "make run: $(DEMO) at its demo level into $(OUT)/ - about 1.5 minutes on 2 cores, then its report"
	$(CRATER) run $(DEMO) --out $(OUT) --force
	$(CRATER) report $(OUT)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE slow

test-slow: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -L slow

bench: build
	$(BUILD)/bench/crater_bench_kernels --benchmark_min_time=0.2

format:
	@find src tests bench -name '*.cpp' -o -name '*.hpp' | xargs clang-format -i

docs: build
	$(CRATER) schema --markdown > docs/scenario-format.md

clean:
	rm -rf build out
