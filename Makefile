# lodstream: `make demo` and `make test` work on a fresh Debian 12 machine as root. Each target first runs
# scripts/setup, which installs only the missing Debian packages (seconds when nothing is missing).
JOBS ?= 2
BUILD ?= build

.PHONY: setup build test demo data format clean

setup:
	@./scripts/setup

build: setup
	@cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

data: setup build
	@./scripts/fetch-data

test: build data
	@ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) --timeout 900

demo: build data
	@./scripts/demo

format:
	@clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf $(BUILD) out
