// How far two runs of the same meadow are apart: per-tick tuft-tip and body-pose errors (what
// `simgrass diff` and `simgrass compare` report) and a PNG heat map of the tip error.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/world/world.h"

namespace sg {

/// The divergence between two observations of the same field at one common time.
struct TickDivergence {
  int64_t tick = 0;                      ///< in the reference's (A's, the recording's) time base
  double tipMax = 0;                     ///< m: largest distance between corresponding tuft tips
  double tipRms = 0;                     ///< m: root mean square of that distance over all patches
  double bodyPosMax = 0;                 ///< m: largest distance between corresponding body centres
  double bodyAngleMax = 0;               ///< rad: largest angle of the relative rotation of a body (0 … pi)
  int64_t contactsA = 0, contactsB = 0;  ///< body contacts found in the tick that led here
  /// Bodies in each run (spawn commands add bodies mid-run): the pose errors cover the bodies
  /// both runs have (the same indices); a body only one run has counts as a difference.
  int64_t bodiesA = 0, bodiesB = 0;
  bool identical = false;  ///< the two state hashes are equal

  /// Anything measured differs (tips, body poses, body or contact counts).
  bool observedDifference() const {
    return tipMax > 0 || bodyPosMax > 0 || bodyAngleMax > 0 || contactsA != contactsB || bodiesA != bodiesB;
  }
};

/// Divergence over a run: the largest per-tick errors and the first ticks things differ.
struct DivergenceSummary {
  int64_t ticks = 0;               ///< ticks measured
  double tipMax = 0;               ///< m: largest TickDivergence::tipMax (NaN if any was)
  int64_t tipMaxTick = -1;         ///< first tick with that value
  double tipSumSquares = 0;        ///< sum over ticks of tipRms^2 (all ticks have the same patches)
  double bodyPosMax = 0;           ///< m
  double bodyAngleMax = 0;         ///< rad
  int64_t contactDeltaMax = 0;     ///< largest |contactsA - contactsB|
  int64_t firstObservedTick = -1;  ///< first tick whose tips, body poses or contact counts differ
  int64_t firstHashTick = -1;      ///< first tick whose state hashes differ

  void add(const TickDivergence& d);
  /// m: root mean square tip distance over all patches and all ticks measured.
  double tipRms() const;
};

/// Empty when `a` and `b` observe fields of the same size (with any number of bodies each: a
/// run may have spawned bodies the other has not), else what differs ("151 x 151 patches, 1
/// bodies vs 31 x 31 patches, 1 bodies").
std::string observationMismatch(const Observation& a, const Observation& b);

/// Measures a against b. Throws std::invalid_argument (observationMismatch's text) when they
/// are not observations of comparable worlds. `tick` is taken from a.
TickDivergence measureDivergence(const Observation& a, const Observation& b, bool hashesEqual);

/// Angle of the rotation that takes unit quaternion qa to qb (w, x, y, z each), in [0, pi]:
/// 2 atan2(|vec(qa* qb)|, |w(qa* qb)|), accurate near 0 where 2 acos(|dot|) is not, and blind to
/// the sign (q and -q are the same rotation) and to the quaternions' length.
double relativeRotationAngle(const double* qa, const double* qb);

/// Per-patch tip distance |tip_a - tip_b| (m), row-major like the observations.
std::vector<double> tipDistances(const Observation& a, const Observation& b);

/// Writes a heat map of the tip distance between a and b: the field seen from above (x to the
/// right, z downwards), each patch a square of a few pixels (the image at least ~512 px wide;
/// fields wider than 2048 patches show the largest distance of each block), coloured on a
/// viridis ramp from 0 (dark blue) to the largest distance (yellow), with a legend bar below.
/// An all-zero divergence is a uniform dark image. Returns false with `error` set ("path: why")
/// when the observations do not match or the file cannot be written.
bool writeDivergencePng(const std::string& path, const Observation& a, const Observation& b, std::string* error);

/// The colour ramp used by the heat map: t in [0, 1] (clamped) to 8-bit RGB.
void divergenceColour(double t, uint8_t rgb[3]);

}  // namespace sg
