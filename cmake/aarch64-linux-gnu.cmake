# Cross-compiling for arm64 with Debian's cross toolchain
# (crossbuild-essential-arm64) against the arm64 libraries installed beside
# the host's (dpkg --add-architecture arm64; libfoo-dev:arm64). The binaries
# run here under qemu-user (qemu-aarch64-static), which ctest puts in front
# of every test.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
# The arm64 libraries' pkg-config files, never the host's.
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")
# The loader and libraries are under / (multiarch): qemu needs no prefix.
find_program(ANIMRT_QEMU_AARCH64 qemu-aarch64-static REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR ${ANIMRT_QEMU_AARCH64})
