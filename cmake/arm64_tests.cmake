# ANIMRT_RUNTIME_ONLY: the tests of the arm64 tier (`make test-arm64`), the
# sources of tests/ that check what a little-endian, strictly aligned 64-bit
# ARM build could get wrong, in four executables. Cross-compiled, ctest runs
# each under the emulator (CMAKE_CROSSCOMPILING_EMULATOR) as one entry: one
# emulator start per executable instead of one per test case.
#   codecs:   the bytes on the wire (Dynamixel 2.0, Feetech, CANopen, MIT,
#             Maestro, Modbus, the IMU's frames) and the MCAP recording
#   loop:     the cycle's step(), the safety filter, the runner on fake buses
#             in lockstep, telemetry, the heartbeat, the bus workers
#   devices:  the buses against the simulated devices' firmware
#   lockstep: whole figures on simulated devices on a lockstep clock
find_package(GTest REQUIRED)
enable_testing()
set(ANIMRT_SOURCE_DIR ${CMAKE_SOURCE_DIR})

add_library(animrt_arm64_test_support OBJECT tests/support/alloc_counter.cpp
            tests/support/private_tmpdir.cpp tests/support/sim_rig.cpp)
target_include_directories(animrt_arm64_test_support PUBLIC ${CMAKE_SOURCE_DIR}/tests)
target_link_libraries(animrt_arm64_test_support PUBLIC animrt_runtime animrt_sim ${CMAKE_DL_LIBS})

function(animrt_arm64_test name)
  set(srcs ${ARGN})
  list(TRANSFORM srcs PREPEND ${CMAKE_SOURCE_DIR}/tests/)
  set(target animrt_test_arm64_${name})
  add_executable(${target} ${srcs})
  # One unity source per test folder, as the native test binaries build.
  animrt_unity_by_folder(${target} "${srcs}")
  target_link_libraries(${target} PRIVATE animrt_runtime animrt_sim animrt_arm64_test_support
                        GTest::gtest GTest::gmock GTest::gtest_main)
  target_compile_definitions(${target} PRIVATE ANIMRT_SOURCE_DIR="${ANIMRT_SOURCE_DIR}"
                             ANIMRT_BINARY_DIR="${CMAKE_BINARY_DIR}")
  add_test(NAME arm64.${name} COMMAND ${target})
  set_tests_properties(arm64.${name} PROPERTIES LABELS arm64 TIMEOUT 600)
endfunction()

animrt_arm64_test(codecs
  bridge/protocol2_test.cpp bridge/protocol2_fast_read_test.cpp bridge/serial_servo_core_test.cpp
  bridge/bno08x_rvc_test.cpp bridge/rvc_reader_test.cpp bridge/dynamixel_bus_test.cpp
  can/mit_codec_test.cpp can/canopen_test.cpp can/cia402_state_test.cpp can/lockstep_can_test.cpp
  feetech/feetech_codec_test.cpp feetech/feetech_bus_test.cpp
  maestro/maestro_codec_test.cpp
  modbus/register_map_test.cpp modbus/sim_frame_test.cpp
  runtime/mcap_test.cpp)
animrt_arm64_test(loop
  core/error_test.cpp core/mailbox_test.cpp core/input_file_test.cpp
  runtime/cycle_test.cpp runtime/cycle_sensors_test.cpp runtime/cycle_balance_test.cpp
  runtime/safety_filter_test.cpp runtime/runner_test.cpp runtime/telemetry_test.cpp
  runtime/service_watch_test.cpp runtime/bus_worker_test.cpp)
animrt_arm64_test(devices
  sim/dynamixel_servo_test.cpp sim/dynamixel_fast_read_test.cpp sim/dynamixel_sim_bus_test.cpp
  sim/dynamixel_bus_on_sim_test.cpp
  feetech/feetech_sim_test.cpp feetech/feetech_bus_on_sim_test.cpp
  can/can_nodes_test.cpp can/cia402_homing_test.cpp can/cia402_guard_bus_test.cpp
  can/device_guard_test.cpp
  modbus/modbus_bus_test.cpp
  maestro/maestro_board_test.cpp maestro/maestro_bus_test.cpp)
animrt_arm64_test(lockstep
  integration/quadruped_lockstep_test.cpp integration/lockstep_line_test.cpp
  integration/figure_builder_test.cpp
  integration_can/quadruped_can_lockstep_test.cpp
  integration_feetech/arm_sts_lockstep_test.cpp
  integration_mixed/mixed_figure_test.cpp)
