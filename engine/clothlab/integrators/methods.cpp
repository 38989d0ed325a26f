#include "clothlab/integrators/methods.hpp"

#include <array>

#include "clothlab/integrators/euler.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/local_global.hpp"
#include "clothlab/integrators/runge_kutta.hpp"
#include "clothlab/integrators/vbd.hpp"
#include "clothlab/integrators/verlet.hpp"
#include "clothlab/integrators/xpbd.hpp"

namespace clothlab {

namespace {

struct Method {
  std::string_view name;                  // as a scene writes it, and as the method's name()
  std::unique_ptr<Integrator> (*make)();  // a new integrator of this method
};

template <class Integrator>
std::unique_ptr<clothlab::Integrator> make() {
  return std::make_unique<Integrator>();
}

// Every method a scene may name, the engine's one list of them: first the force-based
// integrators of lessons 01 to 08, then those of lessons 12, 13 and 14.
constexpr std::array kMethods = {Method{"explicit-euler", make<ExplicitEuler>},
                                 Method{"symplectic-euler", make<SymplecticEuler>},
                                 Method{"midpoint", make<Midpoint>},
                                 Method{"rk4", make<RungeKutta4>},
                                 Method{"velocity-verlet", make<VelocityVerlet>},
                                 Method{"position-verlet", make<PositionVerlet>},
                                 Method{"implicit-euler", make<ImplicitEuler>},
                                 Method{"xpbd", make<Xpbd>},
                                 Method{"local-global", make<LocalGlobal>},
                                 Method{"vbd", make<Vbd>}};
constexpr size_t kForceBased = 7;  // the first seven move particles by forces

// The table's names, for the lists below.
constexpr std::array<std::string_view, kMethods.size()> kNames = [] {
  std::array<std::string_view, kMethods.size()> names{};
  for (size_t k = 0; k < kMethods.size(); ++k)
    names[k] = kMethods[k].name;
  return names;
}();

}  // namespace

std::span<const std::string_view> integrator_names() {
  return std::span(kNames).first(kForceBased);
}

std::span<const std::string_view> method_names() {
  return kNames;
}

std::unique_ptr<Integrator> make_integrator(std::string_view name) {
  for (const Method& method : kMethods) {
    if (method.name == name) return method.make();
  }
  return nullptr;
}

}  // namespace clothlab
