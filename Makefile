# animrt: the two README commands are `make demo` and `make test`.
BUILD ?= build
ASAN_BUILD ?= build-asan
JOBS ?= $(shell nproc)

.PHONY: deps build demo test test-release test-sanitize bench clean

deps:
	@scripts/install-deps.sh

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DANIMRT_WERROR=ON
	cmake --build $(BUILD) -j $(JOBS)

# The 12-servo quadruped walks its gait for 10 s on simulated Dynamixel
# servos behind a pseudo-terminal, then prints the loop statistics.
demo: build
	$(BUILD)/bin/animrt run configs/robots/quadruped.yaml --backend sim --duration 10 \
	  --telemetry $(BUILD)/demo_telemetry.csv --summary-json $(BUILD)/demo_summary.json

# Every test tier: unit and integration on the warnings-as-errors build, then
# again under AddressSanitizer and UndefinedBehaviorSanitizer.
test: test-release test-sanitize

test-release: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

test-sanitize: deps
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DANIMRT_WERROR=ON -DANIMRT_SANITIZE=ON \
	  -DANIMRT_BENCH=OFF
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	ctest --test-dir $(ASAN_BUILD) --output-on-failure -j $(JOBS)

bench: build
	scripts/run-benchmarks.sh $(BUILD)

clean:
	rm -rf $(BUILD) $(ASAN_BUILD)
