# ANIMRT_LOOP_ONLY: the loop's unit tests in one executable (the cycle, the
# safety filter and ramps, the runner on fake buses in lockstep, telemetry,
# the heartbeat), without the simulated devices or the learners the full
# test tree links. Cross-compiled, ctest runs it under the emulator.
find_package(GTest REQUIRED)
enable_testing()
set(loop_test_srcs core/error_test.cpp core/mailbox_test.cpp runtime/cycle_test.cpp
    runtime/cycle_sensors_test.cpp runtime/safety_filter_test.cpp runtime/runner_test.cpp
    runtime/telemetry_test.cpp runtime/service_watch_test.cpp support/alloc_counter.cpp)
list(TRANSFORM loop_test_srcs PREPEND ${CMAKE_SOURCE_DIR}/tests/)
add_executable(animrt_test_loop ${loop_test_srcs})
target_include_directories(animrt_test_loop PRIVATE ${CMAKE_SOURCE_DIR}/tests)
target_link_libraries(animrt_test_loop PRIVATE animrt_loop GTest::gtest GTest::gtest_main
                      ${CMAKE_DL_LIBS})
add_test(NAME loop COMMAND animrt_test_loop)
set_tests_properties(loop PROPERTIES LABELS unit TIMEOUT 600)
