#pragma once
// Names the element where the kinetic energy concentrates, for the energy-growth stop's message
// (energy_growth_error.hpp): of the elements holding the hottest node, the one whose nodes carry
// the most kinetic energy.
#include <cstdint>
#include <string>

#include "valvefsi/solid/element_model.hpp"
#include "valvefsi/solid/explicit_solver.hpp"
#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid {

// "element <e> (nodes ..., <p> % of the kinetic energy)", or "no element" when none holds it.
std::string kinetic_energy_element(const Mesh& mesh, ElementFamily family, const ExplicitSolver& solver,
                                   std::int64_t hottest_node);

}  // namespace valvefsi::solid
