#include "clothlab/world.hpp"

#include <cassert>
#include <chrono>
#include <utility>

#include "clothlab/fast_forces.hpp"

namespace clothlab {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}
}  // namespace

void World::step(double dt) {
  assert(integrator && "a world needs an integrator before it can step");
  if (steps == 0) guard.start(*this);
  if (!timing) {
    // The state the step starts from: the last step left it valid, but code between steps may
    // have changed it. The guard checks it (one vectorised pass) and names the particle before
    // a NaN can spread. An integrator that moves every particle in one pass has that pass check
    // each particle before anything moves, and after moving it when nothing else follows
    // (StepChecks): the same checks, without two more passes over the whole state.
    // The post-step effects that act on each particle alone, from the front of the list, go
    // into that pass as well: each range of particles meets them right after it moves, in the
    // order of the list, as it would in passes of their own. The others follow the step.
    step_checks_ = StepChecks{};
    size_t in_pass = 0;
    // It captures `this` alone, so that std::function keeps it without allocating.
    const std::function<void(Index, Index)> after_move = [this](Index begin, Index end) {
      for (size_t k = 0; k < step_checks_.post_in_pass; ++k)
        post_step_effects[k]->apply_range(particles, step_checks_.dt, begin, end);
    };
    if (integrator->moves_in_one_pass()) {
      while (in_pass < post_step_effects.size() && post_step_effects[in_pass]->acts_per_particle())
        ++in_pass;
      step_checks_.armed = true;
      step_checks_.end = in_pass == post_step_effects.size();
      step_checks_.post_in_pass = in_pass;
      step_checks_.dt = dt;
      if (in_pass > 0) step_checks_.after_move = &after_move;
    } else {
      guard.check(*this, /*before_step=*/true);
    }
    integrator->advance(*this, dt);  // calls compute_forces (steps 1-2) as often as it needs
    assert(!step_checks_.armed &&
           "moves_in_one_pass, but advance did not call compute_forces_then");
    step_checks_.after_move = nullptr;
    for (size_t k = in_pass; k < post_step_effects.size(); ++k)
      post_step_effects[k]->apply(*this, dt);
    t += dt;
    ++steps;
    if (!(step_checks_.end_checked && step_checks_.end_within)) guard.check(*this);
    if (steps % guard.energy_check_every == 0) guard.check_energy(*this);
    return;
  }
  guard.check(*this, /*before_step=*/true);
  // The same step, timed part by part (for --stats).
  timing->force_effects.resize(force_effects.size(), 0.0);
  timing->post_step_effects.resize(post_step_effects.size(), 0.0);
  double forces_before = 0.0;
  for (double s : timing->force_effects)
    forces_before += s;
  Clock::time_point start = Clock::now();
  integrator->advance(*this, dt);
  double forces_after = 0.0;
  for (double s : timing->force_effects)
    forces_after += s;
  timing->integrator += seconds_since(start) - (forces_after - forces_before);
  for (size_t k = 0; k < post_step_effects.size(); ++k) {
    start = Clock::now();
    post_step_effects[k]->apply(*this, dt);
    timing->post_step_effects[k] += seconds_since(start);
  }
  t += dt;
  ++steps;
  start = Clock::now();
  guard.check(*this);
  if (steps % guard.energy_check_every == 0) guard.check_energy(*this);
  timing->guard += seconds_since(start);
}

ThreadTeam* World::team() const {
  if (threads <= 1) return nullptr;
  if (!team_ || team_->size() != threads) team_ = std::make_unique<ThreadTeam>(threads);
  return team_.get();
}

void World::compute_forces(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const {
  if (!takes_fast_path() || !prepare_fast_forces(*this, fast_)) {
    compute_forces_readable(x, v, f);
    return;
  }
  ++force_evaluations;
  ++fast_evaluations;
  fast_forces(*this, x, v, f, fast_, team());
}

void World::compute_forces_then(const Matrix3X& x, const Matrix3X& v, Matrix3X& f,
                                const MoveRange& move) const {
  // The step's own pass (World::step armed its checks): (x, v) is the state it starts from.
  const bool step_pass = std::exchange(step_checks_.armed, false);
  assert((!step_pass || (&x == &particles.x && &v == &particles.v)) &&
         "compute_forces_then of a step moves the particles' own state");
  // The step's post-step effects that ride along (StepChecks::after_move): each range meets
  // them right after it moves.
  MoveRange move_then_after;
  const MoveRange* moves = &move;
  if (step_pass && step_checks_.after_move) {
    move_then_after = [&](Index begin, Index end, const FastScratch* copies) {
      move(begin, end, copies);
      (*step_checks_.after_move)(begin, end);
    };
    moves = &move_then_after;
  }
  if (!takes_fast_path() || !prepare_fast_forces(*this, fast_)) {
    if (step_pass) guard.check(*this, /*before_step=*/true);
    compute_forces_readable(x, v, f);
    for_particles([&](Index begin, Index end) { (*moves)(begin, end, nullptr); });
    return;
  }
  ++force_evaluations;
  ++fast_evaluations;
  fast_forces(*this, x, v, f, fast_, team(), moves, step_pass ? &step_checks_ : nullptr);
}

void World::for_particles(const std::function<void(Index begin, Index end)>& range) const {
  for_ranges(team(), particles.size(), range);
}

void World::compute_forces_readable(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const {
  f.setZero();
  ++force_evaluations;
  if (!timing) {
    for (const auto& effect : force_effects)
      effect->add_forces(particles, x, v, f);
    return;
  }
  timing->force_effects.resize(force_effects.size(), 0.0);
  for (size_t k = 0; k < force_effects.size(); ++k) {
    const Clock::time_point start = Clock::now();
    force_effects[k]->add_forces(particles, x, v, f);
    timing->force_effects[k] += seconds_since(start);
  }
}

double World::kinetic_energy() const {
  // 1/2 m |v|^2 summed: colwise().squaredNorm() gives |v_i|^2 for every particle at once.
  return 0.5 * particles.m.dot(particles.v.colwise().squaredNorm().transpose());
}

double World::potential_energy() const {
  double energy = 0.0;
  for (const auto& effect : force_effects)
    energy += effect->potential_energy(particles, particles.x);
  return energy;
}

Vec3 World::momentum() const {
  return particles.v * particles.m;
}

std::string World::effects_in_play() const {
  std::string names;
  for (const auto& effect : force_effects) {
    if (!names.empty()) names += ", ";
    names += effect->name();
  }
  for (const auto& effect : post_step_effects) {
    if (!names.empty()) names += ", ";
    names += effect->name();
  }
  if (names.empty()) names = "no effects";
  if (integrator) {
    names += "; integrator ";
    names += integrator->name();
  }
  return names;
}

}  // namespace clothlab
