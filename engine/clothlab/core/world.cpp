#include "clothlab/core/world.hpp"

#include <algorithm>
#include <cassert>
#include <stdexcept>

#include <fmt/format.h>

namespace clothlab {

namespace {

// A thread's particles start at a multiple of 16 once a pass has moved the split: 16
// particles are 6 cache lines in the engine's layout (3 doubles each) and 2 or 1 in each row of
// the fast engine's copies (doubles, floats), so no line is written by two threads.
constexpr Index kBoundAlign = 16;
// The imbalance a pass leaves alone: the busiest thread within 3 % of the mean is timing noise
// as often as not.
constexpr double kBalanceTolerance = 0.03;

}  // namespace

void World::step(double dt) {
  assert(integrator && "a world needs an integrator before it can step");
  if (steps == 0) guard.start(*this);
  for (const auto& effect : force_effects)
    effect->set_time(t);  // what changes in time takes its value at the step's start
  // The backend may take the step, or part of it, its own way with the same bits (backend.hpp),
  // checking the state as it goes; it says what it took, and the world does the rest.
  const BackendStep taken = backend ? backend->step(*this, dt) : BackendStep{};
  if (!taken.taken) {
    record_step_start();  // what needs the state the step starts from records it
    {
      const auto timed = lap(timer, &StepTimes::guard);
      guard.check(*this, /*before_step=*/true);  // the guard: the state the step starts from
    }
    const auto timed = lap(timer, &StepTimes::integrator);
    integrator->advance(*this, dt);  // 1-3: the integrator sums forces (compute_forces) and moves
  }
  // 4: collisions, plasticity, tearing, ...: a contact closes the integrator's last substep,
  // every other effect the whole step (the substep contract, world.hpp).
  const StepTime whole = StepTime::whole(t, dt);
  const int n = integrator->substeps_per_step();
  const StepTime last_substep = StepTime::of_substep(t, dt, n - 1, n);
  for (size_t k = taken.post_step_done; k < post_step_effects.size(); ++k) {
    const auto timed = lap(timer, k, post_step_effects.size());
    PostStepEffect& effect = *post_step_effects[k];
    effect.apply(*this, effect.each_substep() ? last_substep : whole);
  }
  t += dt;
  ++steps;
  const bool checked = taken.checked_after && taken.post_step_done == post_step_effects.size();
  if (!checked) {
    const auto timed = lap(timer, &StepTimes::guard);
    guard.check(*this, /*before_step=*/false);  // 5: the guard: the state the step ends with
  }
  if (steps % guard.energy_check_every == 0) guard.check_energy(*this);
}

void World::advance(double dt, long count) {
  while (count > 0) {
    // The first step starts the guard; a timed step (--stats) stays the world's own, and so do
    // the steps of a world whose post-step effects the backend cannot take (it declines).
    if (steps == 0 || !backend || timer) {
      step(dt);
      --count;
      continue;
    }
    // As far as the guard's next energy check, which reads the world's state.
    const long every = std::max(1L, guard.energy_check_every);
    const BackendSteps taken = backend->steps(*this, dt, std::min(count, every - steps % every));
    if (taken.taken == 0) {  // declined: the rest one step at a time
      for (; count > 0; --count)
        step(dt);
      return;
    }
    count -= taken.taken;
    if (!taken.within) guard.check(*this, /*before_step=*/false);  // names the particle, throws
    if (steps % every == 0) guard.check_energy(*this);
  }
}

void World::record_step_start() {
  for (const auto& effect : post_step_effects)
    effect->before_step(*this);
}

ThreadTeam* World::team() const {
  if (threads <= 1) return nullptr;
  if (!team_ || team_->size() != threads) team_ = std::make_unique<ThreadTeam>(threads);
  return team_.get();
}

void World::compute_forces(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const {
  if (backend && backend->sum_forces(*this, x, v, f)) {
    ++force_evaluations;
    ++backend_evaluations;
  } else if (timer) {
    timer->sum_forces(*this, x, v, f);  // --stats: the loop below, each effect timed
  } else {
    compute_forces_readable(x, v, f);
  }
}

const std::vector<Index>& World::particle_bounds() const {
  const auto parts = static_cast<size_t>(std::max(1, threads));
  if (particle_bounds_.size() != parts + 1 || particle_bounds_.back() != particles.size())
    particle_bounds_ = even_bounds(particles.size(), static_cast<int>(parts));
  return particle_bounds_;
}

void World::set_particle_bounds(std::vector<Index> bounds) {
  const auto parts = static_cast<size_t>(std::max(1, threads));
  bool ordered =
      bounds.size() == parts + 1 && bounds.front() == 0 && bounds.back() == particles.size();
  for (size_t k = 1; ordered && k < bounds.size(); ++k)
    ordered = bounds[k - 1] <= bounds[k];
  if (!ordered) {
    throw std::invalid_argument(fmt::format(
        "particle bounds: expected {} bounds from 0 to {}, each at least the one before", parts + 1,
        particles.size()));
  }
  particle_bounds_ = std::move(bounds);
}

void World::for_particles(const std::function<void(Index begin, Index end)>& range) const {
  for_bounds(team(), particle_bounds(), range);
}

void World::for_particles_with_barrier(
    const std::function<void(Index begin, Index end, const Barrier& barrier)>& range) const {
  ThreadTeam* const threads_of_step = team();
  for_ranges_with_barrier(threads_of_step, particle_bounds(), range, thread_profile,
                          threads_of_step ? &pass_work_ : nullptr);
  if (!threads_of_step) return;
  // A bound moves at most a 128th of the cloth a pass: a 10 % shift takes some 25 passes, and a
  // pass that one thread lost to another program moves the split by under 1 %.
  const Index n = particles.size();
  balance_bounds(particle_bounds_, pass_work_, kBoundAlign, std::max(kBoundAlign, n / 128),
                 kBalanceTolerance);
}

void World::for_items(Index n, const std::function<void(Index begin, Index end)>& range) const {
  for_ranges(team(), n, range);
}

void World::compute_forces_readable(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const {
  f.setZero();
  ++force_evaluations;
  for (const auto& effect : force_effects)
    effect->add_forces(particles, x, v, f);
}

double World::kinetic_energy() const {
  // 1/2 m |v|^2 summed: colwise().squaredNorm() gives |v_i|^2 for every particle at once.
  return 0.5 * particles.m.dot(particles.v.colwise().squaredNorm().transpose());
}

double World::potential_energy(std::vector<double>* each) const {
  if (each) each->clear();
  double energy = 0.0;
  for (const auto& effect : force_effects) {
    // The backend may compute an effect's energy faster, to the same bits (backend.hpp).
    double e = 0.0;
    if (!backend || !backend->potential_energy(*this, *effect, particles.x, e))
      e = effect->potential_energy(particles, particles.x);
    energy += e;
    if (each) each->push_back(e);
  }
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
