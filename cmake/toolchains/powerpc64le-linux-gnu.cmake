# Cross toolchain for ppc64le (Debian: crossbuild-essential + multiarch libraries), .ci/cross-check.
set(SG_CROSS_GNU powerpc64le-linux-gnu)
set(SG_CROSS_MULTIARCH powerpc64le-linux-gnu)
set(SG_CROSS_PROCESSOR ppc64le)
set(SG_CROSS_EMULATOR qemu-ppc64le -L /)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
