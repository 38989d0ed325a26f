#include "fast/engine.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/integrators/euler.hpp"
#include "fast/float_room.hpp"
#include "fast/resident.hpp"

namespace clothlab::fast {

namespace {

// Particles [begin, end) moved by their own forces with the one-particle kernel, on the engine's
// layout: ExplicitEuler::advance's loop on a range. `flatten`: the kernel inlined at link time.
template <class Kernel>
[[gnu::flatten]] void move_particles(Particles& p, Index begin, Index end, double dt,
                                     Kernel kernel) {
  for (Index i = begin; i < end; ++i) {
    const PointState next = kernel(p.x.col(i), p.v.col(i), p.f.col(i), p.inv_m[i], dt);
    p.x.col(i) = next.r;
    p.v.col(i) = next.v;
  }
}

// The same moves, the kernel's inputs read from the copies, where component c of particle i
// sits at x[c nx + i]: the compiler then takes several particles at once with vector
// instructions, which the loop above, on x, y and z side by side, does not allow. The same
// operations on the same values: the same bits. The forces go to the engine's layout (f_out)
// with the new state, and when `Check`, the new state is tested against the guard's bounds on
// the values in hand as they are written, where a pass of its own would read them again
// (Guard::within's test: |x| <= max_position, |v| <= max_speed, each component, false for a
// NaN); the result is whether all are within. The pointers are declared not to overlap (the
// outputs are the particles' own x, v and f, the inputs the copies), so the function is kept
// out of line.
template <bool Check, class Kernel>
[[gnu::noinline, gnu::flatten]] bool move_particles_from_copies(
    Index begin, Index end, double dt, Kernel kernel, const double* __restrict x, Index nx,
    const double* __restrict v, Index nv, const double* __restrict f, Index nf,
    const double* __restrict inv_m, double* __restrict x_out, double* __restrict v_out,
    double* __restrict f_out, double max_position, double max_speed) {
  long outside = 0;
  for (Index i = begin; i < end; ++i) {
    // Not const: GCC 12 does not split a const aggregate into its six doubles, and the loop
    // then goes one particle at a time through the stack (three times slower).
    PointState next =
        kernel(Vec3(x[i], x[nx + i], x[2 * nx + i]), Vec3(v[i], v[nv + i], v[2 * nv + i]),
               Vec3(f[i], f[nf + i], f[2 * nf + i]), inv_m[i], dt);
    for (int c = 0; c < 3; ++c) {
      x_out[3 * i + c] = next.r[c];
      v_out[3 * i + c] = next.v[c];
      f_out[3 * i + c] = f[c * nf + i];
      if constexpr (Check)
        outside += !(std::abs(next.r[c]) <= max_position) + !(std::abs(next.v[c]) <= max_speed);
    }
  }
  return outside == 0;
}

// The same moves into the other copy of the state, for a run of steps that keeps it in the
// fast layout (resident.hpp): the new x and v to next's rows (x_out, v_out, strides nxo and nvo),
// tested against the guard's bounds as above; the forces stay in the copies.
template <class Kernel>
[[gnu::noinline, gnu::flatten]] bool move_particles_resident(
    Index begin, Index end, double dt, Kernel kernel, const double* __restrict x, Index nx,
    const double* __restrict v, Index nv, const double* __restrict f, Index nf,
    const double* __restrict inv_m, double* __restrict x_out, Index nxo, double* __restrict v_out,
    Index nvo, double max_position, double max_speed) {
  long outside = 0;
  for (Index i = begin; i < end; ++i) {
    PointState next =  // not const: see above
        kernel(Vec3(x[i], x[nx + i], x[2 * nx + i]), Vec3(v[i], v[nv + i], v[2 * nv + i]),
               Vec3(f[i], f[nf + i], f[2 * nf + i]), inv_m[i], dt);
    for (int c = 0; c < 3; ++c) {
      x_out[c * nxo + i] = next.r[c];
      v_out[c * nvo + i] = next.v[c];
      outside += !(std::abs(next.r[c]) <= max_position) + !(std::abs(next.v[c]) <= max_speed);
    }
  }
  return outside == 0;
}

// A contact's response on particles [begin, end), the lecture's loop (Ground::collide,
// Sphere::collide) called from here with `flatten`, so that the loop and the exercise's
// collision_response are inlined at link time. GCC otherwise calls collision_response once per
// particle in contact: perf put 10 % of a step with a ground in that call (SPEED.md).
template <class Collider>
[[gnu::flatten]] void collide_range(const Collider& collider, Particles& p, Index begin,
                                    Index end) {
  collider.collide(p, begin, end);
}

// The contacts of a run of steps (FastEngine::steps) on particles [begin, end): each contact in
// the world's order, over the particles, as Ground::collide and Sphere::collide take them (their
// contact() on each free particle inside), from the state the move left in the next copies
// (x_out, v_out) and the step's start in the copies it read (x0, v0: what the effects'
// before_step records). Returns whether any particle met one. `flatten`, as collide_range, for
// the exercise's kernel. A particle above the ground is tested on its height alone (contact()
// finds the same), without loading the rest of its state.
[[gnu::noinline, gnu::flatten]] bool contacts_resident(
    Index begin, Index end, const std::vector<Contact>& contacts, const double* __restrict inv_m,
    const double* __restrict x0, Index nx0, const double* __restrict v0, Index nv0,
    double* __restrict x_out, Index nxo, double* __restrict v_out, Index nvo) {
  bool met = false;
  const auto meet = [&](Index i, const auto& collider) {
    Vec3 x(x_out[i], x_out[nxo + i], x_out[2 * nxo + i]);
    Vec3 v(v_out[i], v_out[nvo + i], v_out[2 * nvo + i]);
    const Vec3 start_x(x0[i], x0[nx0 + i], x0[2 * nx0 + i]);
    const Vec3 start_v(v0[i], v0[nv0 + i], v0[2 * nv0 + i]);
    if (!collider.contact(x, v, true, start_x, start_v)) return;
    for (int c = 0; c < 3; ++c) {
      x_out[c * nxo + i] = x[c];
      v_out[c * nvo + i] = v[c];
    }
    met = true;
  };
  for (const Contact& contact : contacts) {
    if (contact.ground) {
      const double y0 = contact.ground->y0();
      for (Index i = begin; i < end; ++i) {
        if (y0 - x_out[nxo + i] > 0.0 && inv_m[i] != 0.0) meet(i, *contact.ground);
      }
    }
    if (contact.sphere) {
      for (Index i = begin; i < end; ++i) {
        if (inv_m[i] != 0.0) meet(i, *contact.sphere);
      }
    }
  }
  return met;
}

// Guard::within on particles [begin, end) of the copies' rows x and v (as move_particles_resident
// tests them).
bool within_rows(Index begin, Index end, const double* x, Index nx, const double* v, Index nv,
                 double max_position, double max_speed) {
  long outside = 0;
  for (int c = 0; c < 3; ++c) {
    for (Index i = begin; i < end; ++i) {
      outside +=
          !(std::abs(x[c * nx + i]) <= max_position) + !(std::abs(v[c * nv + i]) <= max_speed);
    }
  }
  return outside == 0;
}

// The Euler methods' one-particle kernels, each a type of its own, so that every loop given one
// is compiled for it, the kernel inlined: the step's pass (euler_move) and a run of steps
// (FastEngine::steps) call the same two.
constexpr auto kExplicitEuler = [](const Vec3& r, const Vec3& v, const Vec3& f, double inv_m,
                                   double h) { return explicit_euler_step(r, v, f, inv_m, h); };
constexpr auto kSymplecticEuler = [](const Vec3& r, const Vec3& v, const Vec3& f, double inv_m,
                                     double h) { return symplectic_euler_step(r, v, f, inv_m, h); };

// An Euler method's move of particles [begin, end) (FastEngine::MoveRange), from the copies
// when it has them. The kernels come wrapped in lambdas, each a type of its own, so that each
// loop is compiled for its kernel, inlined.
template <class Kernel>
FastEngine::MoveRange euler_move(Particles& p, double dt, Kernel kernel) {
  return [&p, dt, kernel](Index begin, Index end, const Copies* copies, const Guard* guard) {
    if (!copies) {
      move_particles(p, begin, end, dt, kernel);
      return !guard || guard->within(p.x, p.v, begin, end);
    }
    const auto move = guard ? move_particles_from_copies<true, Kernel>
                            : move_particles_from_copies<false, Kernel>;
    return move(begin, end, dt, kernel, copies->x.data(), copies->x.cols(), copies->v.data(),
                copies->v.cols(), copies->f.data(), copies->f.cols(), p.inv_m.data(), p.x.data(),
                p.v.data(), p.f.data(), guard ? guard->max_position : 0.0,
                guard ? guard->max_speed : 0.0);
  };
}

}  // namespace

bool FastEngine::prepare(const World& world) {
  const auto& effects = world.force_effects;
  forces_.resize(effects.size());
  bool any = false;
  for (size_t e = 0; e < effects.size(); ++e) {
    Force& force = forces_[e];
    force.match(*effects[e], fast_force);
    force.on = force.fast && force.fast->prepare(world.particles);
    any = any || force.on;
  }
  return any;
}

std::string FastEngine::plan() const {
  std::string names;
  for (const Force& force : forces_) {
    if (!names.empty()) names += ' ';
    names += std::string(force.effect->name()) + (force.on ? "+" : "-");
  }
  return names;
}

size_t FastEngine::stencil_springs() const {
  size_t n = 0;
  for (const Force& force : forces_) {
    if (force.on) n += force.fast->stencil_springs();
  }
  return n;
}

bool FastEngine::sum_forces(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f) {
  if (!prepare(world)) return false;
  pass(world, x, v, f);
  return true;
}

bool FastEngine::potential_energy(const World& world, const ForceEffect& effect, const Matrix3X& x,
                                  double& energy) {
  // The effect's place in the world's list, and its fast form there (made if not yet).
  const auto& effects = world.force_effects;
  forces_.resize(effects.size());
  for (size_t e = 0; e < effects.size(); ++e) {
    if (effects[e].get() != &effect) continue;
    Force& force = forces_[e];
    force.match(effect, fast_force);
    return force.fast && force.fast->potential_energy(world, x, energy);
  }
  return false;
}

BackendStep FastEngine::step(World& world, double dt) {
  if (precision == Precision::float32) {
    if (!float_room_) float_room_ = std::make_shared<FloatRoom>();
    return float_room_->step(world, dt);
  }
  // Only the Euler methods move each particle by its own force alone, after one evaluation.
  const Integrator* integrator = world.integrator.get();
  const bool explicit_euler = dynamic_cast<const ExplicitEuler*>(integrator) != nullptr;
  if (!explicit_euler && !dynamic_cast<const SymplecticEuler*>(integrator)) return {};
  if (!prepare(world)) return {};
  // The post-step effects that change each particle from its own state alone and lead the
  // world's list ride along: each range meets them right after it moves, in the list's order,
  // as it would in passes of their own. The others follow the step (World::step).
  contacts_.clear();
  starts_.clear();
  for (const auto& effect : world.post_step_effects) {
    if (auto* ground = dynamic_cast<Ground*>(effect.get())) {
      contacts_.push_back({ground, nullptr});
      starts_.push_back(&ground->step_start());
    } else if (auto* sphere = dynamic_cast<Sphere*>(effect.get())) {
      contacts_.push_back({nullptr, sphere});
      starts_.push_back(&sphere->step_start());
    } else {
      break;
    }
  }
  Particles& p = world.particles;
  // What the post-step effects record of the state the step starts from (World::record_step_start,
  // which World::step leaves to a backend that takes the step): the contacts that ride along
  // have each thread record its own particles in the pass, before anything moves, where a copy
  // of the whole state on this thread would come first; the effects after them record here.
  for (StepStart* start : starts_)
    start->resize(p.size());
  for (size_t k = contacts_.size(); k < world.post_step_effects.size(); ++k)
    world.post_step_effects[k]->before_step(world);
  const MoveRange move =
      explicit_euler ? euler_move(p, dt, kExplicitEuler) : euler_move(p, dt, kSymplecticEuler);
  MoveRange move_then_contacts;
  const MoveRange* moves = &move;
  if (!contacts_.empty()) {
    // The guard's test after the contacts, on the state they leave.
    move_then_contacts = [&](Index begin, Index end, const Copies* copies, const Guard* guard) {
      move(begin, end, copies, nullptr);
      for (const Contact& contact : contacts_) {
        if (contact.ground) collide_range(*contact.ground, p, begin, end);
        if (contact.sphere) collide_range(*contact.sphere, p, begin, end);
      }
      return !guard || guard->within(p.x, p.v, begin, end);
    };
    moves = &move_then_contacts;
  }
  PassChecks checks;
  checks.starts = &starts_;
  checks.end = contacts_.size() == world.post_step_effects.size();
  pass(world, p.x, p.v, p.f, moves, &checks);
  ++world.force_evaluations;
  ++world.backend_evaluations;
  return {true, contacts_.size(), checks.end_checked && checks.end_within};
}

BackendSteps FastEngine::steps(World& world, double dt, long count) {
  if (count <= 0) return {};
  if (precision == Precision::float32) {
    if (!float_room_) float_room_ = std::make_shared<FloatRoom>();
    return float_room_->steps(world, dt, count);
  }
  // Post-step effects ride along only if all are contacts (the ground, spheres): each moved
  // particle meets them in the world's order, from the state the step began with, which the
  // copies the step reads still hold. Any other (moving pins, tearing, a plane) needs the
  // world's layout between two steps: the world takes them one at a time.
  resident_contacts_.clear();
  for (const auto& effect : world.post_step_effects) {
    if (auto* ground = dynamic_cast<Ground*>(effect.get())) {
      resident_contacts_.push_back({ground, nullptr});
    } else if (auto* sphere = dynamic_cast<Sphere*>(effect.get())) {
      resident_contacts_.push_back({nullptr, sphere});
    } else {
      return {};
    }
  }
  const Integrator* integrator = world.integrator.get();
  const bool explicit_euler = dynamic_cast<const ExplicitEuler*>(integrator) != nullptr;
  if (!explicit_euler && !dynamic_cast<const SymplecticEuler*>(integrator)) return {};
  if (!prepare(world)) return {};
  for (const Force& force : forces_) {
    if (!force.on) return {};  // an effect without a fast form needs the world's layout
  }
  const Particles& p = world.particles;
  const auto add = [&](Index b0, Index b1, const SoA3& x, const SoA3& v, SoA3& f) {
    for (const Force& force : forces_)
      force.fast->add(p, x, v, f, b0, b1);
  };
  const double max_position = world.guard.max_position, max_speed = world.guard.max_speed;
  const auto moves = [&](auto kernel) {
    return [&, kernel](Index c0, Index c1, const Copies& now, Copies& next) {
      const bool within = move_particles_resident(
          c0, c1, dt, kernel, now.x.data(), now.x.cols(), now.v.data(), now.v.cols(), now.f.data(),
          now.f.cols(), p.inv_m.data(), next.x.data(), next.x.cols(), next.v.data(), next.v.cols(),
          max_position, max_speed);
      if (resident_contacts_.empty()) return within;
      if (!contacts_resident(c0, c1, resident_contacts_, p.inv_m.data(), now.x.data(), now.x.cols(),
                             now.v.data(), now.v.cols(), next.x.data(), next.x.cols(),
                             next.v.data(), next.v.cols()))
        return within;  // nothing met them: the move's state, as it tested it
      // The guard's test after the contacts, on the state they leave.
      return within_rows(c0, c1, next.x.data(), next.x.cols(), next.v.data(), next.v.cols(),
                         max_position, max_speed);
    };
  };
  const Index block = std::max<Index>(pass_block, 1);
  if (explicit_euler)
    return resident_steps(world, dt, count, resident_, block, kPassChunk, add,
                          moves(kExplicitEuler));
  return resident_steps(world, dt, count, resident_, block, kPassChunk, add,
                        moves(kSymplecticEuler));
}

void FastEngine::pass(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f,
                      const MoveRange* move, PassChecks* checks) {
  const auto& effects = world.force_effects;
  const Index n = x.cols();
  Copies& c = copies_;
  c.resize(n);
  f.resize(3, n);
  // The effects with a fast form that lead the world's list share one job of the threads with
  // the copies: each thread copies its particles, waits at the barrier until every thread has
  // (a spring at the border of two ranges reads the other range's x and v), then lets every one
  // of those effects add its forces on its own particles. When they are the whole list, it then
  // moves its particles (move) or copies their forces back (a sum alone): one wake of the
  // threads for all of it. Later effects take passes of their own (below).
  size_t lead = 0;
  while (lead < effects.size() && forces_[lead].on)
    ++lead;
  const bool all_fast = lead == effects.size();
  const bool check_end = all_fast && move && checks && checks->end;
  std::atomic<bool> start_within = true, end_within = true;
  // Particles [begin, end) summed and moved block by block (pass_block): every effect adds its
  // forces on the block, then the block moves, while its x, v and f are still in the cache.
  // These particles' forces are final: no other block or thread adds to them. The others read x
  // and v from the copies, so moving these in x and v changes nothing they see.
  const auto sum_and_move = [&](Index begin, Index end) {
    const Particles& p = world.particles;
    const Index block = std::max<Index>(pass_block, 1);
    for (Index b0 = begin; b0 < end; b0 += block) {
      const Index b1 = std::min(b0 + block, end);
      for (const Force& force : forces_)
        force.fast->add(p, c.x, c.v, c.f, b0, b1);
      for (Index c0 = b0; c0 < b1; c0 += kPassChunk) {
        const Index c1 = std::min(c0 + kPassChunk, b1);
        if (!(*move)(c0, c1, &c, check_end ? &world.guard : nullptr)) end_within = false;
      }
    }
  };
  world.for_particles_with_barrier([&](Index begin, Index end, const Barrier& barrier) {
    if (!checks) {
      to_soa(begin, end, x.data(), c.x.data(), c.x.cols());
      to_soa(begin, end, v.data(), c.v.data(), c.v.cols());
    } else {
      const bool x_within =
          to_soa_within(begin, end, x.data(), c.x.data(), c.x.cols(), world.guard.max_position);
      const bool v_within =
          to_soa_within(begin, end, v.data(), c.v.data(), c.v.cols(), world.guard.max_speed);
      if (!x_within || !v_within) start_within = false;
      if (checks->starts) {
        for (StepStart* start : *checks->starts)
          start->record(x, v, begin, end);
      }
    }
    c.f.middleCols(begin, end - begin).setZero();
    if (lead == 0) return;
    barrier.wait();
    // A bad state stops every thread here, before anything moves (the guard's error follows).
    if (!start_within) return;
    if (all_fast && move) {
      sum_and_move(begin, end);
      return;
    }
    for (size_t k = 0; k < lead; ++k)
      forces_[k].fast->add(world.particles, c.x, c.v, c.f, begin, end);
    if (all_fast) from_soa(begin, end, c.f.data(), c.f.cols(), f.data());
  });
  // The step's state was bad before it began: the guard names the particle and throws, before
  // anything moves.
  if (!start_within) world.guard.check(world, /*before_step=*/true);
  if (check_end) {
    checks->end_checked = true;
    checks->end_within = end_within;
  }
  if (all_fast) return;
  const auto move_f = [&](bool soa) {
    world.for_particles([&](Index begin, Index end) {
      if (soa) {
        to_soa(begin, end, f.data(), c.f.data(), c.f.cols());
      } else {
        from_soa(begin, end, c.f.data(), c.f.cols(), f.data());
      }
    });
  };
  // The rest of the effects in the world's order; f moves to whichever layout the next effect
  // works on. Consecutive effects with a fast form share one pass of the threads: each thread
  // lets every one of them add its forces on the thread's own particles.
  bool in_soa = true;
  for (size_t e = lead; e < effects.size();) {
    if (!forces_[e].on) {
      if (in_soa) move_f(false);
      in_soa = false;
      effects[e]->add_forces(world.particles, x, v, f);
      ++e;
      continue;
    }
    size_t last = e + 1;
    while (last < effects.size() && forces_[last].on)
      ++last;
    if (!in_soa) move_f(true);
    in_soa = true;
    world.for_particles([&](Index begin, Index end) {
      for (size_t k = e; k < last; ++k)
        forces_[k].fast->add(world.particles, c.x, c.v, c.f, begin, end);
    });
    e = last;
  }
  if (in_soa) move_f(false);
  if (move) {
    world.for_particles([&](Index begin, Index end) { (*move)(begin, end, nullptr, nullptr); });
  }
}

std::unique_ptr<Backend> make_fast_engine() {
  return std::make_unique<FastEngine>();
}

}  // namespace clothlab::fast
