#include "analysis/stability.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Eigenvalues>

#include "clothlab/core/not_implemented.hpp"
#include "clothlab/integrators/stability_limit.hpp"

namespace clothlab {

namespace {

using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The matrix of a linear map, column by column: the map applied to each basis vector.
Matrix matrix_of(int n, const std::function<Vector(const Vector&)>& step) {
  Matrix a(n, n);
  for (int k = 0; k < n; ++k)
    a.col(k) = step(Vector::Unit(n, k));
  return a;
}

// The biggest factor by which a row's oscillator grows in `steps` steps at dt, over the rows.
double growth_over(std::string_view integrator, double dt, double steps, const StiffnessBounds& b) {
  double rho = 0.0;
  for (const RowOscillator& row : b.rows) {
    // In the row's own time (w = 1, y = dt w), where the matrix is well scaled.
    const Matrix a = oscillator_step_matrix(integrator, dt * row.omega, 1.0, row.beta / row.omega);
    rho = std::max(rho, spectral_radius(a));
  }
  return std::pow(rho, steps);
}

// Merges rows with the same damping ratio zeta = beta / 2w, to 0.1 %, keeping the highest w of
// each group with the group's lowest and highest zeta. At a fixed zeta every method's limit is
// y(zeta) / w, so the highest w of a group has its smallest limit; a regular cloth has a handful
// of groups where it has thousands of particles, and the advisor solves for a limit per group.
std::vector<RowOscillator> merge_rows(const std::vector<RowOscillator>& rows) {
  struct Group {
    double omega = 0.0, zeta_lo = 0.0, zeta_hi = 0.0;
  };
  std::map<long long, Group> groups;
  for (const RowOscillator& row : rows) {
    if (row.omega == 0.0) continue;  // no spring on this particle: nothing oscillates
    const double zeta = row.beta / (2.0 * row.omega);
    const long long key = zeta > 0.0 ? std::llround(std::log(zeta) / std::log1p(1e-3)) : LLONG_MIN;
    const auto [at, is_new] = groups.try_emplace(key, Group{row.omega, zeta, zeta});
    Group& g = at->second;
    if (is_new) continue;
    g.omega = std::max(g.omega, row.omega);
    g.zeta_lo = std::min(g.zeta_lo, zeta);
    g.zeta_hi = std::max(g.zeta_hi, zeta);
  }
  std::vector<RowOscillator> merged;
  for (const auto& [key, g] : groups) {
    merged.push_back({g.omega, 2.0 * g.zeta_lo * g.omega});
    if (g.zeta_hi != g.zeta_lo) merged.push_back({g.omega, 2.0 * g.zeta_hi * g.omega});
  }
  return merged;
}

// Collects block Gershgorin row sums of M^-1/2 K M^-1/2 and of the damping blocks: for row i,
// the largest |eigenvalue| of the diagonal block (the sum of every block that lands there, so
// springs pulling in different directions are not counted as if they were parallel) plus the
// spectral norm of each off-diagonal block.
class GershgorinRows final : public ForceJacobians {
 public:
  explicit GershgorinRows(const Particles& p)
      : p_(p),
        k_diagonal_(p.size(), Mat3::Zero()),
        c_diagonal_(p.size(), Mat3::Zero()),
        k_off_(VectorX::Zero(p.size())),
        c_off_(VectorX::Zero(p.size())),
        c_self_(p.size(), Mat3::Zero()) {}

  void add_pair(Index i, Index j, const Mat3& dfdx, const Mat3& dfdv) override {
    const double k = norm(dfdx), c = norm(dfdv);
    for (const auto& [a, b] : {std::pair{i, j}, std::pair{j, i}}) {
      if (p_.inv_m[a] == 0.0) continue;  // a pinned particle is not an unknown
      k_diagonal_[a] += dfdx;
      c_diagonal_[a] += dfdv;
      // Off the diagonal: |K_ab| / sqrt(m_a m_b), nothing when b is pinned.
      k_off_[a] += k * std::sqrt(p_.inv_m[a] * p_.inv_m[b]);
      c_off_[a] += c * std::sqrt(p_.inv_m[a] * p_.inv_m[b]);
    }
  }

  void add_self(Index i, const Mat3& dfdx, const Mat3& dfdv) override {
    if (p_.inv_m[i] == 0.0) return;
    k_diagonal_[i] -= dfdx;
    c_diagonal_[i] -= dfdv;
    c_self_[i] -= dfdv;
  }

  StiffnessBounds bounds() const {
    StiffnessBounds b;
    bool any_free = false;
    b.beta_min = kInfinity;
    std::vector<RowOscillator> rows;
    for (Index i = 0; i < p_.size(); ++i) {
      if (p_.inv_m[i] == 0.0) continue;
      any_free = true;
      const double w2 = norm(k_diagonal_[i]) * p_.inv_m[i] + k_off_[i];
      const double beta = norm(c_diagonal_[i]) * p_.inv_m[i] + c_off_[i];
      rows.push_back({std::sqrt(w2), beta});
      b.omega_max = std::max(b.omega_max, w2);
      b.beta_max = std::max(b.beta_max, beta);
      // The damping every direction of this particle gets: the smallest eigenvalue of its own
      // damping block ([damping] rate m I gives the rate).
      Eigen::SelfAdjointEigenSolver<Mat3> eigen;
      eigen.computeDirect(c_self_[i], Eigen::EigenvaluesOnly);
      b.beta_min =
          std::min(b.beta_min, std::max(0.0, eigen.eigenvalues().minCoeff()) * p_.inv_m[i]);
    }
    b.omega_max = std::sqrt(b.omega_max);
    if (!any_free) b.beta_min = 0.0;
    b.rows = merge_rows(rows);
    return b;
  }

 private:
  static double norm(const Mat3& block) {
    Eigen::SelfAdjointEigenSolver<Mat3> eigen;
    eigen.computeDirect(block, Eigen::EigenvaluesOnly);
    return eigen.eigenvalues().cwiseAbs().maxCoeff();
  }

  const Particles& p_;
  std::vector<Mat3> k_diagonal_, c_diagonal_;  // the diagonal blocks -K_ii and -D_ii
  VectorX k_off_, c_off_;                      // scaled off-diagonal block norms
  std::vector<Mat3> c_self_;                   // damping each particle has on its own
};

}  // namespace

Matrix oscillator_step_matrix(std::string_view integrator, double dt, double omega, double beta) {
  const double h = dt, w2 = omega * omega;
  // The oscillator's acceleration.
  const auto a = [&](double x, double v) { return -w2 * x - beta * v; };
  const auto state = [](double x, double v) { return Vector((Vector(2) << x, v).finished()); };

  if (integrator == "explicit-euler") {
    return matrix_of(
        2, [&](const Vector& s) { return state(s[0] + h * s[1], s[1] + h * a(s[0], s[1])); });
  }
  if (integrator == "symplectic-euler") {
    return matrix_of(2, [&](const Vector& s) {
      const double v = s[1] + h * a(s[0], s[1]);
      return state(s[0] + h * v, v);
    });
  }
  if (integrator == "midpoint" || integrator == "rk4" || integrator == "implicit-euler") {
    // On a linear system these are functions of J = [[0, 1], [-w^2, -beta]]:
    // midpoint I + hJ + (hJ)^2/2, RK4 the Taylor series of exp(hJ) to (hJ)^4/24, implicit
    // Euler (I - hJ)^-1 (its single linearisation is exact for a linear spring).
    Matrix j(2, 2);
    j << 0.0, 1.0, -w2, -beta;
    const Matrix hj = h * j, i = Matrix::Identity(2, 2);
    if (integrator == "implicit-euler") return (i - hj).inverse();
    Matrix sum = i, term = i;
    const int order = integrator == "midpoint" ? 2 : 4;
    for (int k = 1; k <= order; ++k) {
      term = term * hj / k;
      sum += term;
    }
    return sum;
  }
  if (integrator == "velocity-verlet") {
    // As VelocityVerlet::advance: the second acceleration at the predicted velocity v + h a.
    return matrix_of(2, [&](const Vector& s) {
      const double a0 = a(s[0], s[1]);
      const double v_half = s[1] + 0.5 * h * a0;
      const double x = s[0] + h * v_half;
      return state(x, v_half + 0.5 * h * a(x, s[1] + h * a0));
    });
  }
  if (integrator == "position-verlet") {
    // State (x_n, x_n-1, a_n-1), as PositionVerlet::advance keeps it: the velocity it reports
    // is v_n = (x_n - x_n-1) / h + h/2 a_n-1.
    return matrix_of(3, [&](const Vector& s) {
      const double v = (s[0] - s[1]) / h + 0.5 * h * s[2];
      const double an = a(s[0], v);
      return Vector((Vector(3) << 2.0 * s[0] - s[1] + h * h * an, s[0], an).finished());
    });
  }
  throw std::invalid_argument(fmt::format("no step matrix for integrator '{}'", integrator));
}

double spectral_radius(const Matrix& a) {
  return a.eigenvalues().cwiseAbs().maxCoeff();
}

double eigenvalue_dt_limit(std::string_view integrator, double omega, double beta) {
  // The search runs in the oscillator's own time, w = 1 and y = dt w, and scales back at the end:
  // the eigenvalues are the same, and the matrix stays well scaled however stiff the spring (at
  // w = 1e4 rad/s position Verlet's matrix would hold both dt and w^2 / dt, 1e-6 s and 1e14 1/s^3,
  // and its eigenvalues would carry errors far above the 1e-12 allowed for rounding).
  const double b = beta / omega;
  const auto rho = [&](double y) {
    return spectral_radius(oscillator_step_matrix(integrator, y, 1.0, b));
  };
  // Stable: no eigenvalue outside the unit circle (beyond rounding).
  const auto stable = [&](double y) { return rho(y) <= 1.0 + 1e-12; };
  // A step visibly loses amplitude: its largest eigenvalue below 1 by more than rounding. Or,
  // on a heavily overdamped spring, whose slow mode loses less than rounding a step while its
  // fast one dies out at once: every eigenvalue within the circle and their product (det M, the
  // factor by which a step shrinks an area of states) below 1 by more than rounding. A method
  // unstable at every dt has det M >= 1 (explicit Euler 1 + y^2, midpoint 1 + y^4 / 4).
  const auto shrinks = [&](double y) {
    const Matrix m = oscillator_step_matrix(integrator, y, 1.0, b);
    const double r = spectral_radius(m);
    return r < 1.0 - 1e-14 || (r <= 1.0 + 1e-12 && std::abs(m.determinant()) < 1.0 - 1e-14);
  };
  // At y = 0.01 the growth of undamped explicit Euler (y^2 / 2 a step) and midpoint (y^4 / 8)
  // still shows above rounding. A damped method unstable there may be stable further down
  // (explicit Euler below y = 2 zeta, midpoint below about y = 2 zeta^(1/3), symplectic Euler
  // below y = 2 / (2 zeta) on a spring damped far past critical): halve y until a step visibly
  // shrinks the motion, or call the method unstable at every dt once y is below 1e-30.
  double lo = 1e-2;
  if (!stable(lo)) {
    do {
      lo *= 0.5;
      if (lo < 1e-30) return 0.0;
    } while (!shrinks(lo));
  }
  // Up in steps of 10 % to the first unstable y, then bisect between the last two.
  double hi = 1.1 * lo;
  while (stable(hi)) {
    lo = hi;
    hi *= 1.1;
    if (hi > 1e6) return kInfinity;
  }
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (stable(mid) ? lo : hi) = mid;
  }
  return lo / omega;
}

double oscillator_dt_limit(std::string_view integrator, double omega, double beta) {
  // Explicit Euler's limit has a closed form, which lesson 08's exercise derives (m = 1 kg:
  // k = w^2, c = beta).
  if (integrator == "explicit-euler")
    return largest_stable_dt_explicit_euler(omega * omega, 1.0, beta);
  return eigenvalue_dt_limit(integrator, omega, beta);
}

std::string round_down(double x, int digits) {
  if (!(x > 0.0) || !std::isfinite(x)) return fmt::format("{}", x);
  const int exponent = static_cast<int>(std::floor(std::log10(x))) - (digits - 1);
  // The leading digits, rounded down; the factor keeps 0.02 from coming out as 199.99999 units
  // of 1e-4 and printing as 0.0199, and the check below undoes any step it takes too far.
  double q = std::floor(x / std::pow(10.0, exponent) * (1.0 + 1e-12));
  for (;;) {
    const std::string text = fmt::format("{:.{}g}", q * std::pow(10.0, exponent), digits);
    if (std::stod(text) <= x) return text;
    q -= 1.0;  // the division or the formatting rounded up: one unit less
  }
}

std::string describe_dt_limit(double dt_limit) {
  if (dt_limit == 0.0) return "none (unstable at every dt)";
  if (std::isinf(dt_limit)) return "any";
  return fmt::format("dt <= {} s", round_down(dt_limit));
}

StiffnessBounds stiffness_bounds(const World& world) {
  const Particles& p = world.particles;
  GershgorinRows rows(p);
  for (const auto& effect : world.force_effects)
    effect->add_jacobians(p, p.x, p.v, rows);
  return rows.bounds();
}

TimeStepAdvice advise_time_step(const World& world, double dt, long steps) {
  TimeStepAdvice advice;
  advice.bounds = stiffness_bounds(world);
  const StiffnessBounds& b = advice.bounds;
  if (!world.integrator || b.omega_max == 0.0) return advice;  // no springs: nothing to limit
  const std::string method(world.integrator->name());
  // XPBD (lesson 12) moves by constraints, not spring forces: no step limit of its springs to
  // give. (Its explicit external forces and dampers are held by its small substeps.) The
  // local/global solver (lesson 13) steps its springs and dampers implicitly: none either.
  if (!world.integrator->springs_without_dt_limit().empty()) return advice;
  // The worst row. Until exercise ex08.1 is done, explicit Euler's limit comes from the
  // eigenvalues, as every other method's does.
  const auto worst_row = [&](const auto& limit) {
    double worst = kInfinity;
    for (const RowOscillator& row : b.rows)
      worst = std::min(worst, limit(method, row.omega, row.beta));
    return worst;
  };
  try {
    advice.dt_limit = worst_row(oscillator_dt_limit);
  } catch (const NotImplemented&) {
    advice.dt_limit = worst_row(eigenvalue_dt_limit);
  }
  advice.growth = growth_over(method, dt, static_cast<double>(steps), b);
  if (advice.growth <= 2.0) return advice;

  // A dt at which the run stays within a factor 2: below the limit, and short enough that a
  // method unstable at every dt grows by at most 2 over the scene's duration.
  const double duration = dt * static_cast<double>(steps);
  double lo = 0.0, hi = dt;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (growth_over(method, mid, duration / mid, b) <= 2.0 ? lo : hi) = mid;
  }
  const double suggested = 0.9 * lo;

  const std::string mode = fmt::format(
      "its stiffest mode (w <= {:.4g} rad/s, damping up to {:.3g} 1/s, by Gershgorin's bound)",
      b.omega_max, b.beta_max);
  const std::string growth = std::isfinite(advice.growth) && advice.growth < 1e300
                                 ? fmt::format("{:.3g}", advice.growth)
                                 : std::string("more than 1e300");
  std::string why;
  if (advice.dt_limit > 0.0) {
    why = fmt::format(
        "dt = {} s is above the stability limit of {} for this scene, about {} s: {} would "
        "grow by a factor of {} over the run's {} steps",
        dt, method, round_down(advice.dt_limit), mode, growth, steps);
  } else {
    why = fmt::format(
        "{} adds energy at every step on {} springs: at dt = {} s {} would grow by a "
        "factor of {} over the run's {} steps",
        method, b.beta_max > 0.0 ? "these" : "undamped", dt, mode, growth, steps);
  }
  // A dt that small may be none a double can hold (a damping of 1e40 1/s): then no dt to offer.
  const std::string smaller = suggested > 0.0
                                  ? fmt::format("dt <= {} s ({:.0f} times smaller), or ",
                                                round_down(suggested), std::ceil(dt / suggested))
                                  : std::string();
  const bool offer_symplectic = advice.dt_limit == 0.0 && method != "symplectic-euler";
  advice.warning = fmt::format(
      "{}. Take {}method = \"implicit-euler\", which is stable at any dt{}", why, smaller,
      offer_symplectic ? ", or \"symplectic-euler\", which keeps energy bounded" : "");
  return advice;
}

}  // namespace clothlab
