// The truth that grass models are measured against (issue 16, docs/grass-models.md "Model
// error"): one blade as a chain of N straight segments, in double, at a time step small enough
// that its own discretisation error is negligible beside any model's. Not part of the step (it
// uses libm and runs only in tools: the sweep's model error, tests).
//
// The blade: length L, mass m spread evenly over its N nodes (the root is clamped upright),
// gravity g = 9.81 m/s^2 down, bending energy (kappa/2) sum_j |t_j - t_(j-1)|^2 over the unit
// tangents of consecutive segments (t_0 = up: the clamp), and a drag alpha m_i v_i on every node.
// kappa is chosen so that the first bending mode, gravity included, sways at the scenario's blade
// frequency f; alpha = 2 zeta omega_1 so that this mode's damping ratio is the scenario's zeta
// (mode k's is zeta omega_1 / omega_k). Wind is a force per tuft (N), spread evenly over the
// nodes: drag on a uniform blade.
//
// Step (substep h): v = (v + h (gravity + wind/N + bending)/m_i) exp(-alpha h); x += h v; the
// segment lengths are restored by mass-weighted projection, root to tip, until within 1e-6 (at
// most 64 sweeps); nodes are kept above the root's height; where a length still does not hold
// to 1e-3 (forces per unit mass far beyond a scenario's) each node is put back at its length root to
// tip, so a tip is never farther than L (1 + 1e-3) from its root; v = (x - x_before)/h. h is chosen from
// the chain's highest linearised mode, h omega_max <= 0.05.
//
// A body (the model error with bodies): a sphere moved kinematically (it is not pushed back: the
// grass's push on a body is the share m_particle / (m + m_particle) of the models, ~0 for a heavy
// one). Each projection sweep also moves every node inside it out to its surface along the
// radius, so the contact is a position constraint like the lengths: its velocity (the body stops
// the node, or carries it along) comes from v = (x - x_before)/h.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace sg {

/// A sphere moving in a straight line over one advance(): its centre goes from `from` to `to`
/// (m, relative to the root) at a uniform speed.
struct ReferenceBall {
  std::array<double, 3> from{0, 0, 0}, to{0, 0, 0};
  double radius = 0;  ///< m
};

struct ReferenceBladeParams {
  double length = 1;          ///< m
  double mass = 1;            ///< kg, the whole blade
  double frequency = 0.5;     ///< Hz: first bending mode, gravity included
  double dampingRatio = 0.3;  ///< of critical, first mode
  double gravity = 9.81;      ///< m/s^2, down
  int segments = 8;
};

class ReferenceBlade {
 public:
  /// Upright and at rest, root at the origin. Throws std::invalid_argument for parameters no
  /// blade has (a non-positive length, mass or frequency, a negative damping ratio, fewer than 2
  /// segments) or a frequency so low that the blade buckles under its own weight.
  explicit ReferenceBlade(const ReferenceBladeParams& p);

  /// Advances `seconds` (in whole substeps of at most substep()) under a total wind force
  /// (N, spread evenly over the nodes), against `ball` where given (its centre at each substep's
  /// end interpolated between from and to).
  void advance(double seconds, const std::array<double, 3>& windForce, const ReferenceBall* ball = nullptr);

  /// Puts the blade straight at `angle` (rad) from upright toward +x, at rest.
  void bendTo(double angle);

  std::array<double, 3> tip() const { return {x_.back(), y_.back(), z_.back()}; }
  double substep() const { return h_; }
  double bendingStiffness() const { return kappa_; }  ///< kappa, N m (per unit bend)
  double dragRate() const { return alpha_; }          ///< alpha, 1/s
  double highestMode() const { return omegaMax_; }    ///< rad/s, linearised

 private:
  void substepOnce(double h, const std::array<double, 3>& windForce, const std::array<double, 4>* ball);
  /// Moves the nodes inside the ball (centre, radius) out to its surface along its radius; returns
  /// the deepest a node was (0: none inside).
  double pushOutOf(const std::array<double, 4>& ball);

  int n_ = 0;
  double length_ = 0, segment_ = 0, nodeMass_ = 0, gravity_ = 0;
  double kappa_ = 0, alpha_ = 0, omegaMax_ = 0, h_ = 0;
  std::vector<double> x_, y_, z_, vx_, vy_, vz_;     ///< nodes 1..N (index 0 = node 1)
  std::vector<double> fx_, fy_, fz_, px_, py_, pz_;  ///< scratch: forces, positions before
  std::vector<std::array<double, 4>> tangent_;       ///< scratch: each segment's unit tangent and length
};

}  // namespace sg
