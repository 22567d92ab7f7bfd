# Cross toolchain for aarch64 (Debian: crossbuild-essential + multiarch libraries), .ci/cross-check.
set(SG_CROSS_GNU aarch64-linux-gnu)
set(SG_CROSS_MULTIARCH aarch64-linux-gnu)
set(SG_CROSS_PROCESSOR aarch64)
set(SG_CROSS_EMULATOR qemu-aarch64 -L /)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
