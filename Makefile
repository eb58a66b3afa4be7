# lodstream: `make demo` and `make test` work on a fresh Debian 12 machine as root. Each target first runs
# scripts/setup, which installs only the missing Debian packages (seconds when nothing is missing).
JOBS ?= 2
BUILD ?= build

.PHONY: setup build test test-asan demo data format clean

setup:
	@./scripts/setup

build: setup
	@cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

data: setup build
	@./scripts/fetch-data

test: build data
	@ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) --timeout 900

# The hostile-input tests (corrupted packages, wire messages, model files) under AddressSanitizer and UBSan, in
# their own build folder; not part of `make test` (building it takes ~10 minutes on 2 cores). Any report fails.
ASAN_BUILD ?= build-asan
test-asan: setup data
	@cmake -S . -B $(ASAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLODSTREAM_SANITIZE=ON >/dev/null
	@cmake --build $(ASAN_BUILD) -j $(JOBS) --target lodstream test_package test_net test_io
	@export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1; \
	  for t in test_package test_net test_io; do $(ASAN_BUILD)/bin/$$t --gtest_brief=1 || exit 1; done

demo: build data
	@./scripts/demo

format:
	@clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf $(BUILD) out
