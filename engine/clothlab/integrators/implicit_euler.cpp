#include "clothlab/integrators/implicit_euler.hpp"

#include <chrono>

#include <Eigen/IterativeLinearSolvers>
#include <algorithm>

#include "clothlab/core/backend.hpp"
#include "clothlab/core/world.hpp"

namespace clothlab {

namespace {

// Collects the effects' Jacobian blocks as blocks of A = M - dt D - dt^2 K (without M) and
// accumulates K v for the right-hand side.
class SystemAssembler final : public ForceJacobians {
 public:
  SystemAssembler(const Matrix3X& v, double dt, std::vector<ImplicitEuler::Block>& blocks,
                  Matrix3X& kv)
      : v_(v), dt_(dt), blocks_(blocks), kv_(kv) {}

  void add_pair(Index i, Index j, const Mat3& dfdx, const Mat3& dfdv) override {
    const Mat3 block = -dt_ * dfdv - dt_ * dt_ * dfdx;  // this pair's share of A at (i, j)
    blocks_.push_back({i, j, block});
    blocks_.push_back({j, i, block});
    blocks_.push_back({i, i, -block});
    blocks_.push_back({j, j, -block});
    // K v: df_i/dx_j v_j + df_i/dx_i v_i = dfdx (v_j - v_i), and the opposite on j.
    const Vec3 kv = dfdx * (v_.col(j) - v_.col(i));
    kv_.col(i) += kv;
    kv_.col(j) -= kv;
  }

  void add_self(Index i, const Mat3& dfdx, const Mat3& dfdv) override {
    blocks_.push_back({i, i, -dt_ * dfdv - dt_ * dt_ * dfdx});
    kv_.col(i) += dfdx * v_.col(i);
  }

 private:
  const Matrix3X& v_;
  double dt_;
  std::vector<ImplicitEuler::Block>& blocks_;
  Matrix3X& kv_;
};

}  // namespace

void ImplicitEuler::build_pattern(const Particles& p) {
  const Index n = p.size();
  pattern_.clear();
  for (const Block& block : blocks_)
    pattern_.emplace_back(block.i, block.j);
  pinned_.assign(n, false);
  for (Index i = 0; i < n; ++i)
    pinned_[i] = p.inv_m[i] == 0.0;

  // The pattern: every free block, plus the diagonal (the mass, or 1 for a pinned particle).
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(9 * blocks_.size() + 3 * n);
  for (const auto& [i, j] : pattern_) {
    if (pinned_[i] || pinned_[j]) continue;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c)
        triplets.emplace_back(3 * i + r, 3 * j + c, 0.0);
    }
  }
  for (Index k = 0; k < 3 * n; ++k)
    triplets.emplace_back(k, k, 0.0);
  a_.resize(3 * n, 3 * n);
  a_.setFromTriplets(triplets.begin(), triplets.end());
  a_.makeCompressed();

  // In a column of a compressed column-major matrix the rows are sorted, so rows 3i..3i+2 of
  // column 3j+c sit next to each other: one offset per block column finds all three.
  block_offsets_.assign(3 * blocks_.size(), -1);
  for (size_t k = 0; k < pattern_.size(); ++k) {
    const auto [i, j] = pattern_[k];
    if (pinned_[i] || pinned_[j]) continue;
    for (int c = 0; c < 3; ++c)
      block_offsets_[3 * k + c] = &a_.coeffRef(3 * i, 3 * j + c) - a_.valuePtr();
  }
}

void ImplicitEuler::advance(World& world, double dt) {
  // The world's backend may take the whole step (the same solution, to the tolerance).
  if (world.backend &&
      world.backend->implicit_euler_step(world, dt, tolerance, max_iterations, last_dv_, stats_)) {
    ++backend_steps;
    return;
  }
  Particles& p = world.particles;
  const Index n = p.size();

  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  // f0 = f(x, v), and the Jacobians at the same state.
  world.compute_forces(p.x, p.v, p.f);
  blocks_.clear();
  Matrix3X kv = Matrix3X::Zero(3, n);
  SystemAssembler assembler(p.v, dt, blocks_, kv);
  for (const auto& effect : world.force_effects)
    effect->add_jacobians(p, p.x, p.v, assembler);

  // Rebuild the pattern only when the blocks or the pins changed (tearing removes springs).
  bool same = pattern_.size() == blocks_.size() && pinned_.size() == static_cast<size_t>(n);
  for (size_t k = 0; same && k < blocks_.size(); ++k)
    same = pattern_[k] == std::make_pair(blocks_[k].i, blocks_[k].j);
  for (Index i = 0; same && i < n; ++i)
    same = pinned_[i] == (p.inv_m[i] == 0.0);
  if (!same) build_pattern(p);

  // A = M - dt D - dt^2 K, refilled in place; a pinned particle's rows hold the identity.
  double* values = a_.valuePtr();
  std::fill(values, values + a_.nonZeros(), 0.0);
  for (Index i = 0; i < n; ++i) {
    const double mass = pinned_[i] ? 1.0 : p.m[i];
    for (int r = 0; r < 3; ++r)
      a_.coeffRef(3 * i + r, 3 * i + r) += mass;
  }
  for (size_t k = 0; k < blocks_.size(); ++k) {
    if (block_offsets_[3 * k] < 0) continue;  // a pinned particle's row or column
    for (int c = 0; c < 3; ++c) {
      double* column = values + block_offsets_[3 * k + c];
      for (int r = 0; r < 3; ++r)
        column[r] += blocks_[k].value(r, c);
    }
  }

  // b = dt (f0 + dt K v), zero on pinned rows.
  Matrix3X b = dt * (p.f + dt * kv);
  for (Index i = 0; i < n; ++i) {
    if (pinned_[i]) b.col(i).setZero();
  }

  const Clock::time_point assembled = Clock::now();
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> solver;
  solver.setTolerance(tolerance);
  solver.setMaxIterations(max_iterations);
  solver.compute(a_);
  const Eigen::Map<const VectorX> rhs(b.data(), 3 * n);
  if (last_dv_.size() != 3 * n) last_dv_ = VectorX::Zero(3 * n);
  // Eigen's count leaves out the iteration in which it converged (and is also 0 when the start
  // was already good enough), so tell those apart to count the iterations actually taken.
  const bool start_good_enough =
      (rhs - a_ * last_dv_).squaredNorm() <= tolerance * tolerance * rhs.squaredNorm();
  last_dv_ = solver.solveWithGuess(rhs, last_dv_);
  const long taken =
      solver.iterations() + (solver.info() == Eigen::Success && !start_good_enough ? 1 : 0);

  ++stats_.solves;
  stats_.iterations += taken;
  stats_.max_iterations = std::max(stats_.max_iterations, taken);
  stats_.worst_error = std::max(stats_.worst_error, solver.error());
  if (solver.info() != Eigen::Success) ++stats_.unconverged;
  const Clock::time_point solved = Clock::now();
  stats_.assembly_seconds += std::chrono::duration<double>(assembled - start).count();
  stats_.solve_seconds += std::chrono::duration<double>(solved - assembled).count();

  // v' = v + dv, x' = x + dt v'.
  p.v += Eigen::Map<const Matrix3X>(last_dv_.data(), 3, n);
  p.x += dt * p.v;
}

}  // namespace clothlab
