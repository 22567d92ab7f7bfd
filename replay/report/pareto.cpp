#include "replay/report/pareto.h"

#include <algorithm>
#include <cmath>

namespace sg {

std::vector<bool> paretoFront(const std::vector<double>& cost, const std::vector<double>& error,
                              const std::vector<bool>& eligible) {
  const size_t n = std::min(cost.size(), error.size());
  auto usable = [&](size_t i) {
    return (eligible.empty() || (i < eligible.size() && eligible[i])) && !std::isnan(cost[i]) && !std::isnan(error[i]);
  };
  std::vector<bool> front(n, false);
  for (size_t i = 0; i < n; ++i) {
    if (!usable(i)) continue;
    bool dominated = false;
    for (size_t j = 0; j < n && !dominated; ++j)
      dominated = j != i && usable(j) && cost[j] <= cost[i] && error[j] <= error[i] &&
                  (cost[j] < cost[i] || error[j] < error[i]);
    front[i] = !dominated;
  }
  return front;
}

std::vector<size_t> paretoOrder(const std::vector<double>& cost, const std::vector<bool>& front) {
  std::vector<size_t> order;
  for (size_t i = 0; i < front.size(); ++i)
    if (front[i]) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return cost[a] < cost[b]; });
  return order;
}

}  // namespace sg
