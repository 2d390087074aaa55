# animrt: the two README commands are `make demo` and `make test`.
BUILD ?= build
ASAN_BUILD ?= build-asan
JOBS ?= $(shell nproc)

.PHONY: deps build demo test test-release test-sanitize test-hil bench clean

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
# again under AddressSanitizer and UndefinedBehaviorSanitizer, then the
# hardware-in-the-loop tier in a QEMU guest.
test: test-release test-sanitize
	$(MAKE) test-hil

test-release: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

test-sanitize: deps
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DANIMRT_WERROR=ON -DANIMRT_SANITIZE=ON \
	  -DANIMRT_BENCH=OFF
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	ctest --test-dir $(ASAN_BUILD) --output-on-failure -j $(JOBS)

# Hardware-in-the-loop: the release build's animrt in a Linux guest under
# QEMU, on a real 8250 UART and on SocketCAN (vcan0); results in $(BUILD)/hil.
test-hil: build
	tests/hil/run $(BUILD)

bench: build
	scripts/run-benchmarks.sh $(BUILD)

clean:
	rm -rf $(BUILD) $(ASAN_BUILD)
