// The contact solver's islands (Box2D v3 and Jolt solve islands apart, Jolt on several threads):
// the awake bodies joined by this tick's body-body contacts, with their rows. Islands share no
// body, so the solver runs them one by one or on the pool's threads and gets the bits of one
// sequence over every row in canonical order (solveIsland). Built each tick from the sorted
// contacts: ascending root, body and row indices, so the partition depends on the contacts alone.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "sim/bodies/sleep_islands.h"

namespace sg {

struct SolverIslands {
  /// Island k: bodies[bodyStart[k] .. bodyStart[k + 1]) and rows[rowStart[k] .. rowStart[k + 1]),
  /// each ascending. Islands are in order of their lowest body.
  std::vector<int32_t> bodyStart{0}, bodies, rowStart{0}, rows;

  size_t count() const { return bodyStart.size() - 1; }
  std::span<const int32_t> bodiesOf(size_t k) const {
    return {bodies.data() + bodyStart[k], size_t(bodyStart[k + 1] - bodyStart[k])};
  }
  std::span<const int32_t> rowsOf(size_t k) const {
    return {rows.data() + rowStart[k], size_t(rowStart[k + 1] - rowStart[k])};
  }
};

/// The islands of the awake bodies under `contacts` (sorted, canonical: row i is contact i). A
/// sleeping body keeps no contacts and needs no sub-steps: it is in no island.
template <class S>
SolverIslands solverIslands(const std::vector<RigidBody<S>>& bodyList, const std::vector<Contact<S>>& contacts) {
  const size_t n = bodyList.size();
  const std::vector<int32_t> root = contactIslands(n, contacts);  // a root is its island's lowest body
  // Island number of each root, in ascending root order.
  std::vector<int32_t> islandOf(n, -1);
  SolverIslands out;
  int32_t islands = 0;
  // A root gets an island when an awake body or a row is under it (a row between sleeping bodies
  // is not made, but would still be solved, as in one sequence over all rows).
  std::vector<uint8_t> used(n, 0);
  for (size_t i = 0; i < n; ++i)
    if (!bodyList[i].asleep) used[size_t(root[i])] = 1;
  for (const Contact<S>& c : contacts) used[size_t(root[size_t(c.bodyA)])] = 1;
  for (size_t i = 0; i < n; ++i)
    if (used[i]) islandOf[i] = islands++;
  // Counting sorts: bodies, then rows, by island (stable: ascending within each).
  std::vector<int32_t> bodyCount(size_t(islands) + 1, 0), rowCount(size_t(islands) + 1, 0);
  for (size_t i = 0; i < n; ++i)
    if (!bodyList[i].asleep) ++bodyCount[size_t(islandOf[size_t(root[i])]) + 1];
  for (const Contact<S>& c : contacts) ++rowCount[size_t(islandOf[size_t(root[size_t(c.bodyA)])]) + 1];
  for (int32_t k = 0; k < islands; ++k) {
    bodyCount[size_t(k) + 1] += bodyCount[size_t(k)];
    rowCount[size_t(k) + 1] += rowCount[size_t(k)];
  }
  out.bodyStart = bodyCount;
  out.rowStart = rowCount;
  out.bodies.resize(size_t(bodyCount[size_t(islands)]));
  out.rows.resize(contacts.size());
  for (size_t i = 0; i < n; ++i)
    if (!bodyList[i].asleep) out.bodies[size_t(bodyCount[size_t(islandOf[size_t(root[i])])]++)] = int32_t(i);
  for (size_t r = 0; r < contacts.size(); ++r)
    out.rows[size_t(rowCount[size_t(islandOf[size_t(root[size_t(contacts[r].bodyA)])])]++)] = int32_t(r);
  return out;
}

}  // namespace sg
