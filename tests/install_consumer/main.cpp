// Builds the default meadow from the installed library, runs 10 ticks, prints the state hash.
#include <cstdio>

#include "sim/world/world.h"

int main() {
  sg::Scenario s = sg::parseScenario(sg::defaultScenarioText(), "<built-in>", {});
  auto world = sg::makeWorld(s, 1);
  for (int t = 0; t < 10; ++t)
    if (!world->step(sg::TickInput{}).ok) return 1;
  std::printf("tick %lld hash %016llx\n", (long long)world->tick(), (unsigned long long)world->stateHash());
  return 0;
}
