#include "replay/report/reference_blade.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sg {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// The chain linearised about upright, in the segments' small angles theta_1..theta_N from the
/// vertical (node i is ell * sum_(j <= i) theta_j to the side): mass matrix M, bending stiffness
/// per unit kappa (D^T D, D the first difference with theta_0 = 0) and gravity's (negative)
/// stiffness G (a node's weight lowers the potential as its segments lean).
struct Linearised {
  Eigen::MatrixXd mass, bending, gravity;
};

Linearised linearise(int n, double segment, double nodeMass, double g) {
  Linearised l{Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXd::Zero(n, n), Eigen::MatrixXd::Zero(n, n)};
  for (int j = 0; j < n; ++j) {
    for (int k = 0; k < n; ++k) l.mass(j, k) = segment * segment * nodeMass * double(n - std::max(j, k));
    l.bending(j, j) = j + 1 < n ? 2 : 1;  // D^T D of the differences theta_j - theta_(j-1)
    if (j + 1 < n) l.bending(j, j + 1) = l.bending(j + 1, j) = -1;
    l.gravity(j, j) = -g * segment * nodeMass * double(n - j);
  }
  return l;
}

/// omega^2 of every mode at bending stiffness kappa, ascending, with the mode shapes (M-normalised).
Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> modes(const Linearised& l, double kappa) {
  return Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>(kappa * l.bending + l.gravity, l.mass);
}

}  // namespace

ReferenceBlade::ReferenceBlade(const ReferenceBladeParams& p) {
  if (!(p.length > 0) || !(p.mass > 0) || !(p.frequency > 0) || !(p.dampingRatio >= 0) || !(p.gravity >= 0) ||
      p.segments < 2 || p.segments > 64)
    throw std::invalid_argument(
        "reference blade: expected a positive length, mass and frequency, a damping ratio >= 0 "
        "and 2 to 64 segments");
  n_ = p.segments;
  length_ = p.length;
  segment_ = p.length / n_;
  nodeMass_ = p.mass / n_;
  gravity_ = p.gravity;
  const Linearised lin = linearise(n_, segment_, nodeMass_, gravity_);
  // kappa: the first mode's omega^2 grows with kappa (from negative, buckled, at kappa = 0):
  // bracket it, then bisect to the last bit.
  const double omega1 = 2 * kPi * p.frequency, target = omega1 * omega1;
  double lo = 0, hi = nodeMass_ * gravity_ * p.length + target * p.mass * p.length * p.length;
  for (int i = 0; i < 200 && modes(lin, hi).eigenvalues()(0) < target; ++i) hi *= 2;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (modes(lin, mid).eigenvalues()(0) < target ? lo : hi) = mid;
  }
  kappa_ = hi;
  const auto m = modes(lin, kappa_);
  if (!(m.eigenvalues()(0) > 0)) throw std::invalid_argument("reference blade: no stiffness gives that frequency");
  omegaMax_ = std::sqrt(m.eigenvalues()(n_ - 1));
  // Damping proportional to mass (air drag on every node, C = alpha M): every mode keeps its
  // shape and mode k's ratio is alpha / (2 omega_k), exactly zeta for the first. Integrated as the
  // exact decay exp(-alpha h) of each substep: stable at any alpha. (Damping the bends' rates,
  // C proportional to K, damps high modes more but bounds an explicit step by 2 / (beta omega^2):
  // 64 segments needed ~10^7 substeps a second.)
  alpha_ = 2 * p.dampingRatio * omega1;
  // Substep: accurate for the highest mode (h omega_max <= 0.05).
  h_ = 0.05 / omegaMax_;
  for (auto* v : {&x_, &y_, &z_, &vx_, &vy_, &vz_, &fx_, &fy_, &fz_, &px_, &py_, &pz_}) v->assign(size_t(n_), 0.0);
  tangent_.assign(size_t(n_), {0, 0, 0, 0});
  bendTo(0);
}

void ReferenceBlade::bendTo(double angle) {
  for (int i = 0; i < n_; ++i) {
    const double r = segment_ * (i + 1);
    x_[size_t(i)] = r * std::sin(angle);
    y_[size_t(i)] = r * std::cos(angle);
    z_[size_t(i)] = 0;
    vx_[size_t(i)] = vy_[size_t(i)] = vz_[size_t(i)] = 0;
  }
}

void ReferenceBlade::advance(double seconds, const std::array<double, 3>& windForce, const ReferenceBall* ball) {
  const int steps = std::max(1, int(std::ceil(seconds / h_ - 1e-9)));
  const double h = seconds / steps;
  for (int s = 0; s < steps; ++s) {
    if (!ball) {
      substepOnce(h, windForce, nullptr);
      continue;
    }
    const double u = double(s + 1) / steps;  // the ball where it is at the substep's end
    std::array<double, 4> at{0, 0, 0, ball->radius};
    for (size_t c = 0; c < 3; ++c) at[c] = ball->from[c] + (ball->to[c] - ball->from[c]) * u;
    substepOnce(h, windForce, &at);
  }
}

double ReferenceBlade::pushOutOf(const std::array<double, 4>& ball) {
  double deepest = 0;
  for (size_t i = 0; i < size_t(n_); ++i) {
    const double dx = x_[i] - ball[0], dy = y_[i] - ball[1], dz = z_[i] - ball[2];
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (d >= ball[3]) continue;
    deepest = std::max(deepest, ball[3] - d);
    if (!(d > 0)) {  // at the centre: straight up
      y_[i] = ball[1] + ball[3];
      continue;
    }
    const double scale = ball[3] / d;
    x_[i] = ball[0] + dx * scale, y_[i] = ball[1] + dy * scale, z_[i] = ball[2] + dz * scale;
  }
  return deepest;
}

void ReferenceBlade::substepOnce(double h, const std::array<double, 3>& windForce, const std::array<double, 4>* ball) {
  const size_t n = size_t(n_);
  // Forces: weight and wind on every node.
  for (size_t i = 0; i < n; ++i) {
    fx_[i] = windForce[0] / n_;
    fy_[i] = windForce[1] / n_ - nodeMass_ * gravity_;
    fz_[i] = windForce[2] / n_;
  }
  // Bending. Segment j runs from node j-1 (the root for j = 0) to node j: its unit tangent t_j
  // (components 0-2) and length (3); e_j = t_j - t_(j-1), with t_(-1) = up (the clamp).
  std::vector<std::array<double, 4>>& seg = tangent_;
  for (size_t j = 0; j < n; ++j) {
    const double ax = j ? x_[j - 1] : 0, ay = j ? y_[j - 1] : 0, az = j ? z_[j - 1] : 0;
    const double d[3] = {x_[j] - ax, y_[j] - ay, z_[j] - az};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    seg[j] = {d[0] / len, d[1] / len, d[2] / len, len};
  }
  // Component c of e_j (j = n: none, the free tip).
  auto bend = [&](size_t j, size_t c) { return j >= n ? 0.0 : seg[j][c] - (j ? seg[j - 1][c] : (c == 1 ? 1.0 : 0.0)); };
  for (size_t j = 0; j < n; ++j) {
    // dE/dt_j = kappa (e_j - e_(j+1)), through dt_j/dx_j = (I - t t^T)/len: a force on node j
    // and the opposite on node j-1.
    double g[3];
    for (size_t c = 0; c < 3; ++c) g[c] = kappa_ * (bend(j, c) - bend(j + 1, c));
    const std::array<double, 4>& t = seg[j];
    const double along = t[0] * g[0] + t[1] * g[1] + t[2] * g[2];
    double f[3];
    for (size_t c = 0; c < 3; ++c) f[c] = (g[c] - t[c] * along) / t[3];
    fx_[j] -= f[0], fy_[j] -= f[1], fz_[j] -= f[2];
    if (j > 0) fx_[j - 1] += f[0], fy_[j - 1] += f[1], fz_[j - 1] += f[2];
  }
  // Symplectic Euler with the drag's exact decay, then the lengths and the ground, then the
  // velocities from the positions.
  const double decay = std::exp(-alpha_ * h);
  for (size_t i = 0; i < n; ++i) {
    px_[i] = x_[i], py_[i] = y_[i], pz_[i] = z_[i];
    vx_[i] = (vx_[i] + h * fx_[i] / nodeMass_) * decay;
    vy_[i] = (vy_[i] + h * fy_[i] / nodeMass_) * decay;
    vz_[i] = (vz_[i] + h * fz_[i] / nodeMass_) * decay;
    x_[i] += h * vx_[i];
    y_[i] += h * vy_[i];
    z_[i] += h * vz_[i];
  }
  // Mass-weighted projection, root to tip, until every segment is within 1e-6 of its length
  // and no node is inside the ball (4 sweeps or fewer under a scenario's forces; at most 64).
  for (int sweep = 0; sweep < 64; ++sweep) {
    double worst = ball ? pushOutOf(*ball) : 0;
    for (size_t j = 0; j < n; ++j) {
      const double ax = j ? x_[j - 1] : 0, ay = j ? y_[j - 1] : 0, az = j ? z_[j - 1] : 0;
      const double dx = x_[j] - ax, dy = y_[j] - ay, dz = z_[j] - az;
      const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
      const double stretch = (len - segment_) / len;
      worst = std::max(worst, std::fabs(len - segment_));
      const double share = j ? 0.5 : 1.0;  // equal node masses; the root does not move
      x_[j] -= share * stretch * dx, y_[j] -= share * stretch * dy, z_[j] -= share * stretch * dz;
      if (j) x_[j - 1] += share * stretch * dx, y_[j - 1] += share * stretch * dy, z_[j - 1] += share * stretch * dz;
    }
    if (worst <= 1e-6 * segment_) break;
  }
  // Then the ground and, only where the sweeps could not hold a length (forces per unit mass far
  // beyond a scenario's: a reviewer's 1e-9 kg blade in a 1e4 N wind had stretched to 5.7e5 m),
  // each node put back at the segment length from the one below, root to tip. Not always: that
  // pass ignores the masses, and as the rule it slowed the first mode by 15 %.
  bool holds = true;
  for (size_t j = 0; j < n; ++j) {
    y_[j] = std::max(y_[j], 0.0);
    const double ax = j ? x_[j - 1] : 0, ay = j ? y_[j - 1] : 0, az = j ? z_[j - 1] : 0;
    const double dx = x_[j] - ax, dy = y_[j] - ay, dz = z_[j] - az;
    holds = holds && std::fabs(std::sqrt(dx * dx + dy * dy + dz * dz) - segment_) <= 1e-3 * segment_;
  }
  for (size_t j = 0; !holds && j < n; ++j) {
    const double ax = j ? x_[j - 1] : 0, ay = j ? y_[j - 1] : 0, az = j ? z_[j - 1] : 0;
    double dx = x_[j] - ax, dy = y_[j] - ay, dz = z_[j] - az;
    double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (!(len > 0)) dx = 0, dy = 1, dz = 0, len = 1;  // on the node below: put it upright
    x_[j] = ax + dx * segment_ / len;
    y_[j] = ay + dy * segment_ / len;
    z_[j] = az + dz * segment_ / len;
    if (y_[j] < 0) {  // below the ground: on it, at the segment length, in the same horizontal direction
      const double horizontal = std::sqrt(std::max(0.0, segment_ * segment_ - ay * ay));
      double hx = dx, hz = dz, hl = std::sqrt(hx * hx + hz * hz);
      if (!(hl > 0)) hx = 1, hz = 0, hl = 1;
      x_[j] = ax + hx * horizontal / hl;
      y_[j] = 0;
      z_[j] = az + hz * horizontal / hl;
    }
  }
  for (size_t i = 0; i < n; ++i) {
    vx_[i] = (x_[i] - px_[i]) / h;
    vy_[i] = (y_[i] - py_[i]) / h;
    vz_[i] = (z_[i] - pz_[i]) / h;
  }
}

}  // namespace sg
