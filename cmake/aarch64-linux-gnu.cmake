# Cross-compiling for 64-bit ARM with Debian's cross toolchain (g++-aarch64-linux-gnu) and the
# arm64 packages of the dependencies (multiarch): scripts/check-aarch64 uses it.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
