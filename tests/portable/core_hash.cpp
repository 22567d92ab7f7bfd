// Minimal driver for the deterministic core alone (sim/, no replay/ or viewer/): builds a
// scenario, runs it with its scripted inputs and prints the state hash. Used by
// .ci/i686-core-hashes to prove that a build without __int128 (i686, or x86-64 with
// -DSIMGRASS_PORTABLE_INT128) reaches the committed x86-64 goldens bit for bit.
//
//   core_hash [--scalar fx32|fx16|float|double] [--ticks N] [--scalar-kernel] [scenario.json]
//
// Without a file it runs the built-in thesis meadow. --scalar-kernel runs the particle pass with
// the scalar reference instead of AVX2 (where the CPU has it), so that on x86-64 all of it goes
// through Fixed's 128-bit arithmetic. Prints the hash as %016llx.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "sim/scenario/scenario.h"
#include "sim/world/tick_input.h"
#include "sim/world/world.h"

// The core reads PNG heightmaps with libspng: linked by .ci/i686-core-hashes (the host's, or the
// static i686 build that .ci/cross-check makes).

namespace {
bool readBytes(const std::string& path, std::vector<uint8_t>* bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  bytes->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return true;
}
}  // namespace

int main(int argc, char** argv) {
  std::string scalar, file;
  long long ticks = 600;
  bool scalarKernel = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--scalar") && i + 1 < argc) {
      scalar = argv[++i];
    } else if (!std::strcmp(argv[i], "--ticks") && i + 1 < argc) {
      ticks = std::atoll(argv[++i]);
    } else if (!std::strcmp(argv[i], "--scalar-kernel")) {
      scalarKernel = true;
    } else if (argv[i][0] == '-') {
      std::fprintf(
          stderr, "usage: core_hash [--scalar fx32|fx16|float|double] [--ticks N] [--scalar-kernel] [scenario.json]\n");
      return 2;
    } else {
      file = argv[i];
    }
  }
  try {
    std::string text = sg::defaultScenarioText(), name = "<built-in>", dir = ".";
    if (!file.empty()) {
      std::vector<uint8_t> bytes;
      if (!readBytes(file, &bytes)) {
        std::fprintf(stderr, "core_hash: cannot read %s\n", file.c_str());
        return 2;
      }
      text.assign(bytes.begin(), bytes.end());
      name = file;
      const size_t slash = file.find_last_of('/');
      dir = slash == std::string::npos ? "." : file.substr(0, slash);
    }
    // Files a scenario names (its heightmap) are relative to the scenario.
    const sg::ScenarioFileReader reader = [&dir](const std::string& path, std::vector<uint8_t>* bytes,
                                                 std::string* error) {
      if (readBytes(dir + "/" + path, bytes)) return true;
      *error = "file '" + path + "' not found";
      return false;
    };
    sg::Scenario scenario = sg::parseScenario(text, name, reader);
    if (!scalar.empty()) {
      const auto kind = sg::parseScalarKind(scalar);
      if (!kind) {
        std::fprintf(stderr, "core_hash: unknown scalar %s\n", scalar.c_str());
        return 2;
      }
      scenario.scalar = *kind;
    }
    auto world = sg::makeWorld(scenario);
    if (scalarKernel) world->setParticleKernel(sg::ParticleKernel::Scalar);
    for (long long t = 0; t < ticks; ++t) {
      const sg::StepResult r = world->step(sg::scriptedInput(scenario, world->tick()));
      if (!r.ok) {
        std::fprintf(stderr, "core_hash: the step failed at tick %lld\n", t);
        return 1;
      }
    }
    std::printf("%016llx\n", (unsigned long long)world->stateHash());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "core_hash: %s\n", e.what());
    return 2;
  }
  return 0;
}
