# Cross toolchain for i686 (Debian: crossbuild-essential + multiarch libraries), .ci/cross-check.
set(SG_CROSS_GNU i686-linux-gnu)
set(SG_CROSS_MULTIARCH i386-linux-gnu)
set(SG_CROSS_PROCESSOR i686)
set(SG_CROSS_EMULATOR qemu-i386 -L /)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
# float/double in SSE2 registers, not the x87 unit: x87 keeps 80-bit intermediates, so float and
# double results differed from every other architecture's IEEE single/double steps (measured:
# thesis-meadow float/double hashes). Any i686 CPU of this century has SSE2.
set(CMAKE_C_FLAGS_INIT "-msse2 -mfpmath=sse")
set(CMAKE_CXX_FLAGS_INIT "-msse2 -mfpmath=sse")
