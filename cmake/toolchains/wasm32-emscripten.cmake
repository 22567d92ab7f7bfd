# WebAssembly (wasm32) through Debian's emscripten, run by Node.js: .ci/cross-check wasm32.
#
# SG_WASM_DEPS (required, -DSG_WASM_DEPS=DIR): a prefix that .ci/cross-check fills with the
# dependencies built for wasm32 and copies of the header-only ones:
#   include/    zstd.h, xxhash.h, spng.h, zlib.h, stb/, nlohmann/, CLI/
#   lib/        libzstd.a, libxxhash.a, libstb.a, libspng.a, libz.a (compiled with emcc from
#               Debian's sources/headers)
#   lib/pkgconfig/{libxxhash,stb,spng}.pc, lib/cmake/zstd/, share/cmake/{nlohmann_json,CLI11}/
# Nothing is taken from the build machine's /usr/include itself: an -isystem /usr/include would
# put glibc's headers in front of emscripten's libc. Eigen is header-only in its own directory
# (/usr/include/eigen3), so Debian's package is used as it is.
#
# Exceptions: Debian's frozen emscripten cache has the JavaScript-based C++ exception libraries
# only (no -fwasm-exceptions build), so the program is compiled and linked with -fexceptions
# (the CLI catches its parse errors; without it a throw aborts).
# Threads: none. The core's ChunkPool starts no thread for --threads 1 (the default), and the
# check never passes more, so no -pthread / SharedArrayBuffer is needed.
# Files: NODERAWFS=1 gives the program the host's file system, relative paths included.
# WASM_ASYNC_COMPILATION=0: emscripten 3.1.6 would fetch() the .wasm when the JavaScript engine
# has a global fetch (Node.js 18 and later), which fails for a file path; synchronous
# instantiation reads the file.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES SG_WASM_DEPS)  # the toolchain runs in try_compile too
if(NOT SG_WASM_DEPS)
  message(FATAL_ERROR "wasm32 toolchain: pass -DSG_WASM_DEPS=DIR (.ci/cross-check wasm32 builds it)")
endif()
set(_sg_em_root "$ENV{EMSCRIPTEN_ROOT}")
if(NOT _sg_em_root)
  set(_sg_em_root /usr/share/emscripten)
endif()
include(${_sg_em_root}/cmake/Modules/Platform/Emscripten.cmake)

set(ENV{PKG_CONFIG_LIBDIR} ${SG_WASM_DEPS}/lib/pkgconfig)
unset(ENV{PKG_CONFIG_PATH})
list(APPEND CMAKE_FIND_ROOT_PATH ${SG_WASM_DEPS})  # pkg-config's libdir hints (find_library, ONLY mode)
set(zstd_DIR ${SG_WASM_DEPS}/lib/cmake/zstd CACHE PATH "zstd built for wasm32")
set(nlohmann_json_DIR ${SG_WASM_DEPS}/share/cmake/nlohmann_json CACHE PATH "nlohmann-json (copied headers)")
set(CLI11_DIR ${SG_WASM_DEPS}/share/cmake/CLI11 CACHE PATH "CLI11 (copied headers)")
set(Eigen3_DIR /usr/share/eigen3/cmake CACHE PATH "Eigen 3 (Debian, header-only)")

set(CMAKE_C_FLAGS_INIT "-fexceptions")
set(CMAKE_CXX_FLAGS_INIT "-fexceptions")
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "-fexceptions -sNODERAWFS=1 -sWASM_ASYNC_COMPILATION=0 -sALLOW_MEMORY_GROWTH=1 -sMAXIMUM_MEMORY=4GB -sEXIT_RUNTIME=1")
set(CMAKE_CROSSCOMPILING_EMULATOR node CACHE FILEPATH "runs a wasm32 program" FORCE)
