# Cross-compiling for arm64 with Debian's cross toolchain
# (crossbuild-essential-arm64) against a sysroot of Debian's arm64 -dev
# packages, extracted by packaging/arm64-sysroot (ANIMRT_ARM64_SYSROOT;
# `make test-arm64` builds it under the cross build directory). The
# binaries run here under qemu-user (qemu-aarch64-static, with the
# sysroot's loader and libraries), which ctest puts in front of every test.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
set(ANIMRT_ARM64_SYSROOT "" CACHE PATH "arm64 sysroot (packaging/arm64-sysroot)")
# try_compile projects read this file too: hand the sysroot on to them.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES ANIMRT_ARM64_SYSROOT)
if(NOT ANIMRT_ARM64_SYSROOT OR NOT EXISTS "${ANIMRT_ARM64_SYSROOT}/usr/include")
  message(FATAL_ERROR "ANIMRT_ARM64_SYSROOT must name a sysroot built by packaging/arm64-sysroot")
endif()
set(CMAKE_SYSROOT "${ANIMRT_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH "${ANIMRT_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
# The sysroot's pkg-config files, never the host's.
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${ANIMRT_ARM64_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${ANIMRT_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${ANIMRT_ARM64_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")
# MuJoCo's CMake package asks for OpenGL, which the sysroot leaves out.
list(APPEND CMAKE_MODULE_PATH ${CMAKE_CURRENT_LIST_DIR}/arm64)
# Debian's cross g++ looks for LLVM's linker (-fuse-ld=lld, CMakeLists.txt)
# as ld.lld among its own programs, not on PATH: a directory that holds only
# that name, handed to it with -B.
find_program(ANIMRT_LD_LLD ld.lld)
if(ANIMRT_LD_LLD)
  file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/cross-ld)
  file(CREATE_LINK ${ANIMRT_LD_LLD} ${CMAKE_BINARY_DIR}/cross-ld/ld.lld SYMBOLIC)
  foreach(kind EXE SHARED MODULE)
    set(CMAKE_${kind}_LINKER_FLAGS_INIT "-B${CMAKE_BINARY_DIR}/cross-ld/")
  endforeach()
endif()
find_program(ANIMRT_QEMU_AARCH64 qemu-aarch64-static REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR ${ANIMRT_QEMU_AARCH64} -L ${ANIMRT_ARM64_SYSROOT})
