// fx16's impact envelope, checked at load (docs/fixed-point.md, "fx16's rigid-body envelope").
//
// Q16.16 holds at most 32,767, so every contact row's accumulated impulse (N s) and every row's
// inverse effective mass (1/kg) must stay below it for the whole run. Both are bounded at load
// from the scenario alone:
//
//   impulse of a row   <= (1 + e) x mu x (closing speed)     mu = m (terrain), m_a m_b / (m_a + m_b)
//   closing speed      <= s_a + s_b (terrain: s_a)
//   s                  =  sqrt(2 E / m) + 3 m/s (the soft push-out) + |g| dt (a tick of fall)
//   E                  =  sum over bodies of m w^2 / 2, the most energy the scene can hold
//   w                  =  sqrt(|v0|^2 + 2 g_down drop) + the script's velocity changes + its drag
//   drop               =  the highest the body starts or is put (script) above the lowest ground
//   1/(effective mass) <= 1/m + R^2 / I_min per body (R its bounding radius), summed over a pair
//
// A row's effective mass is at most the pair's reduced mass mu (its angular terms only lower it;
// a box landing on a corner along its diagonal meets exactly mu), and a row stops at most the
// pair's closing motion and bounces back e of it. All the energy may reach one body (a heavy
// body passes its speed on to a light one). What the bound cannot see: gravity off the vertical
// over unbounded flat ground (a body slides down the tilted pull for as long as the run lasts),
// a script's velocity change on a body that others have sped up, commands from an input track or
// the viewer, and bodies wedged between contacts that fight each other; these still stop the tick
// with the overflow error in stage `response` (never a silently wrong run).
#pragma once

#include "sim/scenario/scenario.h"

namespace sg {

/// Throws ScenarioError naming the body (its JSON path) whose impacts or effective mass may not
/// fit fx16. Call for fx16 worlds only, after the per-body checks (mass properties in range).
void checkFx16ImpactEnvelope(const Scenario& scenario);

}  // namespace sg
