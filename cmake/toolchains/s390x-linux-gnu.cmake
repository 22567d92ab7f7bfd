# Cross toolchain for s390x (Debian: crossbuild-essential + multiarch libraries), .ci/cross-check.
set(SG_CROSS_GNU s390x-linux-gnu)
set(SG_CROSS_MULTIARCH s390x-linux-gnu)
set(SG_CROSS_PROCESSOR s390x)
set(SG_CROSS_EMULATOR qemu-s390x -L /)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
