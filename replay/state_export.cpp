#include "replay/state_export.h"

namespace sg {

nlohmann::json stateExportJson(const StateExport& s) {
  using nlohmann::json;
  json bodies = json::array();
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    const StateExport::Body& b = s.bodies[i];
    bodies.push_back({{"index", i},
                      {"template", b.templateBody},
                      {"position", b.position},
                      {"orientation", b.orientation},
                      {"velocity", b.velocity},
                      {"angularVelocity", b.angularVelocity},
                      {"asleep", b.asleep},
                      {"bladeOn", b.bladeOn}});
  }
  json cuts = json::array();
  for (const auto& c : s.cuts) cuts.push_back({c[0], c[1]});
  return json{{"format", "simgrass-state/2"},
              {"scalar", scalarName(s.scalar)},
              {"tick", s.tick},
              {"interpolation", s.interpolation},
              {"field", {{"patchesX", s.fieldPatchesX}, {"patchesZ", s.fieldPatchesZ}}},
              {"particles",
               {{"originI", s.particleOriginI},
                {"originJ", s.particleOriginJ},
                {"countX", s.particlesX},
                {"countZ", s.particlesZ},
                {"position", s.particlePosition},
                {"velocity", s.particleVelocity}}},
              {"patches",
               {{"originI", s.patchOriginI},
                {"originJ", s.patchOriginJ},
                {"countX", s.patchesX},
                {"countZ", s.patchesZ},
                {"tipOffset", s.tipOffset}}},
              {"bodies", bodies},
              {"cuts", cuts}};
}

}  // namespace sg
