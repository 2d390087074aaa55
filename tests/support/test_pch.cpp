// Compiled with the test binaries' precompiled header (tests/CMakeLists.txt,
// animrt_test_pch), which is built beside it for every test binary to use.
