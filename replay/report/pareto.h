// The Pareto front of a set of (cost, error) pairs: the variants no other variant beats on both.
#pragma once

#include <cstddef>
#include <vector>

namespace sg {

/// front[i] is true when no j dominates i, where j dominates i when cost[j] <= cost[i] and
/// error[j] <= error[i] with at least one of the two strictly smaller. Entries with a NaN or a
/// false in `eligible` (e.g. a run that faulted) are never on the front and dominate nothing.
/// O(n^2): sweeps have a few hundred rows.
std::vector<bool> paretoFront(const std::vector<double>& cost, const std::vector<double>& error,
                              const std::vector<bool>& eligible = {});

/// The indices of the front ordered by increasing cost (how it is drawn as a line).
std::vector<size_t> paretoOrder(const std::vector<double>& cost, const std::vector<bool>& front);

}  // namespace sg
