#pragma once
// Raised when the energy ledger's balance error passes solid.max_energy_balance_error of the
// largest energy seen (docs/solid_fe.md, "Energy-growth stop"): the time integration is creating
// energy. The message names the time, the energies, the node and element where the kinetic
// energy concentrates and the settings that change it; the state stays the one at that step.
#include <cstdint>
#include <stdexcept>
#include <string>

namespace valvefsi::solid {

class EnergyGrowthError : public std::runtime_error {
 public:
  EnergyGrowthError(const std::string& message, std::int64_t hottest_node)
      : std::runtime_error(message), hottest_node_(hottest_node) {}
  // The node with the largest kinetic energy (the caller names its element from the mesh).
  std::int64_t hottest_node() const { return hottest_node_; }

 private:
  std::int64_t hottest_node_;
};

}  // namespace valvefsi::solid
