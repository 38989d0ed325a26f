#include "clothlab/world.hpp"

#include <cassert>

namespace clothlab {

void World::step(double dt) {
  assert(integrator && "a world needs an integrator before it can step");
  integrator->advance(*this, dt);  // calls compute_forces (steps 1-2) as often as it needs
  for (const auto& effect : post_step_effects)
    effect->apply(particles, dt);
  t += dt;
  ++steps;
  guard.check(*this);
}

void World::compute_forces(const Matrix3X& x, const Matrix3X& v, Matrix3X& f) const {
  f.setZero();
  for (const auto& effect : force_effects)
    effect->add_forces(particles, x, v, f);
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
