# animrt: the two README commands are `make demo` and `make test`.
BUILD ?= build
ASAN_BUILD ?= build-asan
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_TEST_SECONDS ?= 3
JOBS ?= $(shell nproc)

.PHONY: deps build demo test test-release sanitize-build test-sanitize test-fuzz test-hil fuzz fuzz-build bench deb test-install install-root test-boot arm64-build test-arm64 clean

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
# again under AddressSanitizer and UndefinedBehaviorSanitizer, then every
# fuzz harness for a few seconds, the hardware-in-the-loop tier in a QEMU
# guest, the arm64 build's tests under qemu-user, and the Debian packages
# installed into a fresh Debian 12 root and booted with their service under
# QEMU (as root). The later tiers' builds, and the packages' root, are made
# beside the earlier tiers' tests at idle CPU priority (scripts/test-tiers:
# the tests mostly wait, on ptys, clocks, browsers and guests).
test: deps
	scripts/test-tiers

test-release: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

sanitize-build: deps
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DANIMRT_WERROR=ON -DANIMRT_SANITIZE=ON \
	  -DANIMRT_BENCH=OFF
	cmake --build $(ASAN_BUILD) -j $(JOBS)

test-sanitize: sanitize-build
	ctest --test-dir $(ASAN_BUILD) --output-on-failure -j $(JOBS)

# libFuzzer harnesses of every decoder and file parser (tests/fuzz), in a
# clang build of their libraries under ASan and UBSan. `make fuzz` runs each
# for FUZZ_SECONDS, `make test-fuzz` for FUZZ_TEST_SECONDS.
fuzz-build: deps
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DANIMRT_WERROR=ON -DANIMRT_FUZZ=ON
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target animrt_fuzz

fuzz: fuzz-build
	scripts/run-fuzz.sh $(FUZZ_BUILD) $(FUZZ_SECONDS)

test-fuzz: fuzz-build
	scripts/run-fuzz.sh $(FUZZ_BUILD) $(FUZZ_TEST_SECONDS)

# Hardware-in-the-loop: the release build's animrt in a Linux guest under
# QEMU, on a real 8250 UART and on SocketCAN (vcan0); results in $(BUILD)/hil.
test-hil: build
	tests/hil/run $(BUILD)

# Debian packages from the release build: animrt (what a figure runs, its
# service and data) and animrt-tools (the offline tools), in $(BUILD)/deb.
deb: build
	packaging/build-debs $(BUILD) $(BUILD)/deb

# The packages installed with dpkg into a fresh Debian 12 root (mmdebstrap; the
# root is cached in $(BUILD)/install/cache, the first run fetches it from
# Debian's archive) and checked there: the service user, the files, the
# unit, every shipped robot file validated from the installed paths. Needs
# root. `make test-boot` runs it first.
test-install: deb
	packaging/test-install $(BUILD)

# Only the root test-install needs, fetched and cached (make test does it in
# the background).
install-root: deb
	packaging/test-install --root-only $(BUILD)

# That installed system booted with systemd under QEMU (TCG): the service
# plays a figure on the host's simulated servos, a shutdown ramps it home
# and turns torque off. Results in $(BUILD)/hil-boot. Needs root; the last
# tier of `make test`.
test-boot: deb
	tests/hil/boot $(BUILD)

# The arm64 tier: what a figure runs (the loop, the buses, the motion that
# plays, the dashboard), the simulated devices and the tests that check what
# a 64-bit ARM build could get wrong (codecs, the cycle, the devices, lockstep
# figures: cmake/arm64_tests.cmake), cross-compiled with Debian's cross
# toolchain at -O1 (the tests' own sources at -O0) without debug information
# against a sysroot of Debian's arm64 -dev packages ($(ARM64_BUILD)/sysroot,
# fetched once from Debian's archive), and run under qemu-user.
ARM64_BUILD ?= build-arm64
arm64-build: deps
	packaging/arm64-sysroot $(ARM64_BUILD)/sysroot
	cmake -S . -B $(ARM64_BUILD) -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake \
	  -DANIMRT_ARM64_SYSROOT=$(abspath $(ARM64_BUILD))/sysroot -DANIMRT_RUNTIME_ONLY=ON \
	  -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -DNDEBUG" -DANIMRT_WERROR=ON
	cmake --build $(ARM64_BUILD) -j $(JOBS)

test-arm64: arm64-build
	ctest --test-dir $(ARM64_BUILD) --output-on-failure -j $(JOBS)

bench: build
	scripts/run-benchmarks.sh $(BUILD)

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD) $(ARM64_BUILD)
