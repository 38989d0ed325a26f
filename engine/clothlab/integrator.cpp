#include "clothlab/integrator.hpp"

#include <array>

#include "clothlab/euler.hpp"

namespace clothlab {

namespace {
// Every integrator a scene may name; a later lesson adds its methods here.
constexpr std::array<std::string_view, 2> kNames = {"explicit-euler", "symplectic-euler"};
}  // namespace

std::span<const std::string_view> integrator_names() {
  return kNames;
}

std::unique_ptr<Integrator> make_integrator(std::string_view name) {
  if (name == "explicit-euler") return std::make_unique<ExplicitEuler>();
  if (name == "symplectic-euler") return std::make_unique<SymplecticEuler>();
  return nullptr;
}

}  // namespace clothlab
