// The saved-state format, version 2 (docs/state-format.md): what saveState() writes, stateHash()
// hashes and restoreState() reads.
//
//   magic "SGSTATE2" (8 bytes), then sections in this fixed order, every one always present but TRMP:
//     tag (4 ASCII bytes)  payload length (u64)  payload
//   HEAD  version u32 (2), scalar u8, k u8, reserved u16 (0), scenario fingerprint u64, tick i64,
//         particle count i64, body count u32, reserved u32 (0)
//   PART  px, py, pz, vx, vy, vz: particle count scalars each, in window storage order
//   TRMP  only in worlds whose grass tramples (model blade, trampleSeconds > 0): the trample
//         level of each particle (particle count scalars, each in [0, 1]), in the same order
//   BODY  per body: position (3), orientation w x y z (4), velocity (3), angular velocity (3)
//         scalars, still ticks i32, flags u8 (1 asleep, 2 blade off), reserved u8 u16 (0)
//   SPWN  spawned bodies (body scenario-bodies + n is spawn n): count u32, then per spawn
//         template body i32, reserved i32 (0), position as Q32.32 raw i64 x3
//   CONT  warm-start impulses: count u64, then per entry body A i32, body B i32 (-1 terrain),
//         feature A u32, feature B u32, normal, tangent 1, tangent 2, point x y z (6 scalars)
//   CUTS  mown patches: count u64, then (i, j) i64 pairs in increasing (i, j) order
//   LODW  level-of-detail window origin (particle lattice column, row) i64 x2; (0, 0) when off
//
// Every multi-byte field is little-endian whatever the host (byte_order.h); a scalar is its raw
// bits (Q32.32 int64, Q16.16 int32, IEEE float/double). The fixed order and the absence of any
// host-dependent byte make the bytes canonical: equal states are equal bytes on every machine.
#pragma once

#include <cstdint>

namespace sg::state {

inline constexpr char kMagic[8] = {'S', 'G', 'S', 'T', 'A', 'T', 'E', '2'};
inline constexpr uint32_t kVersion = 2;

/// Section tags in their order in a state.
enum class Section : uint8_t { Head, Particles, Trample, Bodies, Spawns, Impulses, Cuts, Window, Count };
inline constexpr char kSectionTags[int(Section::Count)][5] = {"HEAD", "PART", "TRMP", "BODY",
                                                              "SPWN", "CONT", "CUTS", "LODW"};

inline constexpr uint64_t kSectionHeaderBytes = 12;  ///< tag + payload length
inline constexpr uint64_t kHeadBytes = 40;
inline constexpr uint64_t kSpawnBytes = 32;
/// Fixed bytes of one body record besides its 13 scalars.
inline constexpr uint64_t kBodyExtraBytes = 8;
/// Fixed bytes of one warm-start entry besides its 6 scalars.
inline constexpr uint64_t kImpulseExtraBytes = 16;

inline constexpr uint8_t kBodyAsleep = 1;
inline constexpr uint8_t kBodyBladeOff = 2;

}  // namespace sg::state
