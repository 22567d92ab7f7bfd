// Little-endian byte order for everything the core saves or hashes: a state saved on any machine
// (x86-64, aarch64, big-endian s390x, ...) is the same bytes, so its hash is too.
//
// Values are stored by shifts, never by copying host memory, except where the host is known to
// be little-endian at compile time (then the copy *is* the canonical form, and arrays go out in
// one call: the state hash streams ~50 MB per tick at a million particles).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace sg {

// The compilers' predefined macros (GCC, Clang, emscripten), not std::endian: one less library
// feature for the older cross toolchains to lack.
inline constexpr bool kHostIsLittleEndian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

/// The unsigned integer of the same width as T (T: an integer, float or double).
template <class T>
using UnsignedOfSize = std::conditional_t<
    sizeof(T) == 1, uint8_t,
    std::conditional_t<sizeof(T) == 2, uint16_t, std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>>;

/// Writes v's bits (two's complement for signed integers, IEEE bits for float/double) to out in
/// little-endian order.
template <class T>
inline void storeLE(uint8_t* out, T v) {
  static_assert(sizeof(T) <= 8 && std::is_trivially_copyable_v<T>);
  using U = UnsignedOfSize<T>;
  U u;
  std::memcpy(&u, &v, sizeof u);  // std::bit_cast, which emscripten 3.1.6's libc++ lacks
  for (size_t i = 0; i < sizeof(T); ++i) out[i] = uint8_t(u >> (8 * i));
}

/// Reads a T stored by storeLE.
template <class T>
inline T loadLE(const uint8_t* in) {
  static_assert(sizeof(T) <= 8 && std::is_trivially_copyable_v<T>);
  using U = UnsignedOfSize<T>;
  U u = 0;
  for (size_t i = 0; i < sizeof(T); ++i) u = U(u | U(U(in[i]) << (8 * i)));
  T v;
  std::memcpy(&v, &u, sizeof v);
  return v;
}

}  // namespace sg
