// A rectangular window onto a lattice (particles or patches), stored toroidally: lattice column i
// lives in storage column i mod sizeI, row j in storage row j mod sizeJ. Moving the window by one
// row overwrites exactly the storage row that leaves with the row that enters; nothing else
// moves (the thesis copied the whole field on every shift, docs/level-of-detail.md).
//
// Coordinates may lie outside [0, field) (the edge-grass ring reaches past the field's border;
// the simulation window never does). With the window covering the whole field (origin 0) storage
// order is plain row-major order: the level of detail off is the identity.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace sg {

struct LatticeWindow {
  int64_t originI = 0, originJ = 0;  ///< lattice coordinates of the first column and row
  int64_t sizeI = 0, sizeJ = 0;      ///< columns and rows held
  int64_t fieldI = 0, fieldJ = 0;    ///< columns and rows of the whole lattice

  int64_t size() const { return sizeI * sizeJ; }
  int64_t endI() const { return originI + sizeI; }  ///< one past the last column
  int64_t endJ() const { return originJ + sizeJ; }
  bool contains(int64_t i, int64_t j) const { return i >= originI && i < endI() && j >= originJ && j < endJ(); }
  bool coversField() const { return sizeI == fieldI && sizeJ == fieldJ; }

  int64_t storageColumn(int64_t i) const { return floorMod(i, sizeI); }
  int64_t storageRow(int64_t j) const { return floorMod(j, sizeJ); }
  bool insideField(int64_t i, int64_t j) const { return i >= 0 && i < fieldI && j >= 0 && j < fieldJ; }
  size_t storageIndex(int64_t i, int64_t j) const { return size_t(storageRow(j) * sizeI + storageColumn(i)); }
  /// The lattice row held in storage row r.
  int64_t latticeRow(int64_t r) const { return originJ + (r - storageRow(originJ) + sizeJ) % sizeJ; }
  /// The lattice column held in storage column c.
  int64_t latticeColumn(int64_t c) const { return originI + (c - storageColumn(originI) + sizeI) % sizeI; }

  static int64_t floorMod(int64_t a, int64_t n) {
    const int64_t m = a % n;
    return m < 0 ? m + n : m;
  }
};

/// Calls enter(i, j) for the cells of row `r` (0 .. now.sizeJ - 1, counted from now.originJ)
/// that `before` did not hold, or for all of them when `everything`: what enters a window when it
/// moves from `before` to `now`. Rows are independent, so callers may run them in parallel.
template <class Fn>
void forEachEnteringCell(const LatticeWindow& now, const LatticeWindow& before, bool everything, int64_t r,
                         Fn&& enter) {
  const int64_t j = now.originJ + r;
  const bool rowWasHeld = !everything && j >= before.originJ && j < before.endJ();
  if (!rowWasHeld) {
    for (int64_t i = now.originI; i < now.endI(); ++i) enter(i, j);
    return;
  }
  // A held row: only the columns left and right of what was held (no per-cell test, so a shift
  // costs what enters, not what is held).
  for (int64_t i = now.originI; i < std::min(now.endI(), before.originI); ++i) enter(i, j);
  for (int64_t i = std::max(now.originI, before.endI()); i < now.endI(); ++i) enter(i, j);
}

/// The cells forEachEnteringCell(now, before, false, ...) visits, as runs contiguous in storage:
/// span(first storage index, count), a row new to the window as one run, a held row's entering
/// columns as one or two (split where they wrap round the storage row).
template <class Fn>
void forEachEnteringSpan(const LatticeWindow& now, const LatticeWindow& before, Fn&& span) {
  for (int64_t j = now.originJ; j < now.endJ(); ++j) {
    const int64_t rowStart = now.storageRow(j) * now.sizeI;
    const auto columns = [&](int64_t i0, int64_t i1) {  // lattice columns [i0, i1), held by `now`
      while (i0 < i1) {
        const int64_t c = now.storageColumn(i0), n = std::min(i1 - i0, now.sizeI - c);
        span(rowStart + c, n);
        i0 += n;
      }
    };
    if (j < before.originJ || j >= before.endJ()) {
      columns(now.originI, now.endI());
      continue;
    }
    columns(now.originI, std::min(now.endI(), before.originI));
    columns(std::max(now.originI, before.endI()), now.endI());
  }
}

}  // namespace sg
