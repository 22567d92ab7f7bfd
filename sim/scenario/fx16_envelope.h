// fx16's impact envelope, checked at load (docs/fixed-point.md, "fx16's rigid-body envelope").
//
// Q16.16 holds at most 32,767, so every contact row's accumulated impulse (N s) and every row's
// inverse effective mass (1/kg) must stay below it for the whole run. Both are bounded at load
// from the scenario alone:
//
//   impulse of a row   <= mu x ((1 + e) x closing speed + 3 m/s push-out) x max(1, friction)
//                         mu = m (terrain), m_a m_b / (m_a + m_b) (a pair)
//   closing speed      <= s_a + s_b (terrain: s_a)
//   s                  =  min(sqrt(2 E / m), w + 2 w_fastest other) + |g| dt
//   E                  =  sum over bodies of m w^2 / 2, the most energy the scene can hold
//   w                  =  sqrt(|v0|^2 + I_max |w0|^2 / m + 2 g_down drop) + the script's velocity
//                         changes + its drag spring
//   drop               =  the highest its centre of mass starts or is put (script: displacements,
//                         teleports, spawns, spawns of spawns) above the lowest ground, less the
//                         height a lone sphere or box keeps its centre up
//   1/(effective mass) <= 1/m + R^2 / I_min per body (R its bounding radius; 0 for a sphere's
//                         angular part), summed over a pair
//
// A row's effective mass is at most the pair's reduced mass mu (its angular terms only lower it;
// a box landing on a corner along its diagonal meets exactly mu), a row stops at most the pair's
// closing motion, restitution returns e of it and friction holds up to mu of it. All the energy
// may reach one body (a heavy body passes its speed on to a light one); the strike term keeps a
// feather beside a fast heavy ball loadable and is not a proof (a chain of ever lighter bodies
// doubles a speed at each strike). What the bound cannot see: gravity off the vertical over
// unbounded flat ground, a body travelling beyond the +-32,767 m fx16 holds, commands from an
// input track or the viewer, a script's velocity change on a body others have sped up, bodies
// started inside the terrain, heavy long bodies rocking on a heightmap, and a spin near the cap
// with many sub-steps. These still stop the tick with the overflow error in stage `response`
// (never a silently wrong run); docs/fixed-point.md lists them with the scenes that showed them.
#pragma once

#include "sim/scenario/scenario.h"

namespace sg {

/// Throws ScenarioError naming the body (its JSON path) whose impacts or effective mass may not
/// fit fx16. Call for fx16 worlds only, after the per-body checks (mass properties in range).
void checkFx16ImpactEnvelope(const Scenario& scenario);

}  // namespace sg
