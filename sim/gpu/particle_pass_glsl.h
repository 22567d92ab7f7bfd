// The fused particle pass (sim/particles/particle_row.h), the bodies' push on the grass
// (sim/collision/body_particles.h) and the patch stage (sim/patches/patch_state.h) as OpenGL 4.3
// compute shaders, one invocation per particle, candidate particle or patch, in the fixed-point formats' exact integer
// arithmetic (GL_ARB_gpu_shader_int64). Each operation gives sim/math/fixed.h's bits and raises the same overflow: sums
// wrap and are checked by sign; products round to nearest, ties away from zero, Q32.32's 128-bit product built from 32
// x 32 -> 64 partial products; L / |d| and |d| are guessed in double precision and then settled in exact integer
// arithmetic (the guess only decides how many correction steps run, never the result). The prelude gl_physics.cpp puts
// before this text defines FLOAT (1: float, the comparison variant), FX32 (1: Q32.32; both 0: Q16.16), MODEL (0 thesis,
// 1 pbd, 2 blade) and TRAMPLE (0 or 1).
#pragma once

namespace sg::gpu {

/// The scalar format's arithmetic, shared by the particle pass and the patch pass: RAW (a value's
/// stored type) and the checked operations, each with fixed.h's bits (its fault in `overflowed`).
inline constexpr const char* kScalarGlsl = R"GLSL(
#if FLOAT
#define RAW float
#define ONE 1.0
#elif FX32
#define RAW int64_t
#define ONE (int64_t(1) << 32)
#else
#define RAW int
#define ONE (1 << 16)
#endif

bool overflowed;  // this invocation's fault bit (Fixed's kFixedFaultOverflow)

const double kTwo64 = 18446744073709551616.0;
const uint64_t kAllOnes = 0xFFFFFFFFFFFFFFFFul;

// ---- unsigned 128-bit helpers (hi, lo) ------------------------------------------------------
// a * b exactly, from four 32 x 32 -> 64 partial products.
void mul64x64(uint64_t a, uint64_t b, out uint64_t hi, out uint64_t lo) {
  uint64_t al = a & 0xFFFFFFFFul, ah = a >> 32, bl = b & 0xFFFFFFFFul, bh = b >> 32;
  uint64_t p0 = al * bl, p1 = al * bh, p2 = ah * bl, p3 = ah * bh;
  uint64_t mid = (p0 >> 32) + (p1 & 0xFFFFFFFFul) + (p2 & 0xFFFFFFFFul);  // < 3 * 2^32
  lo = (mid << 32) | (p0 & 0xFFFFFFFFul);
  hi = p3 + (p1 >> 32) + (p2 >> 32) + (mid >> 32);
}
bool lessOrEqual128(uint64_t ah, uint64_t al, uint64_t bh, uint64_t bl) { return ah < bh || (ah == bh && al <= bl); }
// |a - b| and whether a >= b.
bool difference128(uint64_t ah, uint64_t al, uint64_t bh, uint64_t bl, out uint64_t dh, out uint64_t dl) {
  bool aAbove = lessOrEqual128(bh, bl, ah, al);
  if (aAbove) { dl = al - bl; dh = ah - bh - (al < bl ? 1ul : 0ul); }
  else { dl = bl - al; dh = bh - ah - (bl < al ? 1ul : 0ul); }
  return aAbove;
}
double toDouble128(uint64_t hi, uint64_t lo) { return double(hi) * kTwo64 + double(lo); }
uint64_t clampedGuess(double g) { return g >= 18446744073709549568.0 ? kAllOnes : (g > 0.0 ? uint64_t(g) : 0ul); }

// floor(n / d) and the remainder, for nh < d (the quotient fits 64 bits): a double guess, then
// Newton-like corrections from the exact remainder (one or two in practice), with schoolbook
// long division as the bounded fallback.
void divide128by64(uint64_t nh, uint64_t nl, uint64_t d, out uint64_t q, out uint64_t r) {
  double dd = double(d);
  uint64_t guess = clampedGuess(toDouble128(nh, nl) / dd);
  for (int step = 0; step < 8; ++step) {
    uint64_t ph, pl, eh, el;
    mul64x64(guess, d, ph, pl);
    bool below = difference128(nh, nl, ph, pl, eh, el);  // guess d <= n
    if (below && eh == 0ul && el < d) { q = guess; r = el; return; }
    uint64_t move = max(uint64_t(toDouble128(eh, el) / dd), 1ul);
    guess = below ? guess + move : guess - move;
  }
  uint64_t rem = 0ul, quo = 0ul;  // never reached in tests; exact for any nh < d
  for (int bit = 127; bit >= 0; --bit) {
    uint64_t top = rem >> 63;
    rem = (rem << 1) | ((bit >= 64 ? (nh >> (bit - 64)) : (nl >> bit)) & 1ul);
    if (top != 0ul || rem >= d) { rem -= d; if (bit < 64) quo |= 1ul << bit; }
  }
  q = quo;
  r = rem;
}

// floor(sqrt(n)) for any 128-bit n: a double guess, then corrections from the exact n - r^2.
uint64_t isqrtFloor128(uint64_t nh, uint64_t nl) {
  uint64_t r = clampedGuess(sqrt(toDouble128(nh, nl)));
  for (int step = 0; step < 64; ++step) {
    uint64_t sh, sl, eh, el;
    mul64x64(r, r, sh, sl);
    bool below = difference128(nh, nl, sh, sl, eh, el);  // r^2 <= n
    // floor: r^2 <= n < (r + 1)^2, i.e. n - r^2 <= 2r
    if (below && lessOrEqual128(eh, el, r >> 63, r << 1)) return r;
    double slope = 2.0 * double(r) + 1.0;
    uint64_t move = max(uint64_t(toDouble128(eh, el) / slope), 1ul);
    r = below ? r + move : r - move;
  }
  return r;  // unreachable: each step at least halves the error once the guess is close
}

#if FLOAT
// ---- float: a comparison variant, no bit-identity promise (GLSL allows division and sqrt some
// latitude). `precise` keeps each product out of a fused multiply-add, as -ffp-contract=off does
// on the CPU; a fault is a non-finite result, as the CPU's float kernels report it.
RAW addChecked(RAW a, RAW b) { precise RAW r = a + b; return r; }
RAW subChecked(RAW a, RAW b) { precise RAW r = a - b; return r; }
RAW mulChecked(RAW a, RAW b) { precise RAW r = a * b; return r; }
RAW divChecked(RAW a, RAW b) { precise RAW r = a / b; return r; }
RAW length3(RAW x, RAW y, RAW z) {
  precise RAW xx = x * x;
  precise RAW yy = y * y;
  precise RAW zz = z * z;
  precise RAW sum = xx + yy;
  precise RAW total = sum + zz;
  return sqrt(total);
}
void checkFinite(RAW a, RAW b, RAW c, RAW d, RAW e, RAW f) {
  if (isinf(a) || isnan(a) || isinf(b) || isnan(b) || isinf(c) || isnan(c) || isinf(d) || isnan(d) || isinf(e) ||
      isnan(e) || isinf(f) || isnan(f))
    overflowed = true;
}
// The end of a particle's step: within a saved state's range, |x| <= 2^48, as the CPU's
// FloatTraits::inStateRange (NaN fails the compare). The integration checks finiteness only.
void checkInRange(RAW a, RAW b, RAW c, RAW d, RAW e, RAW f) {
  const RAW limit = 281474976710656.0;
  if (!(abs(a) <= limit && abs(b) <= limit && abs(c) <= limit && abs(d) <= limit && abs(e) <= limit &&
        abs(f) <= limit))
    overflowed = true;
}
#elif FX32
// ---- Q32.32 (fixed.h's Fx32: int64 raw, 128-bit wide) ---------------------------------------
RAW addChecked(RAW a, RAW b) { RAW r = a + b; if (((a ^ r) & (b ^ r)) < 0l) overflowed = true; return r; }
RAW subChecked(RAW a, RAW b) { RAW r = a - b; if (((a ^ b) & (a ^ r)) < 0l) overflowed = true; return r; }
uint64_t magnitude(RAW a) { return a < 0l ? uint64_t(-a) : uint64_t(a); }  // INT64_MIN: 2^63
// Fixed::operator*: round(a b / 2^32), ties away from zero (the rounding is symmetric, so it is
// formed on magnitudes), then narrowed to 64 bits (wrapping, with the overflow raised).
RAW mulChecked(RAW a, RAW b) {
  bool negative = (a < 0l) != (b < 0l);
  uint64_t hi, lo;
  mul64x64(magnitude(a), magnitude(b), hi, lo);
  uint64_t rounded = lo + 0x80000000ul;
  hi += rounded < lo ? 1ul : 0ul;
  uint64_t m = (hi << 32) | (rounded >> 32);
  if ((hi >> 32) != 0ul || m > (negative ? 0x8000000000000000ul : 0x7FFFFFFFFFFFFFFFul)) overflowed = true;
  return negative ? -RAW(m) : RAW(m);
}
// Fixed::operator/ for b != 0: round(a 2^32 / b), ties away from zero.
RAW divChecked(RAW a, RAW b) {
  bool negative = (a < 0l) != (b < 0l);
  uint64_t ua = magnitude(a), ud = magnitude(b);
  uint64_t nh = ua >> 32, nl = ua << 32;
  if (nh >= ud) { overflowed = true; return negative ? RAW(0x8000000000000000ul) : RAW(0x7FFFFFFFFFFFFFFFul); }
  uint64_t q, r;
  divide128by64(nh, nl, ud, q, r);
  bool up = r >= ud - r;
  if (up && q == kAllOnes) { overflowed = true; return negative ? RAW(0x8000000000000000ul) : RAW(0x7FFFFFFFFFFFFFFFul); }
  uint64_t m = q + (up ? 1ul : 0ul);
  if (m > (negative ? 0x8000000000000000ul : 0x7FFFFFFFFFFFFFFFul)) overflowed = true;
  return negative ? -RAW(m) : RAW(m);
}
// x^2 + y^2 + z^2 of the raw values, exactly (< 3 2^126: no carry out of 128 bits).
void sumOfSquares(RAW x, RAW y, RAW z, out uint64_t h, out uint64_t l) {
  h = 0ul;
  l = 0ul;
  RAW v[3] = RAW[3](x, y, z);
  for (int a = 0; a < 3; ++a) {
    uint64_t sh, sl;
    uint64_t m = magnitude(v[a]);
    mul64x64(m, m, sh, sl);
    l += sl;
    h += sh + (l < sl ? 1ul : 0ul);
  }
}
// length3: isqrtNearest of the exact sum of squares.
RAW length3(RAW x, RAW y, RAW z) {
  uint64_t h, l;
  sumOfSquares(x, y, z, h, l);
  uint64_t r = isqrtFloor128(h, l);
  uint64_t sh, sl, eh, el;
  mul64x64(r, r, sh, sl);
  difference128(h, l, sh, sl, eh, el);  // n - r^2 >= 0
  if (eh != 0ul || el > r) r += 1ul;    // isqrtNearest
  if (r > 0x7FFFFFFFFFFFFFFFul) overflowed = true;
  return RAW(r);
}
#else
// ---- Q16.16 (fixed.h's Fx16: int32 raw, 64-bit wide) ----------------------------------------
RAW addChecked(RAW a, RAW b) { RAW r = a + b; if (((a ^ r) & (b ^ r)) < 0) overflowed = true; return r; }
RAW subChecked(RAW a, RAW b) { RAW r = a - b; if (((a ^ b) & (a ^ r)) < 0) overflowed = true; return r; }
RAW narrow(int64_t w) {
  if (w > 2147483647l || w < -2147483648l) overflowed = true;
  return RAW(uint(uint64_t(w) & 0xFFFFFFFFul));  // the low 32 bits, as static_cast does
}
RAW mulChecked(RAW a, RAW b) {
  int64_t p = int64_t(a) * int64_t(b);
  return narrow((p + (1l << 15) + (p >> 63)) >> 16);
}
RAW divChecked(RAW a, RAW b) {
  if (b == 0) { overflowed = true; return a < 0 ? RAW(0x80000000u) : RAW(0x7FFFFFFF); }  // Fixed's fault and value
  bool negative = (a < 0) != (b < 0);
  uint64_t un = uint64_t(abs(int64_t(a))) << 16, ud = uint64_t(abs(int64_t(b)));
  uint64_t q = un / ud, r = un - q * ud;
  uint64_t m = q + (r >= ud - r ? 1ul : 0ul);
  return narrow(negative ? -int64_t(m) : int64_t(m));
}
RAW length3(RAW x, RAW y, RAW z) {
  uint64_t mx = uint64_t(abs(int64_t(x))), my = uint64_t(abs(int64_t(y))), mz = uint64_t(abs(int64_t(z)));
  uint64_t n = mx * mx + my * my + mz * mz;  // < 3 2^62
  uint64_t r = isqrtFloor128(0ul, n);
  if (n - r * r > r) r += 1ul;
  if (r > 2147483647ul) overflowed = true;
  return RAW(uint(r));
}
#endif

#if !FLOAT
void checkFinite(RAW a, RAW b, RAW c, RAW d, RAW e, RAW f) {}  // every fixed-point value is finite
void checkInRange(RAW a, RAW b, RAW c, RAW d, RAW e, RAW f) {}  // and can be saved
#endif

)GLSL";

inline constexpr const char* kParticlePassGlsl = R"GLSL(
layout(local_size_x = 256) in;

// Each buffer holds three arrays of `count` values (x, then y, then z). The pass reads one set of
// positions and velocities and writes the other: a pass that faults leaves the tick's input
// intact, so the CPU reference can redo that tick (docs/gpu-physics.md, "Faults").
layout(std430, binding = 0) readonly buffer PositionIn { RAW positionIn[]; };
layout(std430, binding = 1) readonly buffer VelocityIn { RAW velocityIn[]; };
layout(std430, binding = 2) writeonly buffer PositionOut { RAW positionOut[]; };
layout(std430, binding = 3) writeonly buffer VelocityOut { RAW velocityOut[]; };
layout(std430, binding = 4) readonly buffer Anchor { RAW anchor[]; };
layout(std430, binding = 5) writeonly buffer Displacement { RAW displacement[]; };
// [0..7]: dt, damping per tick, rod length, 1/dt, blade stiffness dt, blade damping per tick,
// trample decay per tick, 1/L (ParticleConstants); then run k's (a + F/m) dt at 8 + 3k (x, y, z).
layout(std430, binding = 6) readonly buffer Tick { RAW tickData[]; };
// The smallest fault key (0xffffffff: none); see faultKey() below.
layout(std430, binding = 7) buffer Fault { uint faultKey; };
// [0..countZ]: row r's wind runs are [runs[r], runs[r + 1]); run k covers columns
// [runs[countZ + 1 + 2k], runs[countZ + 2 + 2k]).
layout(std430, binding = 8) readonly buffer Runs { uint runs[]; };
#if TRAMPLE
layout(std430, binding = 9) readonly buffer TrampleIn { RAW trampleIn[]; };
layout(std430, binding = 10) writeonly buffer TrampleOut { RAW trampleOut[]; };
#endif

uniform uint countX;
uniform uint countZ;
uniform uint count;

void noteFault(uint key) { atomicMin(faultKey, key); }

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  uint row = i / countX, column = i - row * countX;
  RAW dt = tickData[0], rod = tickData[2], invDt = tickData[3];
  // The run of this row whose columns hold this particle: the CPU advances a row run by run, in
  // column order, so its fault order is (row, run, stage, column). The key below orders the same
  // way: run k of the row covers keys [2 begin_k, 2 end_k) after the row's base.
  // (Each run's end is stored beside its begin. Read instead as `k + 1 < endRun ? <the next run's
  // begin> : countX`, it came out 0 for a row's first run on llvmpipe (Mesa 22.3.6), though the
  // loop above had just read the same element as non-zero; tests/gpu_physics_test.cpp's
  // properties found it.)
  uint endRun = runs[row + 1u], k = runs[row];
  while (k + 1u < endRun && runs[countZ + 1u + 2u * (k + 1u)] <= column) ++k;
  uint pieceBegin = runs[countZ + 1u + 2u * k];
  uint pieceEnd = runs[countZ + 2u + 2u * k];
  uint integrationKey = row * 2u * countX + 2u * pieceBegin + (column - pieceBegin);
  uint projectionKey = integrationKey + (pieceEnd - pieceBegin);
  RAW dvx = tickData[8u + 3u * k], dvy = tickData[9u + 3u * k], dvz = tickData[10u + 3u * k];
  uint j = i + count, l = j + count;  // y and z of particle i
  RAW x = positionIn[i], y = positionIn[j], z = positionIn[l];
  RAW u = velocityIn[i], v = velocityIn[j], w = velocityIn[l];
  RAW ax = anchor[i], ay = anchor[j], az = anchor[l];
  RAW nx, ny, nz;
  overflowed = false;
#if MODEL == 2
  // blade.h: one loop, every fault the integration's.
  RAW stiffness = tickData[4], damping = tickData[5], decay = tickData[6], invRod = tickData[7];
#if TRAMPLE
  RAW trample = trampleIn[i];
  stiffness = mulChecked(stiffness, subChecked(RAW(ONE), trample));
  trampleOut[i] = trample > decay ? subChecked(trample, decay) : RAW(0);
#endif
  RAW rx = subChecked(x, ax), ry = subChecked(y, ay), rz = subChecked(z, az);
  RAW gx = subChecked(dvx, mulChecked(stiffness, rx));
  RAW gy = subChecked(dvy, mulChecked(stiffness, subChecked(ry, rod)));
  RAW gz = subChecked(dvz, mulChecked(stiffness, rz));
  RAW along = mulChecked(
      mulChecked(addChecked(addChecked(mulChecked(gx, rx), mulChecked(gy, ry)), mulChecked(gz, rz)), invRod), invRod);
  gx = subChecked(gx, mulChecked(rx, along));
  gy = subChecked(gy, mulChecked(ry, along));
  gz = subChecked(gz, mulChecked(rz, along));
  u = mulChecked(addChecked(u, gx), damping);
  v = mulChecked(addChecked(v, gy), damping);
  w = mulChecked(addChecked(w, gz), damping);
  RAW predictedX = addChecked(x, mulChecked(u, dt)), predictedY = addChecked(y, mulChecked(v, dt)),
      predictedZ = addChecked(z, mulChecked(w, dt));
  RAW ex = subChecked(predictedX, ax), ey = predictedY > ay ? subChecked(predictedY, ay) : RAW(0),
      ez = subChecked(predictedZ, az);
  RAW len = length3(ex, ey, ez);
  nx = ax;
  ny = addChecked(ay, rod);  // computed whether or not it is used, as the reference does
  nz = az;
  if (len != RAW(0)) {
    RAW scale = divChecked(rod, len);
    nx = addChecked(ax, mulChecked(ex, scale));
    ny = addChecked(ay, mulChecked(ey, scale));
    nz = addChecked(az, mulChecked(ez, scale));
  }
  u = addChecked(u, mulChecked(subChecked(nx, predictedX), invDt));
  v = addChecked(v, mulChecked(subChecked(ny, predictedY), invDt));
  w = addChecked(w, mulChecked(subChecked(nz, predictedZ), invDt));
  checkInRange(nx, ny, nz, u, v, w);
  if (overflowed) noteFault(integrationKey);
#else
  RAW damping = tickData[1];
  // Stage 3, integrate.h: explicit order for "thesis", symplectic for "pbd".
#if MODEL == 0
  x = addChecked(x, mulChecked(u, dt));
  y = addChecked(y, mulChecked(v, dt));
  z = addChecked(z, mulChecked(w, dt));
#endif
  u = mulChecked(addChecked(u, dvx), damping);
  v = mulChecked(addChecked(v, dvy), damping);
  w = mulChecked(addChecked(w, dvz), damping);
#if MODEL == 1
  x = addChecked(x, mulChecked(u, dt));
  y = addChecked(y, mulChecked(v, dt));
  z = addChecked(z, mulChecked(w, dt));
#endif
  checkFinite(x, y, z, u, v, w);
  if (overflowed) noteFault(integrationKey);

  // Stage 4, rod_constraint.h.
  overflowed = false;
  RAW dx = subChecked(x, ax), dy = subChecked(y, ay), dz = subChecked(z, az);
  RAW len = length3(dx, dy, dz);
  if (len == RAW(0)) {
    nx = ax;
    ny = addChecked(ay, rod);
    nz = az;
  } else {
    RAW scale = divChecked(rod, len);
    nx = addChecked(ax, mulChecked(dx, scale));
    ny = addChecked(ay, mulChecked(dy, scale));
    nz = addChecked(az, mulChecked(dz, scale));
  }
#if MODEL == 1
  u = addChecked(u, mulChecked(subChecked(nx, x), invDt));
  v = addChecked(v, mulChecked(subChecked(ny, y), invDt));
  w = addChecked(w, mulChecked(subChecked(nz, z), invDt));
#endif
  checkInRange(nx, ny, nz, u, v, w);
  if (overflowed) noteFault(projectionKey);
#endif

  positionOut[i] = nx; positionOut[j] = ny; positionOut[l] = nz;
  velocityOut[i] = u; velocityOut[j] = v; velocityOut[l] = w;
  // The tip displacement the patch stage reads (patch_state.h): unchecked, wrapping.
  displacement[i] = nx - ax;
  displacement[j] = ny - ay - rod;
  displacement[l] = nz - az;
}
)GLSL";

/// The bodies' push on the grass (sim/collision/body_particles.h) as a compute shader, one
/// invocation per candidate particle: those whose storage row has parts over it and whose column
/// lies in one of their ranges (a list the host builds from the pushers, without positions). Per
/// particle the parts over its row, in (body, part) order, each where the particle lies in its
/// range and reach cube, with the same operations and the same escape chain as
/// pushParticlesOutOfBodies. It runs in the response stage, as the CPU's push, in place on the
/// current state, and keeps each candidate's state as it found it (backup): a push that faults,
/// or may have, offers fault key 0, and a second dispatch (`restore`) puts the state back for the
/// host to push. Put after kScalarGlsl.
inline constexpr const char* kPushPassGlsl = R"GLSL(
layout(local_size_x = 256) in;

layout(std430, binding = 0) buffer Position { RAW position[]; };  // x, y, z arrays of `count`
layout(std430, binding = 1) buffer Velocity { RAW velocity[]; };
layout(std430, binding = 2) readonly buffer Anchor { RAW anchor[]; };
#if TRAMPLE
layout(std430, binding = 3) buffer Trample { RAW trampleLevel[]; };
#endif
layout(std430, binding = 4) buffer Fault { uint faultKey; };
layout(std430, binding = 5) readonly buffer Candidates { uint candidate[]; };  // particle indices
layout(std430, binding = 6) buffer Backup { RAW backup[]; };  // 7 per candidate: position, velocity, trample

uniform uint countX;
uniform uint count;       // particles
uniform uint candidates;  // entries of `candidate`
uniform uint restore;     // 1: write the backup back (a faulted tick), nothing else
// The particle under way: position, velocity, anchor, trample level.
RAW px, py, pz, pu, pv, pw, pax, pay, paz, ptrample;

// [0]: pushAllowance, [1]: rod length (held tips); then per part 17 values: centre (3), rotation
// row by row (9), half extents (3; a sphere's radius first), share, candidate reach.
layout(std430, binding = 7) readonly buffer PushValues { RAW pushValue[]; };
// Per part 4 values: shape (0 sphere, 1 box), body, storage column of its range's first column,
// columns in the range; then per storage row r, [4 parts + r] and [4 parts + r + 1] bound that
// row's part list in this array.
layout(std430, binding = 8) readonly buffer PushInts { int pushInt[]; };
layout(std430, binding = 9) buffer PushCounts { uint pushCount[]; };  // per body (grass drag)
uniform uint pushParts;  // parts pushing this tick (> 0)
uniform uint pushFlags;  // 1 nearest-face box normal (else up), 2 held tips, 4 grid ranges, 8 count pushes


RAW partValue(int part, int k) { return pushValue[2 + 17 * part + k]; }

#if FLOAT
RAW absS(RAW a) { return abs(a); }
RAW sqrtS(RAW a) { return sqrt(a); }
bool length3AtLeast(RAW x, RAW y, RAW z, RAW r) { return length3(x, y, z) >= r; }
RAW sum3(RAW a, RAW b, RAW c) { precise RAW bc = b + c; precise RAW r = a + bc; return r; }
bool movedAtLeast(RAW now, RAW start, RAW limit) { precise RAW d = now - start; return !(abs(d) < limit); }
#else
RAW absS(RAW a) { return a < RAW(0) ? subChecked(RAW(0), a) : a; }  // Fixed's abs: -min overflows
// One row of an Eigen 3 x 3 product: a + (b + c) as Eigen's unrolled sum, the overflow of the other grouping raised
// too (a false alarm at worst, which only sends the tick to the CPU).
RAW sum3(RAW a, RAW b, RAW c) { addChecked(addChecked(a, b), c); return addChecked(a, addChecked(b, c)); }
// movedAtLeast: |now - start| >= limit, a difference that leaves the format counting as moved.
bool movedAtLeast(RAW now, RAW start, RAW limit) {
  RAW d = now - start;
  if (((now ^ start) & (now ^ d)) < RAW(0) || limit <= RAW(0)) return true;
  uint64_t m = d < RAW(0) ? uint64_t(-int64_t(d)) : uint64_t(int64_t(d));
  return m >= uint64_t(int64_t(limit));
}
#if FX32
// sqrt: isqrtNearest(raw 2^32), a domain fault for a negative value.
RAW sqrtS(RAW a) {
  if (a < 0l) { overflowed = true; return 0l; }
  uint64_t nh = uint64_t(a) >> 32, nl = uint64_t(a) << 32;
  uint64_t r = isqrtFloor128(nh, nl);
  uint64_t sh, sl, eh, el;
  mul64x64(r, r, sh, sl);
  difference128(nh, nl, sh, sl, eh, el);
  if (eh != 0ul || el > r) r += 1ul;
  return RAW(r);
}
// length3(x, y, z) >= r without the root: the exact sum of squares against r^2 - r + 1 (r > 0).
bool length3AtLeast(RAW x, RAW y, RAW z, RAW r) {
  uint64_t h, l;
  sumOfSquares(x, y, z, h, l);
  uint64_t radius = uint64_t(r), qh, ql;
  mul64x64(radius, radius, qh, ql);
  if (radius == 0ul) return h != 0ul || l != 0ul;  // r^2 - r + 1 = 1
  uint64_t d = radius - 1ul;  // r^2 - (r - 1) >= 1: no borrow out of the high word
  uint64_t th = qh - (ql < d ? 1ul : 0ul), tl = ql - d;
  return lessOrEqual128(th, tl, h, l);
}
#else
RAW sqrtS(RAW a) {
  if (a < 0) { overflowed = true; return 0; }
  uint64_t n = uint64_t(a) << 16;
  uint64_t r = isqrtFloor128(0ul, n);
  if (n - r * r > r) r += 1ul;
  return RAW(uint(r));
}
bool length3AtLeast(RAW x, RAW y, RAW z, RAW r) {
  uint64_t mx = uint64_t(abs(int64_t(x))), my = uint64_t(abs(int64_t(y))), mz = uint64_t(abs(int64_t(z)));
  uint64_t radius = uint64_t(r);
  return mx * mx + my * my + mz * mz >= radius * radius - radius + 1ul;
}
#endif
#endif

// pose.rotation * v, and its transpose times v (Pose::toLocal), row by row as Eigen sums them.
void rotate(int part, RAW v[3], out RAW r[3]) {
  for (int i = 0; i < 3; ++i)
    r[i] = sum3(mulChecked(partValue(part, 3 + 3 * i), v[0]), mulChecked(partValue(part, 4 + 3 * i), v[1]),
                mulChecked(partValue(part, 5 + 3 * i), v[2]));
}
void rotateBack(int part, RAW v[3], out RAW r[3]) {
  for (int i = 0; i < 3; ++i)
    r[i] = sum3(mulChecked(partValue(part, 3 + i), v[0]), mulChecked(partValue(part, 6 + i), v[1]),
                mulChecked(partValue(part, 9 + i), v[2]));
}

// contact.h's nearestFaceAxis: the lowest axis wins ties.
int nearestFaceAxis(RAW local[3], RAW h[3], out RAW gap, out RAW side) {
  int axis = 0;
  gap = subChecked(h[0], absS(local[0]));
  for (int k = 1; k < 3; ++k) {
    RAW g = subChecked(h[k], absS(local[k]));
    if (g < gap) { gap = g; axis = k; }
  }
  side = local[axis] < RAW(0) ? RAW(-ONE) : RAW(ONE);
  return axis;
}

// reachableFaceAxis: the nearest face the blade can reach out through (exit within `reach` of its root).
int reachableFaceAxis(int part, RAW local[3], RAW h[3], RAW share, RAW reach, out RAW gap, out RAW side) {
  int axis = nearestFaceAxis(local, h, gap, side);
  bool found = false;
  RAW reachSquared = mulChecked(reach, reach);
  for (int k = 0; k < 3; ++k)
    for (int s = 0; s < 2; ++s) {
      RAW sign = s == 0 ? RAW(-ONE) : RAW(ONE);
      RAW g = subChecked(h[k], mulChecked(sign, local[k]));
      if (found && g >= gap) continue;
      RAW amount = mulChecked(g, share);
      RAW moved[3], e[3];
      for (int a = 0; a < 3; ++a) moved[a] = addChecked(local[a], mulChecked(a == k ? sign : RAW(0), amount));
      rotate(part, moved, e);
      RAW ex = subChecked(addChecked(partValue(part, 0), e[0]), pax);
      RAW ey = subChecked(addChecked(partValue(part, 1), e[1]), pay);
      RAW ez = subChecked(addChecked(partValue(part, 2), e[2]), paz);
      RAW d2 = addChecked(addChecked(mulChecked(ex, ex), mulChecked(ey, ey)), mulChecked(ez, ez));
      if (d2 > reachSquared) continue;
      found = true;
      axis = k;
      gap = g;
      side = sign;
    }
  return axis;
}

// pushOut: whether the particle was inside the part (then it is moved out).
bool pushOut(int part, RAW reach) {
  RAW share = partValue(part, 15);
  RAW d[3] = RAW[3](subChecked(px, partValue(part, 0)), subChecked(py, partValue(part, 1)),
                    subChecked(pz, partValue(part, 2)));
  if (pushInt[4 * part] == 0) {  // sphere: out along the normal from the centre
    RAW radius = partValue(part, 12);
    if (length3AtLeast(d[0], d[1], d[2], radius)) return false;
    RAW dist = length3(d[0], d[1], d[2]);
    RAW nx = RAW(0), ny = RAW(ONE), nz = RAW(0);
    if (dist != RAW(0)) { nx = divChecked(d[0], dist); ny = divChecked(d[1], dist); nz = divChecked(d[2], dist); }
    RAW amount = mulChecked(subChecked(radius, dist), share);
    px = addChecked(px, mulChecked(nx, amount));
    py = addChecked(py, mulChecked(ny, amount));
    pz = addChecked(pz, mulChecked(nz, amount));
    return true;
  }
  RAW local[3];
  rotateBack(part, d, local);
  RAW h[3] = RAW[3](partValue(part, 12), partValue(part, 13), partValue(part, 14));
  if (absS(local[0]) >= h[0] || absS(local[1]) >= h[1] || absS(local[2]) >= h[2]) return false;
  bool nearestFace = (pushFlags & 1u) != 0u;
  RAW gap, side;
  int axis = reach > RAW(0) && nearestFace ? reachableFaceAxis(part, local, h, share, reach, gap, side)
                                           : nearestFaceAxis(local, h, gap, side);
  RAW amount = mulChecked(gap, share);
  if (!nearestFace) {  // "up": pressed down, by the smallest face gap
    py = subChecked(py, amount);
    return true;
  }
  RAW face[3] = RAW[3](RAW(0), RAW(0), RAW(0)), n[3];
  face[axis] = side;
  rotate(part, face, n);
  px = addChecked(px, mulChecked(n[0], amount));
  py = addChecked(py, mulChecked(n[1], amount));
  pz = addChecked(pz, mulChecked(n[2], amount));
  return true;
}

// Held tips (holdTip and its two cases, body_particles.cpp).
void bendUnderVerticalPush(RAW centreX, RAW centreZ, RAW rod) {
  RAW height = subChecked(py, pay);
  height = height < RAW(0) ? RAW(0) : (rod < height ? rod : height);  // std::clamp
  RAW leanX = subChecked(px, pax), leanZ = subChecked(pz, paz);
  RAW lean = length3(leanX, RAW(0), leanZ);
  if (lean == RAW(0)) {
    leanX = subChecked(pax, centreX);
    leanZ = subChecked(paz, centreZ);
    lean = length3(leanX, RAW(0), leanZ);
  }
  if (lean == RAW(0)) {
    leanX = RAW(ONE);
    leanZ = RAW(0);
    lean = RAW(ONE);
  }
  RAW reach = divChecked(sqrtS(subChecked(mulChecked(rod, rod), mulChecked(height, height))), lean);
  px = addChecked(pax, mulChecked(leanX, reach));
  py = addChecked(pay, height);
  pz = addChecked(paz, mulChecked(leanZ, reach));
}
void backToTheRod(RAW rod) {
  RAW ex = subChecked(px, pax), ey = py > pay ? subChecked(py, pay) : RAW(0), ez = subChecked(pz, paz);
  RAW len = length3(ex, ey, ez);
  if (len == RAW(0)) return;
  RAW scale = divChecked(rod, len);
  px = addChecked(pax, mulChecked(ex, scale));
  py = addChecked(pay, mulChecked(ey, scale));
  pz = addChecked(paz, mulChecked(ez, scale));
}
void holdTip(RAW bx, RAW by, RAW bz, RAW centreX, RAW centreZ, RAW rod) {
#if TRAMPLE
  ptrample = RAW(ONE);
#endif
  if (px == bx && pz == bz) bendUnderVerticalPush(centreX, centreZ, rod);
  else backToTheRod(rod);
  RAW dx = subChecked(px, bx), dy = subChecked(py, by), dz = subChecked(pz, bz);
  RAW length = length3(dx, dy, dz);
  if (length == RAW(0)) {  // pinned: held still
    pu = RAW(0);
    pv = RAW(0);
    pw = RAW(0);
    return;
  }
  RAW nx = divChecked(dx, length), ny = divChecked(dy, length), nz = divChecked(dz, length);
  RAW into = addChecked(addChecked(mulChecked(pu, nx), mulChecked(pv, ny)), mulChecked(pw, nz));
  if (into >= RAW(0)) return;
  pu = subChecked(pu, mulChecked(nx, into));
  pv = subChecked(pv, mulChecked(ny, into));
  pw = subChecked(pw, mulChecked(nz, into));
}

bool withinReach(int part) {
  RAW reach = partValue(part, 16);
  return !(absS(subChecked(py, partValue(part, 1))) >= reach || absS(subChecked(px, partValue(part, 0))) >= reach ||
           absS(subChecked(pz, partValue(part, 2))) >= reach);
}

// pushInside: one part's push and what follows it; false where the stage must stop.
bool pushInside(int part) {
  bool hold = (pushFlags & 2u) != 0u;
  RAW rod = pushValue[1];
  RAW bx = px, by = py, bz = pz;
  if (!pushOut(part, hold ? rod : RAW(0))) return true;
  if ((pushFlags & 8u) != 0u) atomicAdd(pushCount[pushInt[4 * part + 1]], 1u);
  if (hold) holdTip(bx, by, bz, partValue(part, 0), partValue(part, 2), rod);
  checkInRange(px, py, pz, pu, pv, pw);
  return !overflowed;
}

// Every part over the particle's row, in order (pushParticlesOutOfBodies for one particle).
void pushParticle(uint row, uint column) {
  bool ranged = (pushFlags & 4u) != 0u;
  RAW allowance = pushValue[0];
  RAW startX = px, startZ = pz;
  bool movedYet = false;
  int lists = 4 * int(pushParts);
  int end = pushInt[lists + int(row) + 1];
  for (int e = pushInt[lists + int(row)]; e < end; ++e) {
    int part = pushInt[e];
    int offset = int(column) - pushInt[4 * part + 2];
    if (offset < 0) offset += int(countX);
    if (offset >= pushInt[4 * part + 3] || !withinReach(part)) continue;
    RAW x = px, z = pz;
    if (!pushInside(part)) return;
    if (!ranged || (px == x && pz == z)) continue;
    if (!movedYet) {  // its first push this tick: where it started
      movedYet = true;
      startX = x;
      startZ = z;
    }
    if (!movedAtLeast(px, startX, allowance) && !movedAtLeast(pz, startZ, allowance)) continue;
    // Carried beyond the ranges' allowance: every later part in order, as brute force meets
    // them; the row's later parts then pass it by.
    for (int later = part + 1; later < int(pushParts); ++later)
      if (withinReach(later) && !pushInside(later)) return;
    return;
  }
}



void main() {
  uint k = gl_GlobalInvocationID.x;
  if (k >= candidates) return;
  uint i = candidate[k], j = i + count, l = j + count;
  uint b = 7u * k;
  if (restore != 0u) {
    position[i] = backup[b]; position[j] = backup[b + 1u]; position[l] = backup[b + 2u];
    velocity[i] = backup[b + 3u]; velocity[j] = backup[b + 4u]; velocity[l] = backup[b + 5u];
#if TRAMPLE
    trampleLevel[i] = backup[b + 6u];
#endif
    return;
  }
  px = position[i]; py = position[j]; pz = position[l];
  pu = velocity[i]; pv = velocity[j]; pw = velocity[l];
  pax = anchor[i]; pay = anchor[j]; paz = anchor[l];
  ptrample = RAW(0);
#if TRAMPLE
  ptrample = trampleLevel[i];
#endif
  backup[b] = px; backup[b + 1u] = py; backup[b + 2u] = pz;
  backup[b + 3u] = pu; backup[b + 4u] = pv; backup[b + 5u] = pw;
  backup[b + 6u] = ptrample;
  overflowed = false;
  uint row = i / countX;
  pushParticle(row, i - row * countX);
  if (overflowed) atomicMin(faultKey, 0u);
  position[i] = px; position[j] = py; position[l] = pz;
  velocity[i] = pu; velocity[j] = pv; velocity[l] = pw;
#if TRAMPLE
  trampleLevel[i] = ptrample;
#endif
}
)GLSL";

/// The patch stage (sim/patches/patch_state.h) as a compute shader, one invocation per patch slot:
/// the tip displacement interpolated from the particles around the patch (along z between two
/// particle rows, then along x, weights t/k: updatePatchRow's order), then PatchWriter's tip
/// offset, top and tilt. Patch-stage data is never checked, so every operation wraps as Fixed's
/// operators return it. Besides the exact values, a float copy for a renderer in the same
/// context (ParticleDevice::patchDrawBuffer). Put after kScalarGlsl.
inline constexpr const char* kPatchPassGlsl = R"GLSL(
layout(local_size_x = 256) in;

// The last particle pass's tip displacement: x, y and z arrays of particleCount values.
layout(std430, binding = 0) readonly buffer Displacement { RAW displacement[]; };
// [0..6]: half rod, scaleY, cut reduction, minimum top, drop[0..2] (PatchStateConstants); then
// weight[t] = t / k for t = 0..k-1.
layout(std430, binding = 1) readonly buffer PatchConstants { RAW patchConstants[]; };
layout(std430, binding = 2) readonly buffer RootY { RAW rootY[]; };     // per patch slot
layout(std430, binding = 3) readonly buffer Cut { uint cutFlags[]; };   // per patch slot: 1 mown
// Tip offset x, tip offset z, top y, tilt level: four arrays of patchCount values.
layout(std430, binding = 4) writeonly buffer PatchOut { RAW patchOut[]; };
layout(std430, binding = 5) writeonly buffer PatchDraw { vec4 patchDraw[]; };
// The particles' trample levels (model blade with trampling; read only where `tramples`).
layout(std430, binding = 6) readonly buffer Trample { RAW trampleLevel[]; };

uniform int k;
uniform ivec4 particleWindow;        // originI, originJ, sizeI, sizeJ (lattice_window.h)
uniform ivec4 patchWindow;
uniform ivec2 patchStorageOrigin;    // storage column of patchWindow's originI, storage row of originJ
uniform uint patchCount;
uniform uint particleCount;
uniform bool tramples;

#if FLOAT
RAW blend(RAW a, RAW b, RAW w) { precise RAW d = b - a; precise RAW p = d * w; precise RAW r = a + p; return r; }
float toMetres(RAW v) { return v; }
#else
// Fixed's lerp, a + (b - a) w: the product rounded as Fixed's (mulChecked's bits; its fault is
// ignored), the sums wrapping.
RAW blend(RAW a, RAW b, RAW w) { return a + mulChecked(b - a, w); }
// As the scene extraction converts (double(raw) / 2^frac, then rounded to float).
float toMetres(RAW v) { return float(double(v) / double(ONE)); }
#endif

void main() {
  uint p = gl_GlobalInvocationID.x;
  if (p >= patchCount) return;
  // The patch's lattice coordinates (LatticeWindow::latticeColumn / latticeRow; all >= 0).
  int slotRow = int(p) / patchWindow.z, slotColumn = int(p) - slotRow * patchWindow.z;
  int i = patchWindow.x + (slotColumn - patchStorageOrigin.x + patchWindow.z) % patchWindow.z;
  int j = patchWindow.y + (slotRow - patchStorageOrigin.y + patchWindow.w) % patchWindow.w;
  // The particles around it: columns a0 and a0 + 1, rows b0 and b0 + 1, in storage order.
  int a0 = i / k, tx = i - a0 * k, b0 = j / k, tz = j - b0 * k;
  int nx = particleWindow.z;
  int r0 = (b0 % particleWindow.w) * nx, r1 = ((b0 + 1) % particleWindow.w) * nx;
  int sa = a0 % nx, sb = sa + 1 == nx ? 0 : sa + 1;
  RAW d[3];
  for (int axis = 0; axis < 3; ++axis) {
    int base = axis * int(particleCount);
    RAW va = displacement[base + r0 + sa];
    if (tz != 0) va = blend(va, displacement[base + r1 + sa], patchConstants[7 + tz]);
    if (tx != 0) {
      RAW vb = displacement[base + r0 + sb];
      if (tz != 0) vb = blend(vb, displacement[base + r1 + sb], patchConstants[7 + tz]);
      va = blend(va, vb, patchConstants[7 + tx]);
    }
    d[axis] = va;
  }
  // PatchWriter: the tuft gets shorter as the tip sinks (never below the minimum top), and
  // darker in tilt steps.
  RAW halfRod = patchConstants[0], scaleY = patchConstants[1], cutReduction = patchConstants[2];
  RAW minimumTop = patchConstants[3];
  bool cut = cutFlags[p] != 0u;
#if FLOAT
  precise RAW sink = RAW(0) - d[1];
#else
  RAW sink = RAW(0) - d[1];
#endif
  RAW smaller = sink < RAW(0) ? RAW(0) : (sink > halfRod ? halfRod : sink);
#if FLOAT
  precise RAW shorter = scaleY - smaller;
  precise RAW top = shorter - (cut ? cutReduction : RAW(0));
  precise RAW topY = rootY[p] + (top < minimumTop ? minimumTop : top);
#else
  RAW top = scaleY - smaller - (cut ? cutReduction : RAW(0));
  RAW topY = rootY[p] + (top < minimumTop ? minimumTop : top);
#endif
  uint tilt = sink > patchConstants[6] ? 3u : sink > patchConstants[5] ? 2u : sink > patchConstants[4] ? 1u : 0u;
  patchOut[p] = d[0];
  patchOut[patchCount + p] = d[2];
  patchOut[2u * patchCount + p] = topY;
  patchOut[3u * patchCount + p] = RAW(tilt);
  // The trample level of the particle the patch takes its motion from (its lower-left one), as
  // the scene extraction shows it: lround(255 clamp(level, 0, 1)), added as 4 x that to the
  // brightness level (both exact in a float).
  uint trampled = 0u;
  if (tramples) {
    double level = clamp(double(trampleLevel[r0 + sa]) / double(ONE), 0.0lf, 1.0lf) * 255.0lf;
    double whole = floor(level);
    trampled = uint(whole) + (level - whole >= 0.5lf ? 1u : 0u);
  }
  patchDraw[p] = vec4(toMetres(topY), toMetres(d[0]), toMetres(d[2]), float((cut ? 3u : tilt) + 4u * trampled));
}
)GLSL";

}  // namespace sg::gpu
