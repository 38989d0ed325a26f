// float_room.cpp: a step of an Euler method in single precision (float_room.hpp).
#include "fast/float_room.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/after_step/moving_pins.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/integrators/euler.hpp"
#include "fast/engine.hpp"
#include "fast/resident.hpp"
#include "fast/scalar_kernels.hpp"

namespace clothlab::fast {

namespace {

// Particles [begin, end) moved by their own forces in float, from the float copies (component c
// of particle i at x[c nx + i]), into the engine's layout (x, y, z side by side, in doubles):
// x_out and v_out the new state, f_out the forces the step summed, as the fast path leaves them.
// Returns whether the new state is within the guard's bounds (Guard::within: |x| <= max_position,
// |v| <= max_speed, each component, false for a NaN), tested on the values in hand as they are
// written, where a pass of its own would read them again (the same test: a float is exactly the
// double it is written as). A function of its own so that its pointers can be declared not to
// overlap: the compiler then takes several particles at once.
template <bool Symplectic>
[[gnu::noinline]] bool move_in_float(Index begin, Index end, float dt, const float* __restrict x,
                                     Index nx, const float* __restrict v, Index nv,
                                     const float* __restrict f, Index nf,
                                     const double* __restrict inv_m, double* __restrict x_out,
                                     double* __restrict v_out, double* __restrict f_out,
                                     double max_position, double max_speed) {
  long outside = 0;
  // Particle i moved by its own force, in float.
  const auto next_of = [&](Index i) {
    const Vec3f fi(f[i], f[nf + i], f[2 * nf + i]);
    const Vec3f xi(x[i], x[nx + i], x[2 * nx + i]);
    const Vec3f vi(v[i], v[nv + i], v[2 * nv + i]);
    const float inv_mi = static_cast<float>(inv_m[i]);
    return Symplectic ? symplectic_euler(xi, vi, fi, inv_mi, dt)
                      : explicit_euler(xi, vi, fi, inv_mi, dt);
  };
#if defined(__wasm_simd128__)
  // The lesson pages' WebAssembly: the new state of up to kPassChunk particles in float rows
  // first (the loop below without its stores into doubles, which Clang vectorises), then into
  // the engine's doubles four particles at a time by hand, tested as they go, f with them
  // (from_float_rows_by_four, copies.hpp). The same numbers, the same test.
  float next_r[3][kPassChunk], next_v[3][kPassChunk];
  for (Index c0 = begin; c0 < end; c0 += kPassChunk) {
    const Index count = std::min(kPassChunk, end - c0);
    for (Index k = 0; k < count; ++k) {
      PointStateOf<float> next = next_of(c0 + k);
      for (int c = 0; c < 3; ++c) {
        next_r[c][k] = next.r[c];
        next_v[c][k] = next.v[c];
      }
    }
    bool within = true;
    const Index by_four = from_float_rows_by_four<true>(count, next_r[0], next_r[1], next_r[2],
                                                        x_out + 3 * c0, max_position, within);
    from_float_rows_by_four<true>(count, next_v[0], next_v[1], next_v[2], v_out + 3 * c0, max_speed,
                                  within);
    from_float_rows_by_four<false>(count, f + c0, f + nf + c0, f + 2 * nf + c0, f_out + 3 * c0, 0.0,
                                   within);
    outside += !within;
    for (Index k = by_four; k < count; ++k) {
      const Index i = c0 + k;
      for (int c = 0; c < 3; ++c) {
        const double r = next_r[c][k], u = next_v[c][k];
        x_out[3 * i + c] = r;
        v_out[3 * i + c] = u;
        f_out[3 * i + c] = f[c * nf + i];
        outside += !(std::abs(r) <= max_position) + !(std::abs(u) <= max_speed);
      }
    }
  }
#else
  for (Index i = begin; i < end; ++i) {
    // Not const, as in the fast path's move: GCC 12 does not split a const aggregate.
    PointStateOf<float> next = next_of(i);
    for (int c = 0; c < 3; ++c) {
      const double r = next.r[c], u = next.v[c];
      x_out[3 * i + c] = r;
      v_out[3 * i + c] = u;
      f_out[3 * i + c] = f[c * nf + i];
      outside += !(std::abs(r) <= max_position) + !(std::abs(u) <= max_speed);
    }
  }
#endif
  return outside == 0;
}

// The largest float at most `bound` (a guard's bound, a double): for any float r, r <= bound
// exactly when r <= float_at_most(bound), NaN and infinities included, so that a float can be
// tested against a double's bound without being widened to double.
float float_at_most(double bound) {
  float f = static_cast<float>(bound);
  if (static_cast<double>(f) > bound)
    f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

// The same move into the other copy of the state, for a run of steps that keeps it in float
// (resident.hpp): the new x and v to next's rows (x_out, v_out, strides nxo and nvo), tested as
// above, but in float, against the bounds rounded down to floats (float_at_most: the same test),
// and with the count of values outside kept as a flag of the floats' width: widening 16 floats to
// doubles, and their tests to 64-bit counts, took more instructions than the move itself; for
// the same reason 1/m comes rounded to float once for the run of steps (inv_m, FloatRoom::inv_m_;
// rounded once or as read, each is the same float). The forces stay in the copies.
template <bool Symplectic>
[[gnu::noinline]] bool move_in_float_resident(
    Index begin, Index end, float dt, const float* __restrict x, Index nx,
    const float* __restrict v, Index nv, const float* __restrict f, Index nf,
    const float* __restrict inv_m, float* __restrict x_out, Index nxo, float* __restrict v_out,
    Index nvo, double max_position, double max_speed) {
  const float max_r = float_at_most(max_position), max_v = float_at_most(max_speed);
  int outside = 0;
  for (Index i = begin; i < end; ++i) {
    const Vec3f fi(f[i], f[nf + i], f[2 * nf + i]);
    const Vec3f xi(x[i], x[nx + i], x[2 * nx + i]);
    const Vec3f vi(v[i], v[nv + i], v[2 * nv + i]);
    PointStateOf<float> next = Symplectic ? symplectic_euler(xi, vi, fi, inv_m[i], dt)
                                          : explicit_euler(xi, vi, fi, inv_m[i], dt);
    for (int c = 0; c < 3; ++c) {
      x_out[c * nxo + i] = next.r[c];
      v_out[c * nvo + i] = next.v[c];
      outside |= static_cast<int>(!(std::abs(next.r[c]) <= max_r)) |
                 static_cast<int>(!(std::abs(next.v[c]) <= max_v));
    }
  }
  return outside == 0;
}

// The names of `effects` the float room does not cover, comma-separated, given what it covers.
template <class Effects, class Covered>
std::string uncovered(const Effects& effects, Covered covered) {
  std::string names;
  for (const auto& effect : effects) {
    if (covered(*effect)) continue;
    if (!names.empty()) names += ", ";
    names += effect->name();
  }
  return names;
}

// The methods and the post-step effects the float room covers.
bool covered(const Integrator* integrator) {
  return !integrator || dynamic_cast<const SymplecticEuler*>(integrator) ||
         dynamic_cast<const ExplicitEuler*>(integrator);
}
bool covered(const PostStepEffect& effect) {
  return dynamic_cast<const Ground*>(&effect) || dynamic_cast<const Plane*>(&effect) ||
         dynamic_cast<const Sphere*>(&effect) || dynamic_cast<const MovingPins*>(&effect);
}

}  // namespace

std::string float_room_declines(const World& world) {
  std::string why;
  if (!covered(world.integrator.get())) why = "the method " + std::string(world.integrator->name());
  std::string effects = uncovered(world.force_effects, [](const ForceEffect& effect) {
    return fast_force_float(effect) != nullptr;
  });
  const std::string after = uncovered(world.post_step_effects,
                                      [](const PostStepEffect& effect) { return covered(effect); });
  if (!after.empty()) effects += (effects.empty() ? "" : ", ") + after;
  if (!effects.empty()) {
    why += (why.empty() ? "" : " and ") +
           std::string(effects.find(',') == std::string::npos ? "the effect " : "the effects ") +
           effects;
  }
  return why;
}

std::string use_float(World& world) {
  auto* engine = dynamic_cast<FastEngine*>(world.backend.get());
  if (!engine) {
    return "float runs in the engine room, and this world has none (fast_path = false, "
           "--readable): the readable engine computes in double only";
  }
  if (const std::string why = float_room_declines(world); !why.empty())
    return "float covers " + std::string(kFloatCovers) + "; this scene has " + why;
  engine->precision = FastEngine::Precision::float32;
  return "";
}

BackendSteps FloatRoom::steps(World& world, double dt, long count) {
  if (count <= 0 || !world.post_step_effects.empty()) return {};
  if (!match_forces(world)) return {};  // step() says what is not covered
  const bool symplectic = dynamic_cast<const SymplecticEuler*>(world.integrator.get()) != nullptr;
  if (!symplectic && !dynamic_cast<const ExplicitEuler*>(world.integrator.get())) return {};
  const Particles& p = world.particles;
  for (const FastForceSlot<float>& force : forces_)
    force.fast->prepare(p);
  inv_m_.assign(p.inv_m.begin(), p.inv_m.end());  // rounded once for the steps (the move's note)
  const auto add = [&](Index b0, Index b1, const SoA3f& x, const SoA3f& v, SoA3f& f) {
    for (const FastForceSlot<float>& force : forces_)
      force.fast->add(p, x, v, f, b0, b1);
  };
  const float h = static_cast<float>(dt);
  const auto move = symplectic ? move_in_float_resident<true> : move_in_float_resident<false>;
  return resident_steps(world, dt, count, resident_, kPassBlock, kPassChunk, add,
                        [&](Index c0, Index c1, const CopiesOf<float>& now, CopiesOf<float>& next) {
                          return move(c0, c1, h, now.x.data(), now.x.cols(), now.v.data(),
                                      now.v.cols(), now.f.data(), now.f.cols(), inv_m_.data(),
                                      next.x.data(), next.x.cols(), next.v.data(), next.v.cols(),
                                      world.guard.max_position, world.guard.max_speed);
                        });
}

bool FloatRoom::match_forces(const World& world) {
  const auto& effects = world.force_effects;
  forces_.resize(effects.size());
  bool all = true;
  for (size_t e = 0; e < effects.size(); ++e) {
    forces_[e].match(*effects[e], fast_force_float);
    all = all && forces_[e].fast;
  }
  return all;
}

BackendStep FloatRoom::step(World& world, double dt) {
  // A world that holds something not covered (added since the scene loaded) stops here.
  bool all_covered = match_forces(world) && covered(world.integrator.get());
  for (const auto& effect : world.post_step_effects)
    all_covered = all_covered && covered(*effect);
  if (!all_covered) {
    throw std::logic_error("precision = \"float\" covers " + std::string(kFloatCovers) +
                           "; this world has " + float_room_declines(world));
  }
  Particles& p = world.particles;
  world.record_step_start();  // the step is taken: the post-step effects' record (backend.hpp)
  for (const FastForceSlot<float>& force : forces_)
    force.fast->prepare(p);  // float spring forms take every set (springs.cpp)
  const bool symplectic = dynamic_cast<const SymplecticEuler*>(world.integrator.get()) != nullptr;
  const Index n = p.size();
  CopiesOf<float>& c = copies_;
  c.resize(n);
  p.f.resize(3, n);
  // One job of the threads, as the fast path's pass (FastEngine::pass): 1. x and v rounded into
  // the copies, checked for the guard as they go, f cleared; then, once every thread has copied
  // its particles (a spring at a border reads the other range's), 2-3. block by block, every
  // effect adds its forces on the block, then the block moves, and is checked.
  const float h = static_cast<float>(dt);
  const auto move = symplectic ? move_in_float<true> : move_in_float<false>;
  std::atomic<bool> start_within = true, end_within = true;
  world.for_particles_with_barrier([&](Index begin, Index end, const Barrier& barrier) {
    const bool x_within =
        to_soa_within(begin, end, p.x.data(), c.x.data(), c.x.cols(), world.guard.max_position);
    const bool v_within =
        to_soa_within(begin, end, p.v.data(), c.v.data(), c.v.cols(), world.guard.max_speed);
    if (!x_within || !v_within) start_within = false;
    c.f.middleCols(begin, end - begin).setZero();
    barrier.wait();
    if (!start_within) return;  // nothing moves; the guard's error follows
    for (Index b0 = begin; b0 < end; b0 += kPassBlock) {
      const Index b1 = std::min(b0 + kPassBlock, end);
      for (const FastForceSlot<float>& force : forces_)
        force.fast->add(p, c.x, c.v, c.f, b0, b1);
      for (Index c0 = b0; c0 < b1; c0 += kPassChunk) {
        const Index c1 = std::min(c0 + kPassChunk, b1);
        if (!move(c0, c1, h, c.x.data(), c.x.cols(), c.v.data(), c.v.cols(), c.f.data(), c.f.cols(),
                  p.inv_m.data(), p.x.data(), p.v.data(), p.f.data(), world.guard.max_position,
                  world.guard.max_speed))
          end_within = false;
      }
    }
  });
  if (!start_within) world.guard.check(world, /*before_step=*/true);
  ++world.force_evaluations;
  ++world.backend_evaluations;
  return {true, 0, end_within};
}

}  // namespace clothlab::fast
