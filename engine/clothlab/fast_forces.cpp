#include "clothlab/fast_forces.hpp"

#include "clothlab/threads.hpp"
#include "clothlab/world.hpp"

namespace clothlab {

bool prepare_fast_forces(const World& world, FastScratch& scratch) {
  const auto& effects = world.force_effects;
  scratch.soa.resize(effects.size());
  bool any = false;
  for (size_t e = 0; e < effects.size(); ++e) {
    scratch.soa[e] = effects[e]->adds_soa(world.particles);
    any = any || scratch.soa[e];
  }
  return any;
}

void fast_forces(const World& world, const Matrix3X& x, const Matrix3X& v, Matrix3X& f,
                 FastScratch& scratch, ThreadTeam* team) {
  const auto& effects = world.force_effects;
  const Index n = x.cols();
  scratch.x.resize(3, n);
  scratch.v.resize(3, n);
  scratch.f.resize(3, n);
  f.resize(3, n);
  // Eigen copies between the two storage orders, transposing as it goes.
  for_ranges(team, n, [&](Index begin, Index end) {
    scratch.x.middleCols(begin, end - begin) = x.middleCols(begin, end - begin);
    scratch.v.middleCols(begin, end - begin) = v.middleCols(begin, end - begin);
    scratch.f.middleCols(begin, end - begin).setZero();
  });
  const auto move_f = [&](bool to_soa) {
    for_ranges(team, n, [&](Index begin, Index end) {
      if (to_soa) {
        scratch.f.middleCols(begin, end - begin) = f.middleCols(begin, end - begin);
      } else {
        f.middleCols(begin, end - begin) = scratch.f.middleCols(begin, end - begin);
      }
    });
  };
  // The effects in the world's order; f moves to whichever layout the next effect works on.
  bool in_soa = true;
  for (size_t e = 0; e < effects.size(); ++e) {
    if (scratch.soa[e]) {
      if (!in_soa) move_f(true);
      in_soa = true;
      effects[e]->add_forces_soa(world.particles, scratch.x, scratch.v, scratch.f, team);
    } else {
      if (in_soa) move_f(false);
      in_soa = false;
      effects[e]->add_forces(world.particles, x, v, f);
    }
  }
  if (in_soa) move_f(false);
}

}  // namespace clothlab
