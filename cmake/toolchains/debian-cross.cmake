# Shared part of the Debian cross toolchains (cmake/toolchains/<triplet>.cmake set the four
# variables below, then include this file). Used by .ci/cross-check; docs/determinism.md.
#
#   SG_CROSS_GNU       prefix of the cross compilers (crossbuild-essential-*): aarch64-linux-gnu
#   SG_CROSS_MULTIARCH Debian multiarch triplet of the target libraries:        aarch64-linux-gnu
#   SG_CROSS_PROCESSOR CMAKE_SYSTEM_PROCESSOR
#   SG_CROSS_EMULATOR  how to run a target program here (qemu-user), a list
#
# Libraries come from Debian's multiarch packages (libzstd-dev:arm64 ...) in
# /usr/lib/<multiarch>; headers-only packages (Eigen, nlohmann-json, CLI11) from /usr/share.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR ${SG_CROSS_PROCESSOR})
set(CMAKE_C_COMPILER ${SG_CROSS_GNU}-gcc)
set(CMAKE_CXX_COMPILER ${SG_CROSS_GNU}-g++)
set(CMAKE_LIBRARY_ARCHITECTURE ${SG_CROSS_MULTIARCH})
set(CMAKE_CROSSCOMPILING_EMULATOR ${SG_CROSS_EMULATOR})

# pkg-config: the target's .pc files only (never the build machine's x86-64 ones). SG_PNG_DEPS
# (-DSG_PNG_DEPS=DIR, .ci/cross-check): libspng + zlib compiled for the target from Debian's
# sources (libspng-dev is not Multi-Arch: same, so it has no multiarch package to install).
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES SG_PNG_DEPS)
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/${SG_CROSS_MULTIARCH}/pkgconfig:/usr/share/pkgconfig)
if(SG_PNG_DEPS)
  set(ENV{PKG_CONFIG_LIBDIR} ${SG_PNG_DEPS}/lib/pkgconfig:$ENV{PKG_CONFIG_LIBDIR})
endif()
unset(ENV{PKG_CONFIG_PATH})

# find_package/find_library: the cross compiler's own tree first, then the multiarch
# directories of / (CMAKE_LIBRARY_ARCHITECTURE picks /usr/lib/<multiarch>); programs from the host.
set(CMAKE_FIND_ROOT_PATH /usr/${SG_CROSS_GNU})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)

# libstdc++ and libgcc linked in: qemu runs the program with the multiarch libc of / (-L /), which
# has no target libstdc++ (libstdc++6:<arch> is not installed, the cross one lives in
# /usr/<triplet>/lib where that loader does not look).
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static-libstdc++ -static-libgcc")
