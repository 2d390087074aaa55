# ANIMRT_RUNTIME_ONLY: the tests of the arm64 tier (`make test-arm64`), the
# sources of tests/ that check what an arm64 build could get wrong (char is
# unsigned there, GCC fuses multiply-adds, the libraries are Debian's arm64
# builds), in four executables:
#   codecs:   the bytes on the wire (Dynamixel 2.0, Feetech, CANopen, MIT,
#             Maestro, Modbus, the IMU's frames) and the MCAP recording
#   loop:     the cycle's step(), the safety filter, the runner on fake buses
#             in lockstep, telemetry, the heartbeat, the bus workers
#   devices:  the buses against the simulated devices' firmware
#   lockstep: whole figures on simulated devices on a lockstep clock
# Cross-compiled, ctest runs them under the emulator
# (CMAKE_CROSSCOMPILING_EMULATOR): one entry per test folder of an
# executable (its suites, by --gtest_filter), so that the emulator starts a
# few times instead of once per test case and the long folders run beside
# the short ones.
find_package(GTest REQUIRED)
enable_testing()
set(ANIMRT_SOURCE_DIR ${CMAKE_SOURCE_DIR})

add_library(animrt_arm64_test_support OBJECT tests/support/alloc_counter.cpp
            tests/support/private_tmpdir.cpp tests/support/sim_rig.cpp)
target_include_directories(animrt_arm64_test_support PUBLIC ${CMAKE_SOURCE_DIR}/tests)
target_link_libraries(animrt_arm64_test_support PUBLIC animrt_runtime animrt_sim ${CMAKE_DL_LIBS})

# Left out here, run natively in the other tiers: stress tests of two threads
# handing values over, which check the memory ordering that the emulator
# cannot show on an x86-64 host (it keeps the host's stronger ordering), at
# 5 to 30 s each under emulation.
set(arm64_left_out Mailbox.AReaderNeverSeesAHalfWrittenValue
    TelemetryRing.ProducerAndConsumerThreadsLoseNothing)
list(JOIN arm64_left_out ":" arm64_left_out)

# The tests' settings: their own sources at -O0, the code they test (the
# libraries, the test support) at -O1: 11 s less compile CPU for 2 s more
# under the emulator (docs/results/packaging.md#the-arm64-tier).
function(animrt_arm64_test_settings target)
  target_compile_options(${target} PRIVATE -O0)
  target_link_libraries(${target} PRIVATE animrt_runtime animrt_sim animrt_arm64_test_support
                        GTest::gtest GTest::gmock GTest::gtest_main)
  target_compile_definitions(${target} PRIVATE ANIMRT_SOURCE_DIR="${ANIMRT_SOURCE_DIR}"
                             ANIMRT_BINARY_DIR="${CMAKE_BINARY_DIR}")
endfunction()

# The standard library, gtest and yaml-cpp (what the 17 unity sources of the
# four executables parse each, yaml-cpp 9 of them) as one precompiled header,
# built once with the tests' settings and used by every executable
# (REUSE_FROM), as the sanitizer build's test binaries do (tests/CMakeLists.txt).
# At -O0 GCC 12's false -Warray-bounds from inside a precompiled header does
# not arise (the warning needs the optimiser). CMake passes -Winvalid-pch:
# a header that does not fit the flags fails the -Werror build.
add_library(animrt_arm64_test_pch OBJECT tests/support/test_pch.cpp)
animrt_arm64_test_settings(animrt_arm64_test_pch)
target_precompile_headers(animrt_arm64_test_pch PRIVATE ${ANIMRT_TEST_PCH_HEADERS})

# COST: ctest starts the executables whose entries run longest (the lockstep
# figures, then the loop) first, so that short entries fill the end.
function(animrt_arm64_test name cost)
  set(srcs ${ARGN})
  list(TRANSFORM srcs PREPEND ${CMAKE_SOURCE_DIR}/tests/)
  set(target animrt_test_arm64_${name})
  add_executable(${target} ${srcs})
  # One unity source per test folder, as the native test binaries build.
  animrt_unity_by_folder(${target} "${srcs}")
  animrt_arm64_test_settings(${target})
  target_precompile_headers(${target} REUSE_FROM animrt_arm64_test_pch)
  # The suites of each folder, from the TEST(Suite, ...) lines of its sources.
  set(folders)
  foreach(src ${srcs})
    get_filename_component(folder ${src} DIRECTORY)
    get_filename_component(folder ${folder} NAME)
    list(APPEND folders ${folder})
    file(STRINGS ${src} lines REGEX "^(TYPED_)?TEST(_F|_P)?\\([A-Za-z0-9_]+,")
    foreach(line ${lines})
      string(REGEX REPLACE "^(TYPED_)?TEST(_F|_P)?\\(([A-Za-z0-9_]+),.*" "\\3" suite "${line}")
      list(APPEND suites_${folder} ${suite})
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES folders)
  foreach(folder ${folders})
    list(REMOVE_DUPLICATES suites_${folder})
    # Plain, typed (Suite/0.Case) and value-parameterised (Prefix/Suite.Case/0) suites.
    set(filter ${suites_${folder}})
    list(TRANSFORM filter REPLACE "^(.+)$" "\\1.*:\\1/*:*/\\1.*")
    list(JOIN filter ":" filter)
    add_test(NAME arm64.${name}.${folder} COMMAND ${target}
             --gtest_filter=${filter}-${arm64_left_out})
    set_tests_properties(arm64.${name}.${folder} PROPERTIES LABELS arm64 TIMEOUT 600
                         COST ${cost} FAIL_REGULAR_EXPRESSION "\\[==========\\] 0 tests from")
  endforeach()
endfunction()

animrt_arm64_test(codecs 0
  bridge/protocol2_test.cpp bridge/protocol2_fast_read_test.cpp bridge/serial_servo_core_test.cpp
  bridge/bno08x_rvc_test.cpp bridge/rvc_reader_test.cpp bridge/dynamixel_bus_test.cpp
  can/mit_codec_test.cpp can/canopen_test.cpp can/cia402_state_test.cpp can/lockstep_can_test.cpp
  feetech/feetech_codec_test.cpp feetech/feetech_bus_test.cpp
  maestro/maestro_codec_test.cpp
  modbus/register_map_test.cpp modbus/sim_frame_test.cpp
  runtime/mcap_test.cpp)
animrt_arm64_test(loop 2
  core/error_test.cpp core/mailbox_test.cpp
  runtime/cycle_test.cpp runtime/cycle_sensors_test.cpp runtime/cycle_balance_test.cpp
  runtime/safety_filter_test.cpp runtime/runner_test.cpp runtime/telemetry_test.cpp
  runtime/service_watch_test.cpp runtime/bus_worker_test.cpp)
animrt_arm64_test(devices 1
  sim/dynamixel_servo_test.cpp sim/dynamixel_fast_read_test.cpp sim/dynamixel_sim_bus_test.cpp
  sim/dynamixel_bus_on_sim_test.cpp
  feetech/feetech_sim_test.cpp feetech/feetech_bus_on_sim_test.cpp
  can/can_nodes_test.cpp can/cia402_homing_test.cpp can/cia402_guard_bus_test.cpp
  can/device_guard_test.cpp
  modbus/modbus_bus_test.cpp
  maestro/maestro_board_test.cpp maestro/maestro_bus_test.cpp)
animrt_arm64_test(lockstep 3
  integration/quadruped_lockstep_test.cpp integration/lockstep_line_test.cpp
  integration/figure_builder_test.cpp
  integration_can/quadruped_can_lockstep_test.cpp
  integration_feetech/arm_sts_lockstep_test.cpp
  integration_mixed/mixed_figure_test.cpp)
