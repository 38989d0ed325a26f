#include "clothlab/integrators/integrator.hpp"

#include <array>

#include "clothlab/integrators/euler.hpp"
#include "clothlab/integrators/implicit_euler.hpp"
#include "clothlab/integrators/local_global.hpp"
#include "clothlab/integrators/runge_kutta.hpp"
#include "clothlab/integrators/verlet.hpp"
#include "clothlab/integrators/xpbd.hpp"

namespace clothlab {

namespace {
// Every integrator a scene may name, from lesson 01's Euler methods to lesson 07's.
constexpr std::array<std::string_view, 7> kNames = {
    "explicit-euler",  "symplectic-euler", "midpoint",      "rk4",
    "velocity-verlet", "position-verlet",  "implicit-euler"};
// The same, lesson 12's and lesson 13's.
constexpr std::array<std::string_view, 9> kMethods = {
    "explicit-euler",  "symplectic-euler", "midpoint", "rk4",         "velocity-verlet",
    "position-verlet", "implicit-euler",   "xpbd",     "local-global"};
}  // namespace

std::span<const std::string_view> integrator_names() {
  return kNames;
}

std::span<const std::string_view> method_names() {
  return kMethods;
}

std::unique_ptr<Integrator> make_integrator(std::string_view name) {
  if (name == "explicit-euler") return std::make_unique<ExplicitEuler>();
  if (name == "symplectic-euler") return std::make_unique<SymplecticEuler>();
  if (name == "midpoint") return std::make_unique<Midpoint>();
  if (name == "rk4") return std::make_unique<RungeKutta4>();
  if (name == "velocity-verlet") return std::make_unique<VelocityVerlet>();
  if (name == "position-verlet") return std::make_unique<PositionVerlet>();
  if (name == "implicit-euler") return std::make_unique<ImplicitEuler>();
  if (name == "xpbd") return std::make_unique<Xpbd>();
  if (name == "local-global") return std::make_unique<LocalGlobal>();
  return nullptr;
}

}  // namespace clothlab
