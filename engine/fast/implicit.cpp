// implicit.cpp: implicit Euler's step in the engine room (FastEngine::implicit_euler_step).
//
// The lecture's ImplicitEuler (integrators/implicit_euler.cpp) writes the matrix
// A = M - h D - h^2 K out, block by block, into a sparse matrix, and hands it to Eigen's
// conjugate gradients. Here the matrix is never written: conjugate gradients need only its
// product with a vector, and
//   (A p)_i = d_i p_i + sum over the springs k of i of  +-B_k (p_j - p_i),
// where B_k = -h dfdv_k - h^2 dfdx_k is spring k's 3x3 block (symmetric: six numbers), d_i the
// particle's mass plus its damping's share, and the sign + at a spring's first end, - at its
// second. Each step stores the six numbers of every spring's block (its Jacobian, evaluated once
// with the lecture's spring_damper_jacobian) in a structure of arrays; each iteration then
//   1. over the springs: u_k = B_k (p_j - p_i)                         (split over the threads)
//   2. over the particles: q_i = d_i p_i + sum +-u_k, and p.q          (each its own springs)
//   3. over the particles: x += alpha p, r -= alpha q, z = P^-1 r, r.r and r.z
//   4. over the particles: p = z + beta p
// The dot products ride along in passes 2 and 3, summed per chunk of kChunk particles and the
// chunks added in order, so the result is the same bits on any number of threads.
//
// P is block Jacobi: each particle's 3x3 diagonal block of A, inverted once a step (or, with
// FastEngine::Preconditioner::diagonal, the diagonal alone, as the lecture's solver uses).
// A pinned particle's row and column are the identity's and its right-hand side 0, as in the
// lecture's matrix: its dv is 0 exactly, from the start, so it drops out of every product.
//
// The iteration is Eigen's ConjugateGradient line for line (its stopping rule on the
// recursively updated residual, its count), so the two agree to within the tolerance; the sums
// are taken in another order, so not bit for bit (tests/fast/implicit.cpp states the bound).
// The step declines (the lecture's code takes it) if a force effect other than the springs
// and damping adds Jacobians: it would not know that effect's blocks.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <typeinfo>
#include <utility>
#include <vector>

#include "clothlab/core/world.hpp"
#include "clothlab/forces/damping.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "fast/engine.hpp"
#include "fast/incidence.hpp"

namespace clothlab::fast {

namespace {

// Particles per partial sum of a dot product: the chunks, not the threads, fix the order of
// the sums.
constexpr Index kChunk = 1024;

// Records whether an effect adds any Jacobian, without keeping them.
class Probe final : public ForceJacobians {
 public:
  bool any = false;
  void add_pair(Index /*i*/, Index /*j*/, const Mat3& /*dfdx*/, const Mat3& /*dfdv*/) override {
    any = true;
  }
  void add_self(Index /*i*/, const Mat3& /*dfdx*/, const Mat3& /*dfdv*/) override { any = true; }
};

// Three components, each its own array (component d of item i at c[d][i]).
struct Columns {
  std::vector<double> c[3];
  void assign(size_t n) {
    for (auto& column : c)
      column.assign(n, 0.0);
  }
};

// A symmetric 3x3 matrix by its six numbers: xx, xy, xz, yy, yz, zz.
constexpr int kXX = 0, kXY = 1, kXZ = 2, kYY = 3, kYZ = 4, kZZ = 5;

}  // namespace

struct ImplicitSolver {
  // The plan: the spring sets (at their version) and the particle count the arrays are for.
  std::vector<std::pair<const SpringSet*, unsigned long>> sets;
  Index n = -1;
  std::vector<Index> si, sj;  // every spring's ends, the sets one after the other
  // Particle i's springs: ends[start[i] .. start[i + 1]), 2k where it is spring k's first end,
  // 2k + 1 where it is the second, in the springs' order.
  std::vector<Index> start, ends;

  // A step's numbers.
  std::vector<double> block[6];  // B_k, spring by spring
  Columns u;                     // B_k (p_j - p_i), or dfdx_k (v_j - v_i) while assembling
  std::vector<double> d;         // m_i + the damping's h rate m_i; 1 for a pinned particle
  std::vector<double> free;      // 1, or 0 for a pinned particle
  std::vector<double> pre[6];    // the preconditioner's inverse block, particle by particle
  Columns b, x, r, z, p, q;
  std::vector<double> partial;  // per chunk: two partial sums

  size_t springs() const { return si.size(); }

  // Rebuilds the plan if the springs or the particle count changed.
  void plan(const std::vector<const SpringSet*>& now, Index particles) {
    bool same = particles == n && now.size() == sets.size();
    for (size_t s = 0; same && s < now.size(); ++s)
      same = sets[s].first == now[s] && sets[s].second == now[s]->version();
    if (same) return;
    n = particles;
    sets.clear();
    si.clear();
    sj.clear();
    for (const SpringSet* set : now) {
      sets.emplace_back(set, set->version());
      for (size_t k = 0; k < set->size(); ++k) {
        si.push_back(set->i(k));
        sj.push_back(set->j(k));
      }
    }
    group_ends_by_row(
        si, sj, n, [](Index particle) { return particle; }, start, ends);
    for (auto& column : block)
      column.assign(springs(), 0.0);
    u.assign(springs());
    const size_t np = static_cast<size_t>(n);
    d.assign(np, 0.0);
    free.assign(np, 0.0);
    for (auto& column : pre)
      column.assign(np, 0.0);
    for (Columns* v : {&b, &x, &r, &z, &p, &q})
      v->assign(np);
    partial.assign(2 * static_cast<size_t>((n + kChunk - 1) / kChunk), 0.0);
  }

  // Pass 1: u_k = B_k (p_j - p_i) for springs [begin, end).
  void spring_products(Index begin, Index end) {
    const Index* __restrict i = si.data(), * __restrict j = sj.data();
    const double *__restrict px = p.c[0].data(), *__restrict py = p.c[1].data(),
                 *__restrict pz = p.c[2].data();
    const double *__restrict bxx = block[kXX].data(), *__restrict bxy = block[kXY].data(),
                 *__restrict bxz = block[kXZ].data(), *__restrict byy = block[kYY].data(),
                 *__restrict byz = block[kYZ].data(), *__restrict bzz = block[kZZ].data();
    double* __restrict ux = u.c[0].data(), * __restrict uy = u.c[1].data(), * __restrict uz = u.c[2].data();
    for (Index k = begin; k < end; ++k) {
      const double dx = px[j[k]] - px[i[k]], dy = py[j[k]] - py[i[k]], dz = pz[j[k]] - pz[i[k]];
      ux[k] = bxx[k] * dx + bxy[k] * dy + bxz[k] * dz;
      uy[k] = bxy[k] * dx + byy[k] * dy + byz[k] * dz;
      uz[k] = bxz[k] * dx + byz[k] * dy + bzz[k] * dz;
    }
  }

  // The sum over particle i's springs of +-u_k, component by component.
  Vec3 gathered(Index i) const {
    Vec3 sum = Vec3::Zero();
    for (Index e = start[static_cast<size_t>(i)]; e < start[static_cast<size_t>(i) + 1]; ++e) {
      const Index code = ends[static_cast<size_t>(e)];
      const size_t k = static_cast<size_t>(code >> 1);
      const Vec3 uk(u.c[0][k], u.c[1][k], u.c[2][k]);
      if (code & 1)
        sum -= uk;
      else
        sum += uk;
    }
    return sum;
  }

  // z_i = P^-1 r_i.
  void precondition(size_t i) {
    const double rx = r.c[0][i], ry = r.c[1][i], rz = r.c[2][i];
    z.c[0][i] = pre[kXX][i] * rx + pre[kXY][i] * ry + pre[kXZ][i] * rz;
    z.c[1][i] = pre[kXY][i] * rx + pre[kYY][i] * ry + pre[kYZ][i] * rz;
    z.c[2][i] = pre[kXZ][i] * rx + pre[kYZ][i] * ry + pre[kZZ][i] * rz;
  }

  // Runs chunk(begin, end, sums) on every chunk of particles, on the threads, and returns the
  // two sums each chunk made, added chunk by chunk in order.
  template <class Chunk>
  std::pair<double, double> over_chunks(const World& world, const Chunk& chunk) {
    const Index chunks = (n + kChunk - 1) / kChunk;
    world.for_items(chunks, [&](Index first, Index last) {
      for (Index c = first; c < last; ++c) {
        double sums[2] = {0.0, 0.0};
        chunk(static_cast<size_t>(c * kChunk), static_cast<size_t>(std::min(n, (c + 1) * kChunk)),
              sums);
        partial[2 * static_cast<size_t>(c)] = sums[0];
        partial[2 * static_cast<size_t>(c) + 1] = sums[1];
      }
    });
    double total[2] = {0.0, 0.0};
    for (Index c = 0; c < chunks; ++c) {
      total[0] += partial[2 * static_cast<size_t>(c)];
      total[1] += partial[2 * static_cast<size_t>(c) + 1];
    }
    return {total[0], total[1]};
  }

  // q = A p (passes 1 and 2); returns p.q.
  double product(const World& world) {
    world.for_items(static_cast<Index>(springs()),
                    [&](Index begin, Index end) { spring_products(begin, end); });
    return over_chunks(world,
                       [&](size_t begin, size_t end, double* sums) {
                         for (size_t i = begin; i < end; ++i) {
                           const Vec3 s = gathered(static_cast<Index>(i));
                           for (int c = 0; c < 3; ++c) {
                             q.c[c][i] = d[i] * p.c[c][i] + free[i] * s[c];
                             sums[0] += p.c[c][i] * q.c[c][i];
                           }
                         }
                       })
        .first;
  }
};

bool FastEngine::implicit_euler_step(World& world, double dt, double tolerance, int max_iterations,
                                     VectorX& dv, LinearSolveStats& stats) {
  Particles& particles = world.particles;
  const Index n = particles.size();
  if (n == 0) return false;
  // The effects: springs and damping it knows; any other that adds Jacobians, it declines.
  std::vector<const SpringSet*> sets;
  std::vector<double> damping;  // each damping's rate [1/s]
  for (const auto& effect : world.force_effects) {
    const ForceEffect& e = *effect;
    if (typeid(e) == typeid(SpringDampers)) {
      sets.push_back(&static_cast<const SpringDampers&>(e).springs());
    } else if (typeid(e) == typeid(Damping)) {
      damping.push_back(static_cast<const Damping&>(e).rate());
    } else {
      Probe probe;
      if (e.add_jacobians(particles, particles.x, particles.v, probe) || probe.any) return false;
    }
  }
  if (!implicit_) implicit_ = std::make_shared<ImplicitSolver>();
  ImplicitSolver& s = *implicit_;
  s.plan(sets, n);

  using Clock = std::chrono::steady_clock;
  const Clock::time_point started = Clock::now();
  const double h = dt;
  // f0 = f(x, v) (the engine room's force sum), then every spring's block and K v's share.
  world.compute_forces(particles.x, particles.v, particles.f);
  const Matrix3X& px = particles.x;
  const Matrix3X& pv = particles.v;
  size_t offset = 0;
  for (const SpringSet* set : sets) {
    world.for_items(static_cast<Index>(set->size()), [&](Index begin, Index end) {
      for (Index k = begin; k < end; ++k) {
        const size_t local = static_cast<size_t>(k), g = offset + local;
        const Index i = set->i(local), j = set->j(local);
        const SpringJacobian jac = spring_damper_jacobian(px.col(i), px.col(j), set->ks(local),
                                                          set->kd(local), set->l0(local));
        const Mat3 block = -h * jac.dfdv - h * h * jac.dfdx;
        s.block[kXX][g] = block(0, 0);
        s.block[kXY][g] = block(0, 1);
        s.block[kXZ][g] = block(0, 2);
        s.block[kYY][g] = block(1, 1);
        s.block[kYZ][g] = block(1, 2);
        s.block[kZZ][g] = block(2, 2);
        const Vec3 kv = jac.dfdx * (pv.col(j) - pv.col(i));
        for (int c = 0; c < 3; ++c)
          s.u.c[c][g] = kv[c];
      }
    });
    offset += set->size();
  }
  // Particle by particle: b = h (f0 + h K v), the diagonal, the preconditioner, the start.
  const bool warm = dv.size() == 3 * n;
  const bool block_jacobi = implicit_preconditioner == Preconditioner::block_jacobi;
  const double rhs_norm2 =
      s.over_chunks(world, [&](size_t begin, size_t end, double* sums) {
         for (size_t i = begin; i < end; ++i) {
           const Index pi = static_cast<Index>(i);
           const bool pinned = particles.inv_m[pi] == 0.0;
           s.free[i] = pinned ? 0.0 : 1.0;
           double mass = particles.m[pi];
           for (double rate : damping)
             mass += h * rate * particles.m[pi];
           s.d[i] = pinned ? 1.0 : mass;
           const Vec3 kv = s.gathered(pi);
           // The diagonal block d I - sum of B_k over the particle's springs.
           double a[6] = {s.d[i], 0.0, 0.0, s.d[i], 0.0, s.d[i]};
           for (Index e = s.start[i]; e < s.start[i + 1]; ++e) {
             const size_t k = static_cast<size_t>(s.ends[static_cast<size_t>(e)] >> 1);
             for (int m = 0; m < 6; ++m)
               a[m] -= s.block[m][k];
           }
           if (pinned) {
             std::fill(a, a + 6, 0.0);
             a[kXX] = a[kYY] = a[kZZ] = 1.0;
           } else if (!block_jacobi) {
             a[kXY] = a[kXZ] = a[kYZ] = 0.0;
           }
           // Its inverse, by cofactors (symmetric, positive definite).
           const double c00 = a[kYY] * a[kZZ] - a[kYZ] * a[kYZ],
                        c01 = a[kXZ] * a[kYZ] - a[kXY] * a[kZZ],
                        c02 = a[kXY] * a[kYZ] - a[kXZ] * a[kYY],
                        c11 = a[kXX] * a[kZZ] - a[kXZ] * a[kXZ],
                        c12 = a[kXY] * a[kXZ] - a[kXX] * a[kYZ],
                        c22 = a[kXX] * a[kYY] - a[kXY] * a[kXY];
           const double det = a[kXX] * c00 + a[kXY] * c01 + a[kXZ] * c02;
           const double inv[6] = {c00 / det, c01 / det, c02 / det, c11 / det, c12 / det, c22 / det};
           for (int m = 0; m < 6; ++m)
             s.pre[m][i] = inv[m];
           for (int c = 0; c < 3; ++c) {
             const double bc = pinned ? 0.0 : h * (particles.f(c, pi) + h * kv[c]);
             s.b.c[c][i] = bc;
             sums[0] += bc * bc;
             s.x.c[c][i] = warm && !pinned ? dv[3 * pi + c] : 0.0;
             s.p.c[c][i] = s.x.c[c][i];
           }
         }
       }).first;

  const Clock::time_point assembled = Clock::now();
  // Eigen's ConjugateGradient, line for line (Eigen/src/IterativeLinearSolvers).
  long taken = 0;
  double error = 0.0;
  if (rhs_norm2 == 0.0) {
    for (auto& column : s.x.c)
      std::fill(column.begin(), column.end(), 0.0);
  } else {
    const double threshold =
        std::max(tolerance * tolerance * rhs_norm2, std::numeric_limits<double>::min());
    // r = b - A x (p holds x), z = P^-1 r, p = z.
    s.product(world);
    auto [residual_norm2, abs_new] =
        s.over_chunks(world, [&](size_t begin, size_t end, double* sums) {
          for (size_t i = begin; i < end; ++i) {
            for (int c = 0; c < 3; ++c)
              s.r.c[c][i] = s.b.c[c][i] - s.q.c[c][i];
            s.precondition(i);
            for (int c = 0; c < 3; ++c) {
              sums[0] += s.r.c[c][i] * s.r.c[c][i];
              sums[1] += s.r.c[c][i] * s.z.c[c][i];
              s.p.c[c][i] = s.z.c[c][i];
            }
          }
        });
    while (residual_norm2 >= threshold && taken < max_iterations) {
      const double alpha = abs_new / s.product(world);
      ++taken;
      const auto [rr, rz] = s.over_chunks(world, [&](size_t begin, size_t end, double* sums) {
        for (size_t i = begin; i < end; ++i) {
          for (int c = 0; c < 3; ++c) {
            s.x.c[c][i] += alpha * s.p.c[c][i];
            s.r.c[c][i] -= alpha * s.q.c[c][i];
          }
          s.precondition(i);
          for (int c = 0; c < 3; ++c) {
            sums[0] += s.r.c[c][i] * s.r.c[c][i];
            sums[1] += s.r.c[c][i] * s.z.c[c][i];
          }
        }
      });
      residual_norm2 = rr;
      if (residual_norm2 < threshold) break;
      const double beta = rz / abs_new;
      abs_new = rz;
      s.over_chunks(world, [&](size_t begin, size_t end, double* /*sums*/) {
        for (size_t i = begin; i < end; ++i) {
          for (int c = 0; c < 3; ++c)
            s.p.c[c][i] = s.z.c[c][i] + beta * s.p.c[c][i];
        }
      });
    }
    error = std::sqrt(residual_norm2 / rhs_norm2);
  }

  ++stats.solves;
  stats.iterations += taken;
  stats.max_iterations = std::max(stats.max_iterations, taken);
  stats.worst_error = std::max(stats.worst_error, error);
  if (error > tolerance) ++stats.unconverged;

  // v' = v + dv, x' = x + h v'; dv kept for the next step's start.
  if (!warm) dv.resize(3 * n);
  s.over_chunks(world, [&](size_t begin, size_t end, double* /*sums*/) {
    for (size_t i = begin; i < end; ++i) {
      const Index pi = static_cast<Index>(i);
      for (int c = 0; c < 3; ++c) {
        dv[3 * pi + c] = s.x.c[c][i];
        particles.v(c, pi) += s.x.c[c][i];
        particles.x(c, pi) += h * particles.v(c, pi);
      }
    }
  });
  const Clock::time_point solved = Clock::now();
  stats.assembly_seconds += std::chrono::duration<double>(assembled - started).count();
  stats.solve_seconds += std::chrono::duration<double>(solved - assembled).count();
  return true;
}

}  // namespace clothlab::fast
