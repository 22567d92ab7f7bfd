# Cross toolchain for i686 (Debian: crossbuild-essential + multiarch libraries), .ci/cross-check.
set(SG_CROSS_GNU i686-linux-gnu)
set(SG_CROSS_MULTIARCH i386-linux-gnu)
set(SG_CROSS_PROCESSOR i686)
set(SG_CROSS_EMULATOR qemu-i386 -L /)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
